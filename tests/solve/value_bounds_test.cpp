#include "ontime/solve/value_bounds.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// Rounding slack of the inequalities and equalities below.
constexpr double kBoundsRounding = 1e-12;

// Refines one skeleton at every step: the commit policy of the lower bound.
class AlwaysAllocator final : public Allocator {
 public:
  explicit AlwaysAllocator(int skeleton) : skeleton_(skeleton) {}
  std::string_view name() const noexcept override { return "always"; }
  int choose(const State&) override { return skeleton_; }

 private:
  int skeleton_;
};

// A state laid out as the exact solver's keys are (fixed arrays), with the slots of skeletons
// whose group cannot succeed, or that are fully refined, blanked as the solver blanks them.
struct BlankedState {
  std::uint16_t time = 0;
  std::array<std::uint8_t, kMaxExactSkeletons> refined{};
  std::array<std::uint16_t, kMaxExactSkeletons> spent{};
  std::array<std::uint16_t, kMaxExactSkeletons> execution{};
};

BlankedState blanked(const Mdp& mdp, const State& state) {
  BlankedState out;
  out.time = state.time;
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    const auto slot = static_cast<std::size_t>(k);
    const int action = mdp.next_action(state, k);
    if (action >= 0 && mdp.group_can_succeed(state, action)) {
      out.refined[slot] = state.refined[slot];
      out.spent[slot] = state.spent[slot];
      out.execution[slot] = state.execution[slot];
    } else {
      out.refined[slot] = 0;
      out.spent[slot] = 0xFFFF;
      out.execution[slot] = 0xFFFF;
    }
  }
  return out;
}

// Running states met along random episodes: mostly useful choices, sometimes any skeleton (an
// idle step or a step on a skeleton that cannot succeed), observations drawn from the model.
std::vector<State> reachable_states(const Mdp& mdp, std::uint64_t seed, int episodes) {
  SplitMix64 generator(seed);
  std::vector<State> states;
  for (int episode = 0; episode < episodes; ++episode) {
    State state = mdp.start();
    for (;;) {
      const ChoiceList useful = mdp.useful_choices(state);
      if (useful.empty()) break;
      const int choice = generator() % 4 == 0 ? static_cast<int>(generator() % mdp.skeleton_count())
                                              : useful[generator() % useful.size()];
      if (mdp.apply(state, choice, mdp.sample_observation(state, choice, generator)) != Status::running) break;
      states.push_back(state);
    }
  }
  return states;
}

// The clairvoyant success probability by brute force: the remaining cost W_a = (PT_a - spent |
// PT_a > spent) + E_a of every action still to refine is enumerated jointly (a cost above the
// deadline counts as never), and an outcome succeeds when some skeleton's remaining costs fit
// D - CT - ET_k. No tree structure or independence between groups is used.
double clairvoyant_by_enumeration(const Mdp& mdp, const State& state) {
  const Problem& problem = mdp.problem();
  const Steps deadline = mdp.deadline();
  std::map<int, std::size_t> index;                                   // action -> position in `costs`
  std::vector<std::vector<double>> costs;                             // costs[i][w] = P(W = w), w in [1, D]
  std::vector<std::pair<Steps, std::vector<std::size_t>>> skeletons;  // budget, remaining actions
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    const auto slot = static_cast<std::size_t>(k);
    const int refined = state.refined[slot];
    const Steps spent = state.spent[slot];
    const Steps budget = deadline - state.time - state.execution[slot];
    if (refined >= problem.skeleton_length(k) || spent >= deadline || budget < 1) continue;
    std::vector<std::size_t> remaining;
    for (int l = refined; l < problem.skeleton_length(k); ++l) {
      const int action = problem.action_at(k, l);
      if (!index.contains(action)) {
        const Action& a = problem.action(action);
        const Steps before = l == refined ? spent : 0;
        const double alive = a.planning.survival(before);
        std::vector<double> cost(static_cast<std::size_t>(deadline) + 1, 0.0);
        for (Steps t = 1; t <= deadline && alive > 0; ++t) {
          for (Steps x = 0; t + x <= deadline; ++x) {
            cost[static_cast<std::size_t>(t + x)] += a.planning.pmf(before + t) / alive * a.execution.pmf(x);
          }
        }
        index.emplace(action, costs.size());
        costs.push_back(std::move(cost));
      }
      remaining.push_back(index.at(action));
    }
    skeletons.emplace_back(budget, std::move(remaining));
  }
  constexpr Steps kTooLong = -1;
  std::vector<Steps> drawn(costs.size(), kTooLong);
  double success = 0;
  const auto enumerate = [&](auto&& self, std::size_t i, double probability) -> void {
    if (i == costs.size()) {
      for (const auto& [budget, remaining] : skeletons) {
        Steps total = 0;
        bool fits = true;
        for (const std::size_t a : remaining) {
          fits = fits && drawn[a] != kTooLong;
          total += drawn[a] == kTooLong ? 0 : drawn[a];
        }
        if (fits && total <= budget) {
          success += probability;
          return;
        }
      }
      return;
    }
    double listed = 0;
    for (Steps w = 1; w <= deadline; ++w) {
      const double mass = costs[i][static_cast<std::size_t>(w)];
      if (mass <= 0) continue;
      listed += mass;
      drawn[i] = w;
      self(self, i + 1, probability * mass);
    }
    if (listed < 1.0) {
      drawn[i] = kTooLong;
      self(self, i + 1, probability * (1.0 - listed));
    }
  };
  enumerate(enumerate, 0, 1.0);
  return success;
}

TEST(ValueBounds, CommitValueIsTheExactValueOfAlwaysRefiningTheSkeleton) {
  for (std::uint64_t seed = 1; seed <= 600; ++seed) {
    const Problem problem = testing::random_instance(seed, 6, 4, 20);
    const Mdp mdp(problem);
    const ValueBounds bounds(mdp);
    double best = 0;
    for (int k = 0; k < mdp.skeleton_count(); ++k) {
      AlwaysAllocator always(k);
      const double value = evaluate_exactly(mdp, always).success_probability;
      EXPECT_NEAR(bounds.commit(mdp.start(), k), value, kBoundsRounding) << "seed " << seed << " skeleton " << k;
      best = std::max(best, value);
    }
    EXPECT_NEAR(bounds.lower(mdp.start()), best, kBoundsRounding) << "seed " << seed;
    const int choice = bounds.lower_choice(mdp.start());
    if (choice < 0) {
      EXPECT_EQ(bounds.lower(mdp.start()), 0.0) << "seed " << seed;
    } else {
      EXPECT_EQ(bounds.lower(mdp.start()), bounds.commit(mdp.start(), choice)) << "seed " << seed;
    }
  }
}

TEST(ValueBounds, BracketTheOptimumOnTheStartAndOnReachableStates) {
  std::size_t states = 0;
  for (std::uint64_t seed = 1; seed <= 1000; ++seed) {
    // Small instances, then larger ones (up to 6 skeletons, deadlines up to 20).
    const Problem problem =
        seed <= 500 ? testing::random_instance(seed, 4, 3, 10) : testing::random_instance(seed, 6, 4, 20);
    const Mdp mdp(problem);
    const ValueBounds bounds(mdp);
    OptimalSolver solver(mdp);
    std::vector<State> checked = reachable_states(mdp, seed, 20);
    checked.push_back(mdp.start());
    for (const State& state : checked) {
      const double optimum = solver.solve(state);
      const double lower = bounds.lower(state);
      const double upper = bounds.upper(state);
      EXPECT_LE(lower, optimum + kBoundsRounding) << "seed " << seed << " time " << state.time;
      EXPECT_GE(upper, optimum - kBoundsRounding) << "seed " << seed << " time " << state.time;
      EXPECT_GE(lower, 0.0);
      EXPECT_LE(upper, 1.0);
      // The solver's keys, with blanked slots, give the same bounds.
      const BlankedState key = blanked(mdp, state);
      EXPECT_EQ(bounds.lower(key), lower) << "seed " << seed;
      EXPECT_EQ(bounds.lower_choice(key), bounds.lower_choice(state)) << "seed " << seed;
      EXPECT_EQ(bounds.upper(key), upper) << "seed " << seed;
      ++states;
    }
  }
  EXPECT_GT(states, 30000U);
}

// With chains and expiry (SPEC §9): the upper bound is a relaxation (chain-dependent executions
// 0, no expiry) and still bounds the optimum; no commit value is claimed.
TEST(ValueBounds, WithChainsTheUpperBoundStillBoundsTheOptimumAndTheLowerIsVacuous) {
  std::size_t states = 0;
  int tight = 0;
  const int count = testing::repetitions_to_check(200);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem =
        testing::with_random_chains(testing::random_instance(seed + 700, 4, 3, 9), seed + 700, seed % 2 == 0);
    const Mdp mdp(problem);
    const ValueBounds bounds(mdp);
    OptimalSolver solver(mdp);
    std::vector<State> checked = reachable_states(mdp, seed, 10);
    checked.push_back(mdp.start());
    for (const State& state : checked) {
      const double optimum = solver.solve(state);
      const double upper = bounds.upper(state);
      EXPECT_GE(upper, optimum - kBoundsRounding) << "seed " << seed << " time " << state.time;
      EXPECT_LE(upper, problem.max_reward());
      EXPECT_EQ(bounds.lower(state), 0.0);
      EXPECT_EQ(bounds.lower_choice(state), -1);
      tight += optimum > 0 && upper < problem.max_reward() ? 1 : 0;
      ++states;
    }
  }
  EXPECT_GT(states, static_cast<std::size_t>(count) * 10);
  EXPECT_GT(tight, count);  // the bound says more than "at most the largest reward" on many states
}

TEST(ValueBounds, UpperIsTheClairvoyantProbabilityEnumeratedOutcomeByOutcome) {
  for (std::uint64_t seed = 1; seed <= 400; ++seed) {
    const Problem problem = testing::random_instance(seed * 31, 3, 3, 8);
    const Mdp mdp(problem);
    const ValueBounds bounds(mdp);
    std::vector<State> checked = reachable_states(mdp, seed, 10);
    checked.push_back(mdp.start());
    for (const State& state : checked) {
      EXPECT_NEAR(bounds.upper(state), clairvoyant_by_enumeration(mdp, state), kBoundsRounding)
          << "seed " << seed << " time " << state.time;
    }
  }
}

// With one path of actions there is one useful choice, and the clairvoyant event is the event
// that following it succeeds: both bounds are the optimum.
TEST(ValueBounds, BothBoundsAreTheOptimumWhenThePrefixTreeIsOnePath) {
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const Problem single = testing::random_instance(seed, 1, 5, 14);
    // The same actions, with every prefix of the skeleton a skeleton of its own.
    const std::vector<int> path(single.skeleton(0).begin(), single.skeleton(0).end());
    std::vector<std::vector<int>> prefixes;
    for (std::size_t length = 1; length <= path.size(); ++length)
      prefixes.emplace_back(path.begin(), path.begin() + length);
    const Problem nested("nested", single.deadline(), 1.0,
                         std::vector<Action>(single.actions().begin(), single.actions().end()), prefixes);
    for (const Problem* problem : {&single, &nested}) {
      const Mdp mdp(*problem);
      const ValueBounds bounds(mdp);
      OptimalSolver solver(mdp);
      std::vector<State> checked = reachable_states(mdp, seed, 10);
      checked.push_back(mdp.start());
      for (const State& state : checked) {
        const double optimum = solver.solve(state);
        EXPECT_NEAR(bounds.lower(state), optimum, kBoundsRounding) << "seed " << seed << " " << problem->name();
        EXPECT_NEAR(bounds.upper(state), optimum, kBoundsRounding) << "seed " << seed << " " << problem->name();
      }
    }
  }
}

TEST(ValueBounds, FigureOneBoundsByHand) {
  // Figure 1, D = 5, V* = 0.5625. Every execution takes 1 or 10 steps with probability 1/2.
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  const ValueBounds bounds(mdp);
  // Committing to sigma1 succeeds when d1 is found at step 1 and both executions are fast:
  // 1 + 1 + 1 + 1 <= 5, probability 1/8 (sigma2 alike). Committing to sigma3 succeeds when d3
  // (found at step 3) executes fast: 1/2, the lower bound.
  EXPECT_NEAR(bounds.commit(mdp.start(), 0), 0.125, kBoundsRounding);
  EXPECT_NEAR(bounds.commit(mdp.start(), 1), 0.125, kBoundsRounding);
  EXPECT_NEAR(bounds.commit(mdp.start(), 2), 0.5, kBoundsRounding);
  EXPECT_EQ(bounds.lower_choice(mdp.start()), 2);
  EXPECT_NEAR(bounds.lower(mdp.start()), 0.5, kBoundsRounding);
  // Clairvoyant: group d1 fits when d1 takes 1 + 1 steps (1/4) and d12 or d22 then executes
  // fast (3/4): 3/16; group d3 fits with 1/2. upper = 1 - (1 - 3/16)(1 - 1/2) = 19/32.
  EXPECT_NEAR(bounds.upper(mdp.start()), 19.0 / 32.0, kBoundsRounding);
}

TEST(ValueBounds, RefusesTablesAboveTheCap) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  try {
    const ValueBounds bounds(mdp, 100);
    FAIL() << "expected ResourceLimitError";
  } catch (const ResourceLimitError& error) {
    EXPECT_NE(std::string(error.what()).find("above the cap of 100"), std::string::npos) << error.what();
  }
  const ValueBounds bounds(mdp);
  EXPECT_LE(bounds.table_entries(), ValueBounds::kDefaultMaxTableEntries);
}

// Records (does not assert) how far the bounds are from the optimum at the start of the paper's
// instances. The navigation instance's bounds are printed without its optimum, which takes the
// exact solver about a minute, 15 million states (above its default cap) and 1.6 GB:
// `ontime solve data/instances/navigation.json --max-states 60000000` gives 0.5191953822.
TEST(ValueBounds, RecordsTheGapsOnThePaperInstances) {
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    const ValueBounds bounds(mdp);
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    const double lower = bounds.lower(mdp.start());
    const double upper = bounds.upper(mdp.start());
    EXPECT_LE(lower, optimum + kBoundsRounding) << name;
    EXPECT_GE(upper, optimum - kBoundsRounding) << name;
    std::printf("%-10s lower %.9f  optimum %.9f  upper %.9f  optimum-lower %.3g  upper-optimum %.3g\n", name, lower,
                optimum, upper, optimum - lower, upper - optimum);
  }
  const Problem navigation = load_problem(testing::source_path("data/instances/navigation.json"));
  const Mdp mdp(navigation);
  const ValueBounds bounds(mdp);
  std::printf("%-10s lower %.9f  upper %.9f\n", "navigation", bounds.lower(mdp.start()), bounds.upper(mdp.start()));
}

}  // namespace
}  // namespace ontime
