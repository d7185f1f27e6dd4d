#include <gtest/gtest.h>

#include <cmath>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/dp.hpp"
#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/allocators/greedy.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/allocators/round_robin.hpp"
#include "ontime/allocators/thompson.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

double exact_value(const std::string& allocator, const Mdp& mdp) {
  const auto instance = make_allocator_factory(allocator, mdp)();
  return evaluate_exactly(mdp, *instance).success_probability;
}

// The published figures are means of 100 runs, rounded to two decimals: an exact value is
// consistent with one when it lies within the published 95% half-width plus the rounding.
void expect_consistent(double exact, testing::PublishedCell published, const std::string& what) {
  EXPECT_LE(std::abs(exact - published.mean), published.half_width + 0.005)
      << what << ": exact " << exact << " vs published " << published.mean << " ± " << published.half_width;
}

TEST(Allocators, ExactValuesAreConsistentWithTableOne) {
  for (int i = 0; i < 5; ++i) {
    const std::string name = "instance" + std::to_string(i + 1);
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    const testing::PublishedRow& row = testing::kTableOne[static_cast<std::size_t>(i)];
    expect_consistent(exact_value("dp", mdp), row.dp, name + " dp");
    expect_consistent(exact_value("dp-rerun", mdp), row.dp_rerun, name + " dp-rerun");
    expect_consistent(exact_value("greedy", mdp), row.greedy, name + " greedy");
    expect_consistent(exact_value("round-robin", mdp), row.round_robin, name + " round-robin");
  }
}

TEST(Allocators, DpPicksTheBestSingleSkeletonOnce) {
  const Problem problem = testing::paper_instance("instance4");
  const Mdp mdp(problem);
  DpAllocator dp(mdp);
  EXPECT_EQ(dp.chosen_skeleton(), 1);  // P(T <= 3): 0.9 against 0.55
  State state = mdp.start();
  state.time = 3;
  EXPECT_EQ(dp.choose(state), 1);
  EXPECT_DOUBLE_EQ(exact_value("dp", mdp), 0.9);
}

TEST(Allocators, GreedyComparesMeansAndBreaksTiesLow) {
  // Instance 4: both skeletons have mean planning 3 and execution 1: a tie, skeleton 0 wins,
  // which is why Greedy fails there (P(T_a1 <= 3) = 0.55).
  const Problem problem = testing::paper_instance("instance4");
  const Mdp mdp(problem);
  EXPECT_EQ(GreedyAllocator(mdp).chosen_skeleton(), 0);
  EXPECT_DOUBLE_EQ(exact_value("greedy", mdp), 0.55);
  // Instance 3: sigma4 = (a4_1, a4_2) has the smallest mean: 8 + 5 + 1 + (0.35 + 0.65 * 8).
  const Problem three = testing::paper_instance("instance3");
  EXPECT_EQ(GreedyAllocator(Mdp(three)).chosen_skeleton(), 3);
}

TEST(Allocators, RoundRobinCyclesThroughSkeletons) {
  RoundRobinAllocator round_robin(3);
  State state;
  for (std::uint16_t time = 0; time < 7; ++time) {
    state.time = time;
    EXPECT_EQ(round_robin.choose(state), time % 3);
  }
}

TEST(Allocators, DpRerunConditionsOnTimeAlreadySpent) {
  // Instance 4 at start: a2_1 (0.9) beats a1_1 (0.55). After two unsuccessful steps on a2_1
  // (CT = 2, PT = 2), a2_1 finishes at step 3 with probability 0.8 / 0.9 but needs CT' + 1 <= 4:
  // PS = 0.8/0.9; a1_1 from scratch with 2 steps left: P(T <= 1) = 0.3.
  const Problem problem = testing::paper_instance("instance4");
  const Mdp mdp(problem);
  DpRerunAllocator rerun(mdp);
  EXPECT_EQ(rerun.choose(mdp.start()), 1);
  State state = mdp.start();
  mdp.apply(state, 1, Observation::not_yet());
  mdp.apply(state, 1, Observation::not_yet());
  EXPECT_NEAR(rerun.table().success_probability(state, 1), 0.8 / 0.9, 1e-15);
  EXPECT_NEAR(rerun.table().success_probability(state, 0), 0.3, 1e-15);
  EXPECT_EQ(rerun.choose(state), 1);
}

TEST(Allocators, DpRerunAggregationsAreSelectable) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  // sum: sigma1 scores 0.25 against sigma3's 0.5, so sigma3 is chosen; max and self likewise.
  for (const Aggregation aggregation : {Aggregation::sum, Aggregation::max, Aggregation::self}) {
    DpRerunAllocator rerun(mdp, aggregation);
    EXPECT_EQ(rerun.choose(mdp.start()), 2) << to_string(aggregation);
  }
}

TEST(Allocators, FactoryKnowsEveryNameAndRejectsOthers) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  const AllocatorRegistry& registry = allocator_registry();
  // Every kind that needs nothing beyond the instance (a policy file is tested in ppo_test).
  for (const std::string& name : registry.names({}, {Capability::needs_policy})) {
    const auto allocator = make_allocator_factory(name, mdp)();
    EXPECT_EQ(allocator->name(), name);
    EXPECT_EQ(allocator->is_stationary(), registry.find(name).capabilities.has(Capability::stationary)) << name;
  }
  EXPECT_THROW(make_allocator_factory("mcts-typo", mdp), UsageError);
}

}  // namespace
}  // namespace ontime

namespace ontime {
namespace {

// Skeleton 0 plans in 1 step or in 10 (half each), skeleton 1 in exactly 5; both execute in 0.
Problem one_or_ten_against_five() {
  const Action either{"either", Distribution::from_pmf({0, 0.5, 0, 0, 0, 0, 0, 0, 0, 0, 0.5}),
                      Distribution::from_pmf({1.0})};
  const Action five{"five", Distribution::from_pmf({0, 0, 0, 0, 0, 1.0}), Distribution::from_pmf({1.0})};
  return Problem("one-or-ten", 20, 1.0, {either, five}, {{0}, {1}});
}

TEST(Thompson, SpendsTheStepWhereTheDrawnWorldFinishesSoonest) {
  const Problem problem = one_or_ten_against_five();
  const Mdp mdp(problem);
  ThompsonAllocator thompson(mdp);
  // At the start skeleton 0 finishes at 1 or 10, skeleton 1 at 5: skeleton 0 in half the draws.
  int zero = 0;
  for (std::uint64_t seed = 0; seed < 2'000; ++seed) {
    thompson.begin_episode(seed);
    zero += thompson.choose(mdp.start()) == 0 ? 1 : 0;
  }
  EXPECT_NEAR(zero / 2'000.0, 0.5, 4 * std::sqrt(0.25 / 2'000));
  // One step on skeleton 0 found nothing: its planning time is 10, 9 more steps, conditioned on
  // the step spent; skeleton 1 (5) is sooner in every draw.
  State after = mdp.start();
  ASSERT_EQ(mdp.apply(after, 0, Observation::not_yet()), Status::running);
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    thompson.begin_episode(seed);
    EXPECT_EQ(thompson.choose(after), 1) << seed;
  }
}

TEST(Thompson, SameSeedSameSuccessesForAnyThreadCountAndNeverAboveTheOptimum) {
  for (int i = 1; i <= 5; ++i) {
    const Problem problem = testing::paper_instance("instance" + std::to_string(i));
    const Mdp mdp(problem);
    const AllocatorFactory factory = make_allocator_factory("thompson", mdp);
    MonteCarloOptions options;
    options.episodes = 4'000;
    options.seed = 7;
    options.threads = 1;
    const MonteCarloResult one = run_monte_carlo(mdp, factory, options);
    options.threads = 2;
    const MonteCarloResult two = run_monte_carlo(mdp, factory, options);
    EXPECT_EQ(one.successes, two.successes) << i;
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    EXPECT_LE(one.success_rate, optimum + 4 * std::sqrt(optimum * (1 - optimum) / 4'000) + 1e-12) << i;
    EXPECT_FALSE(factory()->is_stationary());
  }
}

}  // namespace
}  // namespace ontime
