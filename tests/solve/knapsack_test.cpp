#include "ontime/solve/knapsack.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "ontime/allocators/optimal.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

Knapsack random_knapsack(std::uint64_t seed) {
  SplitMix64 generator(seed);
  const auto uniform = [&generator](std::int64_t low, std::int64_t high) {
    return low + static_cast<std::int64_t>(generator() % static_cast<std::uint64_t>(high - low + 1));
  };
  Knapsack knapsack;
  knapsack.capacity = uniform(1, 12);
  const std::int64_t count = uniform(1, 5);
  for (std::int64_t i = 0; i < count; ++i) {
    knapsack.items.push_back({uniform(1, knapsack.capacity + 2), uniform(1, 9)});  // some too heavy
  }
  return knapsack;
}

double relative_difference(double a, double b) {
  return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300});
}

// The exact optimum of the reduced instance is the best success over maximum-value knapsack
// sets, and the bounds of the proof hold for every set.
TEST(Knapsack, ReductionOptimumIsAMaximumValueKnapsack) {
  int nontrivial = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const Knapsack knapsack = random_knapsack(seed);
    const std::size_t count = knapsack.items.size();
    const double epsilon = reduction_epsilon(knapsack);
    std::int64_t best_value = 0;
    double best_over_all_sets = 0;
    std::vector<std::pair<std::int64_t, double>> feasible;  // (value, success)
    for (std::uint32_t mask = 0; mask < (1U << count); ++mask) {
      std::vector<std::uint8_t> chosen(count);
      std::int64_t weight = 0, value = 0;
      for (std::size_t k = 0; k < count; ++k) {
        chosen[k] = (mask >> k) & 1U;
        if (chosen[k] != 0) {
          weight += knapsack.items[k].weight;
          value += knapsack.items[k].value;
        }
      }
      const double success = schedule_success(knapsack, chosen);
      // The proof's bounds: eps (V - 1) < P(S) <= eps V (P(empty) = 0).
      EXPECT_LE(success, epsilon * static_cast<double>(value) * (1 + 1e-12)) << "seed " << seed;
      if (value > 0) {
        EXPECT_GT(success, epsilon * static_cast<double>(value - 1)) << "seed " << seed;
      }
      if (weight > knapsack.capacity) continue;
      feasible.emplace_back(value, success);
      best_value = std::max(best_value, value);
      best_over_all_sets = std::max(best_over_all_sets, success);
    }
    double best_over_maximum_value_sets = 0;
    for (const auto& [value, success] : feasible) {
      if (value == best_value) best_over_maximum_value_sets = std::max(best_over_maximum_value_sets, success);
    }
    const Problem problem = reduce_knapsack(knapsack);
    const Mdp mdp(problem);
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    if (best_value == 0) {
      EXPECT_EQ(optimum, 0.0) << "seed " << seed;
      continue;
    }
    ++nontrivial;
    EXPECT_LT(relative_difference(optimum, best_over_maximum_value_sets), 1e-9) << "seed " << seed;
    EXPECT_LT(relative_difference(optimum, best_over_all_sets), 1e-9) << "seed " << seed;
  }
  EXPECT_GT(nontrivial, 150);
}

TEST(Knapsack, ReducedInstanceFollowsTheProof) {
  const Knapsack knapsack = load_knapsack(testing::source_path("data/knapsack/example.json"));
  const double epsilon = reduction_epsilon(knapsack);
  EXPECT_DOUBLE_EQ(epsilon, 1.0 / (6.0 * 6.0 * 4 * 4 * 4));
  const Problem problem = reduce_knapsack(knapsack);
  EXPECT_EQ(problem.deadline(), 5);
  ASSERT_EQ(problem.skeleton_count(), 4);
  const Distribution& planning = problem.action(1).planning;  // weight 3, value 4
  EXPECT_EQ(planning.cdf(2), 0.0);
  EXPECT_DOUBLE_EQ(planning.cdf(3), 4 * epsilon);
  EXPECT_DOUBLE_EQ(planning.cdf(5), 4 * epsilon);
  EXPECT_DOUBLE_EQ(planning.cdf(6), 1.0);
  EXPECT_EQ(problem.action(1).execution.pmf(0), 1.0);
  // Items 1 and 2 (weights 2 + 3, values 3 + 4) are the maximum-value knapsack.
  const Mdp mdp(problem);
  EXPECT_NEAR(OptimalSolver(mdp).solve(mdp.start()), 1 - (1 - 3 * epsilon) * (1 - 4 * epsilon), 1e-15);
}

TEST(Knapsack, RejectsInvalidFiles) {
  const auto place_of = [](const std::string& text) {
    try {
      parse_knapsack(text, "k.json");
    } catch (const InputError& error) {
      return error.place() + ": " + error.rule();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(place_of(R"({"capacity": 5, "items": [{"weight": 2, "value": 3}]})"), "accepted");
  EXPECT_EQ(place_of(R"({"capacity": 5.0, "items": [{"weight": 2.0, "value": 3e0}]})"),
            "accepted");  // as Python writes
  EXPECT_EQ(place_of(R"({"items": [{"weight": 2, "value": 3}]})"), "top level: missing required key 'capacity'");
  EXPECT_EQ(place_of(R"({"capacity": 0, "items": [{"weight": 2, "value": 3}]})").substr(0, 10), "capacity: ");
  EXPECT_EQ(place_of(R"({"capacity": 10001, "items": [{"weight": 2, "value": 3}]})").substr(0, 10), "capacity: ");
  EXPECT_EQ(place_of(R"({"capacity": 5, "items": []})").substr(0, 7), "items: ");
  EXPECT_EQ(place_of(R"({"capacity": 5, "items": [{"weight": -2, "value": 3}]})").substr(0, 18), "items[0].weight: m");
  EXPECT_EQ(place_of(R"({"capacity": 5, "items": [{"weight": 2, "value": 1.5}]})").substr(0, 17), "items[0].value: m");
  EXPECT_EQ(place_of(R"({"capacity": 5, "items": [{"weight": 2}]})"), "items[0]: missing required key 'value'");
  EXPECT_EQ(place_of(R"({"capacity": 5, "items": [{"weight": 2, "value": 3, "size": 1}]})").substr(0, 14),
            "items[0].size:");
  std::string many = R"({"capacity": 5, "items": [)";
  for (int i = 0; i < 17; ++i) many += std::string(i > 0 ? "," : "") + R"({"weight": 1, "value": 1})";
  EXPECT_EQ(place_of(many + "]}").substr(0, 17), "items: at most 16");
}

}  // namespace
}  // namespace ontime
