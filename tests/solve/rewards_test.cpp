// Rewards beyond success (SPEC §8) in the exact solvers, the bounds and Eq. (1): each against the
// independent reference solver on random instances, and each against the others to the bit.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "ontime/solve/contiguous_success.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/search_solver.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "support/exact_solver_checks.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"
#include "support/reference_solver.hpp"

namespace ontime {
namespace {

TEST(Rewards, TheOptimumIsTheReferenceSolversExpectedReward) {
  int falling = 0;
  const int count = testing::repetitions_to_check(200);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem = testing::with_random_rewards(testing::random_instance(seed, 4, 3, 10), seed);
    ASSERT_TRUE(problem.has_rewards());
    for (const SkeletonReward& reward : problem.rewards()) falling += reward.per_step > 0 ? 1 : 0;
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    EXPECT_NEAR(solver.solve(mdp.start()), testing::ReferenceSolver(problem).optimum(), 1e-12) << "seed " << seed;
  }
  EXPECT_GT(falling, count / 2);  // the rewards that fall with time are well represented
}

TEST(Rewards, SearchAndLayeredSolversEqualTheMemoisedOneBitForBit) {
  for (std::uint64_t seed = 1; seed <= 150; ++seed) {
    const Problem problem = testing::with_random_rewards(testing::random_instance(seed, 5, 4, 14), 7 * seed);
    const Mdp mdp(problem);
    OptimalSolver memoised(mdp);
    const double optimum = memoised.solve(mdp.start());
    const SearchSolution search = solve_search(mdp);
    ASSERT_TRUE(search.exact) << seed;
    EXPECT_EQ(search.lower, optimum) << seed;
    EXPECT_EQ(search.first_choice, memoised.best_choice(mdp.start()).value_or(-1)) << seed;
    const LayeredSolution layered = solve_layered(mdp);
    ASSERT_TRUE(layered.exact) << seed;
    EXPECT_EQ(layered.lower, optimum) << seed;
    EXPECT_EQ(layered.first_choice, memoised.best_choice(mdp.start()).value_or(-1)) << seed;
  }
}

TEST(Rewards, EveryCapsIntervalHoldsTheExpectedReward) {
  // A cap cuts the layered solver at a frontier that takes ValueBounds, and the search where it
  // stands: both intervals must hold the optimum with rewards as without.
  int cut = 0;
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    const Problem problem = testing::with_random_rewards(testing::random_instance(seed, 6, 5, 16), 11 * seed);
    const Mdp mdp(problem);
    OptimalSolver memoised(mdp);
    const double optimum = memoised.solve(mdp.start());
    for (const std::uint64_t cap : {std::uint64_t{3}, std::uint64_t{10}, std::uint64_t{30}}) {
      LayeredSolveOptions layered_options;
      layered_options.max_states = cap;
      const LayeredSolution layered = solve_layered(mdp, layered_options);
      EXPECT_LE(layered.lower, optimum + 1e-12) << seed << " cap " << cap;
      EXPECT_GE(layered.upper, optimum - 1e-12) << seed << " cap " << cap;
      SearchSolveOptions search_options;
      search_options.max_states = cap;
      const SearchSolution search = solve_search(mdp, search_options);
      EXPECT_LE(search.lower, optimum + 1e-12) << seed << " cap " << cap;
      EXPECT_GE(search.upper, optimum - 1e-12) << seed << " cap " << cap;
      cut += (layered.exact ? 0 : 1) + (search.exact ? 0 : 1);
    }
  }
  EXPECT_GT(cut, 60);  // the caps do cut: 83 of the 360 solves here (many instances are tiny)
}

TEST(Rewards, ACommonRewardScalesTheSuccessProbability) {
  // Every skeleton worth c at any finish: the expected reward of every policy is c times its
  // success probability, so the optimum is c times the optimal success probability.
  for (const char* name : {"figure1", "instance1", "instance3", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp plain(problem);
    const double success = OptimalSolver(plain).solve(plain.start());
    const Problem scaled = problem.with_rewards(
        std::vector<SkeletonReward>(static_cast<std::size_t>(problem.skeleton_count()), {0.7, 0.0}));
    const Mdp mdp(scaled);
    EXPECT_NEAR(OptimalSolver(mdp).solve(mdp.start()), 0.7 * success, 1e-14) << name;
  }
}

TEST(Rewards, ExplicitUnitRewardsAreNoRewards) {
  const Problem problem = testing::paper_instance("instance2");
  const Problem unit =
      problem.with_rewards(std::vector<SkeletonReward>(static_cast<std::size_t>(problem.skeleton_count())));
  EXPECT_FALSE(unit.has_rewards());
  EXPECT_EQ(unit.max_reward(), 1.0);
  const Mdp a(problem), b(unit);
  EXPECT_EQ(OptimalSolver(a).solve(a.start()), OptimalSolver(b).solve(b.start()));
}

TEST(Rewards, TheBoundsHoldTheOptimumAndTheCommitBoundIsAPolicysValue) {
  for (std::uint64_t seed = 1; seed <= 120; ++seed) {
    const Problem problem = testing::with_random_rewards(testing::random_instance(seed, 4, 3, 12), seed + 500);
    const Mdp mdp(problem);
    const ValueBounds bounds(mdp);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    EXPECT_LE(bounds.lower(mdp.start()), optimum + 1e-12) << seed;
    EXPECT_GE(bounds.upper(mdp.start()), optimum - 1e-12) << seed;
    // The commit bound is a real policy's value: the reference's value of committing to it.
    const int k = bounds.lower_choice(mdp.start());
    if (k >= 0) {
      const double commit = testing::ReferenceSolver(problem).value_of([k](const auto&) { return k; });
      EXPECT_LE(bounds.commit(mdp.start(), k), commit + 1e-12) << seed;
      EXPECT_GT(bounds.commit(mdp.start(), k), 0.0) << seed;
    }
  }
}

TEST(Rewards, EquationOneOfAOneSkeletonProblemIsItsExpectedReward) {
  // With one skeleton refining it contiguously is the only policy: Eq. (1) with rewards is its
  // expected reward, that is the optimum.
  int checked = 0;
  for (std::uint64_t seed = 1; checked < 60; ++seed) {
    const Problem base = testing::random_instance(seed, 1, 4, 12);
    if (base.skeleton_count() != 1) continue;
    ++checked;
    const Problem problem = testing::with_random_rewards(base, seed);
    const Mdp mdp(problem);
    const ContiguousSuccessTable table(mdp, Aggregation::sum);
    EXPECT_NEAR(table.success_probability(mdp.start(), 0), testing::ReferenceSolver(problem).optimum(), 1e-12)
        << "seed " << seed;
  }
}

TEST(Rewards, BrokenRewardsAreRefusedWithTheSkeletonAndTheRule) {
  const Problem problem = testing::paper_instance("figure1");
  const auto build = [&](std::vector<SkeletonReward> rewards) { return problem.with_rewards(std::move(rewards)); };
  const auto count = static_cast<std::size_t>(problem.skeleton_count());
  std::vector<SkeletonReward> rewards(count);
  rewards[1].value = std::numeric_limits<double>::quiet_NaN();
  try {
    build(rewards);
    ADD_FAILURE() << "a NaN reward was accepted";
  } catch (const RewardError& error) {
    EXPECT_EQ(error.skeleton(), 1);
    EXPECT_EQ(error.rule(), "the value must be a number within [0, 1]");
  }
  rewards[1] = {1.5, 0.0};
  EXPECT_THROW(build(rewards), RewardError);
  rewards[1] = {0.5, -0.1};
  EXPECT_THROW(build(rewards), RewardError);
  rewards[1] = {0.5, 0.5 / problem.deadline() * 1.01};  // below 0 before the deadline
  EXPECT_THROW(build(rewards), RewardError);
  rewards[1] = {0.5, 0.5 / problem.deadline()};  // 0 at the deadline: allowed
  EXPECT_NO_THROW(build(rewards));
  EXPECT_THROW(build(std::vector<SkeletonReward>(count + 1)), UsageError);
}

TEST(Rewards, TheLayeredSolverRefusesADropOrASplitOfRewards) {
  const Problem problem = testing::with_random_rewards(testing::paper_instance("instance3"), 3);
  testing::expect_layered_refuses_a_tolerance_and_a_split(Mdp(problem));
}

}  // namespace
}  // namespace ontime
