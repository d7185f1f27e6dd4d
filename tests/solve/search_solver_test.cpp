#include "ontime/solve/search_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "ontime/allocators/optimal.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// The search solves a choice exactly wherever the bounds cannot settle the tie rule's verdict, and
// sums it as the memoised solver does: the same value to the bit and the same first choice, with
// at most the memoised solver's states solved.
void expect_search_equals_memoised(const Mdp& mdp, const std::string& name) {
  OptimalSolver memoised(mdp);
  const double optimum = memoised.solve(mdp.start());
  const SearchSolution search = solve_search(mdp);
  ASSERT_TRUE(search.exact) << name;
  EXPECT_EQ(search.lower, optimum) << name;
  EXPECT_EQ(search.upper, optimum) << name;
  EXPECT_EQ(search.first_choice, memoised.best_choice(mdp.start()).value_or(-1)) << name;
  EXPECT_LE(search.states, memoised.states()) << name;
  EXPECT_TRUE(search.stopped_by.empty()) << name;
}

TEST(SearchSolver, EqualsTheMemoisedSolverBitForBitOnThePaperInstances) {
  std::uint64_t searched = 0;
  std::uint64_t enumerated = 0;
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    expect_search_equals_memoised(mdp, name);
    searched += solve_search(mdp).states;
    OptimalSolver memoised(mdp);
    memoised.solve(mdp.start());
    enumerated += memoised.states();
  }
  // Instance 1 alone: 872 states reachable; the bounds leave fewer than 600 to solve.
  EXPECT_LT(searched, enumerated);
}

TEST(SearchSolver, EqualsTheMemoisedSolverBitForBitOnRandomInstances) {
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    const Problem problem = testing::random_instance(seed, 5, 4, 14);
    const Mdp mdp(problem);
    expect_search_equals_memoised(mdp, "seed " + std::to_string(seed));
  }
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const Problem problem = testing::random_instance(1000 + seed, 7, 5, 18);
    const Mdp mdp(problem);
    expect_search_equals_memoised(mdp, "deeper, seed " + std::to_string(seed));
  }
}

// `problem` with every skeleton followed by a twin: the same actions under other ids, so that the
// twin's group has the original's distributions and every value of one is a value of the other
// (choices tie exactly, and the tie rule decides by order).
Problem with_twin_skeletons(const Problem& problem) {
  std::vector<Action> actions(problem.actions().begin(), problem.actions().end());
  const auto originals = static_cast<int>(actions.size());
  for (int a = 0; a < originals; ++a) {
    Action twin = problem.action(a);
    twin.id += "'";
    actions.push_back(twin);
  }
  std::vector<std::vector<int>> skeletons;
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    const auto skeleton = problem.skeleton(k);
    skeletons.emplace_back(skeleton.begin(), skeleton.end());
    std::vector<int> twin;
    for (const int a : skeleton) twin.push_back(a + originals);
    skeletons.push_back(twin);
  }
  return {problem.name() + "-twins", problem.deadline(), problem.step_seconds(), actions, skeletons};
}

TEST(SearchSolver, EqualsTheMemoisedSolverBitForBitWhereChoicesTie) {
  for (std::uint64_t seed = 1; seed <= 120; ++seed) {
    const Problem problem = with_twin_skeletons(testing::random_instance(seed, 3, 3, 12));
    const Mdp mdp(problem);
    expect_search_equals_memoised(mdp, "seed " + std::to_string(seed));
  }
  for (const char* name : {"instance1", "instance3"}) {
    const Problem problem = with_twin_skeletons(testing::paper_instance(name));
    const Mdp mdp(problem);
    expect_search_equals_memoised(mdp, name);
  }
}

// Navigation as the layered solver enumerates it (the whole of 22 steps is the benchmark
// SearchNavigationOptimum's): the same bits and first choice, from a small part of the tree.
TEST(SearchSolver, EqualsTheLayeredSolverBitForBitOnNavigation) {
  for (const Steps deadline : {14, 18}) {
    const Problem problem = testing::navigation_with_deadline(deadline);
    const Mdp mdp(problem);
    const LayeredSolution layered = solve_layered(mdp);
    ASSERT_TRUE(layered.exact) << deadline;
    const SearchSolution search = solve_search(mdp);
    ASSERT_TRUE(search.exact) << deadline;
    EXPECT_EQ(search.lower, layered.lower) << deadline;
    EXPECT_EQ(search.first_choice, layered.first_choice) << deadline;
    EXPECT_LT(search.states * 10, layered.states) << deadline;
  }
}

// Wherever a state cap or the stop condition ends the search, the start's interval holds the
// optimum, and its first choice is one of the start's useful choices.
TEST(SearchSolver, EveryCapGivesAnIntervalHoldingTheOptimum) {
  int cut = 0;
  for (std::uint64_t seed = 1; seed <= 120; ++seed) {
    const Problem problem = testing::random_instance(seed, 5, 4, 14);
    const Mdp mdp(problem);
    OptimalSolver memoised(mdp);
    const double optimum = memoised.solve(mdp.start());
    const SearchSolution whole = solve_search(mdp);
    for (const std::uint64_t cap : {std::uint64_t{1}, whole.states / 3 + 1, whole.states / 2 + 1, whole.states}) {
      SCOPED_TRACE("seed " + std::to_string(seed) + ", cap " + std::to_string(cap));
      SearchSolveOptions options;
      options.max_states = cap;
      const SearchSolution capped = solve_search(mdp, options);
      EXPECT_LE(capped.lower, optimum + 1e-15);
      EXPECT_GE(capped.upper, optimum - 1e-15);
      EXPECT_LE(capped.upper, 1.0);
      EXPECT_GE(capped.lower, 0.0);
      if (capped.exact) {
        EXPECT_EQ(capped.lower, optimum);
        continue;
      }
      ++cut;
      EXPECT_LE(capped.states, cap);
      EXPECT_NE(capped.stopped_by.find("cap of " + std::to_string(cap) + " states"), std::string::npos);
      bool useful = false;
      for (const int choice : mdp.useful_choices(mdp.start())) useful = useful || choice == capped.first_choice;
      EXPECT_TRUE(useful) << capped.first_choice;
    }
  }
  EXPECT_GE(cut, 100);
}

// Q*(start, choice) from the memoised solver's values.
double exact_q_at_start(const Mdp& mdp, OptimalSolver& memoised, int choice) {
  double q = 0.0;
  mdp.for_each_outcome(mdp.start(), choice, [&](double p, Status status, const State& next) {
    if (status == Status::success) q += p;
    if (status == Status::running) q += p * memoised.solve(next);
  });
  return q;
}

// Trials back lower and upper ends up along their paths: after any number of them the start's
// interval holds the optimum (its lower end within the tie rule's tolerance: it is the lower end
// of one choice, whose value may pass the optimum by that much where the rule kept an earlier
// choice), its choice's lower end is at most that choice's exact value, and a search after them
// (which settles choices by the trials' lower ends) still gives the memoised solver's bits
// (with backtracking: Backtracking.TheSearchEqualsTheMemoisedSolverBitForBit). On the paper
// instances 300 units of trials close the interval.
void expect_certified_trials(const Mdp& mdp, std::uint64_t budget, const std::string& name) {
  OptimalSolver memoised(mdp);
  const double optimum = memoised.solve(mdp.start());
  BranchAndBoundSearch search(mdp);
  const SearchSolution trials = search.trials(mdp.start(), [&](std::uint64_t work) { return work >= budget; });
  EXPECT_LE(trials.lower, optimum + OptimalSolver::kTieTolerance) << name;
  EXPECT_GE(trials.upper, optimum) << name;
  if (trials.first_choice >= 0) {
    EXPECT_LE(trials.lower, exact_q_at_start(mdp, memoised, trials.first_choice)) << name;
  }
  const SearchSolution after = search.search(mdp.start());
  ASSERT_TRUE(after.exact) << name;
  EXPECT_EQ(after.lower, optimum) << name;
  EXPECT_EQ(after.first_choice, memoised.best_choice(mdp.start()).value_or(-1)) << name;
}

TEST(SearchSolver, TrialsGiveCertifiedBoundsAndTheSearchAfterThemKeepsTheBits) {
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    const Problem problem = testing::random_instance(seed, 5, 4, 14);
    const Mdp mdp(problem);
    for (const std::uint64_t budget : {1U, 4U, 30U, 300U}) {
      expect_certified_trials(mdp, budget, "seed " + std::to_string(seed) + ", " + std::to_string(budget) + " units");
    }
  }
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    for (const std::uint64_t budget : {1U, 10U, 30U, 300U}) expect_certified_trials(mdp, budget, name);
    OptimalSolver memoised(mdp);
    const double optimum = memoised.solve(mdp.start());
    BranchAndBoundSearch search(mdp);
    const SearchSolution one = search.trials(mdp.start(), [](std::uint64_t) { return true; });
    EXPECT_GT(one.upper - one.lower, 0.01) << name;  // the static bounds leave a gap
    const SearchSolution closed = search.trials(mdp.start(), [](std::uint64_t work) { return work >= 300; });
    EXPECT_LE(closed.upper - closed.lower, 1e-9) << name;
    EXPECT_NEAR(exact_q_at_start(mdp, memoised, closed.first_choice), optimum, 1e-9) << name;
    // solve_search with a gap: trials only, until the interval is that narrow.
    SearchSolveOptions narrow;
    narrow.gap = 0.01;
    const SearchSolution within = solve_search(mdp, narrow);
    if (within.exact) continue;  // figure 1's start has one useful choice: solved at once
    EXPECT_EQ(within.stopped_by, "the gap") << name;
    EXPECT_LE(within.upper - within.lower, 0.01) << name;
    EXPECT_LE(within.lower, optimum + OptimalSolver::kTieTolerance) << name;
    EXPECT_GE(within.upper, optimum) << name;
    EXPECT_EQ(within.states, 0U) << name;  // nothing solved exactly
  }
}

TEST(SearchSolver, TheStopConditionEndsItWithAnInterval) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  SearchSolveOptions options;
  options.stop = [] { return true; };
  const SearchSolution stopped = solve_search(mdp, options);
  OptimalSolver memoised(mdp);
  const double optimum = memoised.solve(mdp.start());
  EXPECT_FALSE(stopped.exact);
  EXPECT_EQ(stopped.stopped_by, "the stop condition");
  EXPECT_LE(stopped.lower, optimum);
  EXPECT_GE(stopped.upper, optimum);
  EXPECT_LT(stopped.lower, stopped.upper);
}

TEST(SearchSolver, RefusesMoreSkeletonsThanItsKeysHold) {
  const Problem wide = testing::wide_instance(7, kMaxExactSkeletons + 1, 2, 12);
  const Mdp wide_mdp(wide);
  EXPECT_THROW(solve_search(wide_mdp), UsageError);
}

// A gap finer than the trials certify, negative or NaN is refused; the finest one is met.
TEST(SearchSolver, RefusesAGapFinerThanTheTrialsCertify) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  SearchSolveOptions options;
  for (const double gap : {1e-12, -0.1, 1.5, std::nan("")}) {
    options.gap = gap;
    EXPECT_THROW(solve_search(mdp, options), UsageError) << gap;
  }
  options.gap = SearchSolveOptions::kFinestGap;
  const SearchSolution finest = solve_search(mdp, options);
  EXPECT_LE(finest.upper - finest.lower, SearchSolveOptions::kFinestGap);
  EXPECT_EQ(finest.stopped_by, "the gap");
}

}  // namespace
}  // namespace ontime
