#include "ontime/allocators/branch_and_bound.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/util/random.hpp"
#include "support/exact_q.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// Along episodes drawn from the model, every decision's certified gap is at least its true loss
// V*(s) - Q*(s, choice), whatever the budget; with a budget the search finishes in, the gap is 0
// and the choice attains V*.
void expect_sound_gaps(const Mdp& mdp, std::uint64_t iterations, std::uint64_t seed, int& cut_decisions,
                       double trial_share) {
  OptimalSolver solver(mdp);
  BranchAndBoundOptions options;
  options.budget = DecisionBudget::iterations(iterations);
  options.trial_share = trial_share;
  BranchAndBoundAllocator allocator(mdp, options);
  SplitMix64 generator(seed);
  for (int episode = 0; episode < 20; ++episode) {
    allocator.begin_episode(seed + static_cast<std::uint64_t>(episode));
    State state = mdp.start();
    for (;;) {
      if (mdp.useful_choices(state).empty()) break;
      const int choice = allocator.choose(state);
      const double optimum = solver.solve(state);
      const double loss = optimum - testing::exact_q(mdp, solver, state, choice);
      EXPECT_GE(allocator.last_gap(), loss - 1e-12) << "iterations " << iterations;
      if (allocator.last_gap() == 0.0) {
        EXPECT_NEAR(loss, 0.0, 1e-12) << "iterations " << iterations;
      } else {
        ++cut_decisions;
      }
      if (mdp.apply(state, choice, mdp.sample_observation(state, choice, generator)) != Status::running) break;
    }
  }
}

TEST(BranchAndBound, TheCertifiedGapIsNeverBelowTheTrueLoss) {
  int cut_decisions = 0;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = testing::random_instance(seed, 5, 4, 14);
    const Mdp mdp(problem);
    // Search alone, trials then search, trials alone.
    for (const std::uint64_t iterations : {1U, 5U, 50U}) {
      for (const double share : {0.0, 0.5, 1.0}) expect_sound_gaps(mdp, iterations, seed, cut_decisions, share);
    }
  }
  for (const char* name : {"instance1", "instance3"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    for (const std::uint64_t iterations : {1U, 10U, 100U}) {
      for (const double share : {0.0, 0.5, 1.0}) expect_sound_gaps(mdp, iterations, 7, cut_decisions, share);
    }
  }
  EXPECT_GE(cut_decisions, 600);  // the small budgets do cut searches short
}

// With the default budget the paper's instances are solved exactly at every decision: the
// choices are the optimal allocator's, and the success rate over the same episodes is its rate.
TEST(BranchAndBound, ItsDefaultBudgetIsTheOptimumOnThePaperInstances) {
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    MonteCarloOptions monte_carlo;
    monte_carlo.episodes = 2000;
    monte_carlo.seed = 11;
    monte_carlo.threads = 1;
    const MonteCarloResult searched =
        run_monte_carlo(mdp, make_allocator_factory("branch-and-bound", mdp, {}), monte_carlo);
    const MonteCarloResult optimal = run_monte_carlo(mdp, make_allocator_factory("optimal", mdp, {}), monte_carlo);
    EXPECT_EQ(searched.successes, optimal.successes) << name;
    EXPECT_EQ(searched.statistics.find("exact_decisions"), searched.statistics.find(kSearchesCounter)) << name;
    EXPECT_EQ(searched.statistics.find("max_gap").value_or(-1.0), 0.0) << name;
  }
}

// A budget of a stop condition alone (the caller's clock) has no size to share: trials and
// search take turns in rounds, so the search runs however soon it trips (a share of it would
// give the trials all). On navigation neither finishes in 5,000 units.
TEST(BranchAndBound, AStopConditionAloneStillRunsTheSearch) {
  const Problem problem = load_problem(testing::source_path("data/instances/navigation.json"));
  const Mdp mdp(problem);
  BranchAndBoundAllocator allocator(mdp, {});
  allocator.begin_episode(1);
  std::uint64_t calls = 0;
  const int choice = allocator.choose(mdp.start(), DecisionBudget::until([&calls] { return ++calls >= 5'000; }));
  Statistics statistics;
  allocator.collect_statistics(statistics);
  const double work = statistics.find(kIterationsCounter).value_or(0.0);
  const double trial_work = statistics.find("trial_work").value_or(-1.0);
  EXPECT_EQ(work, 5'000.0);  // the condition is asked after every unit
  EXPECT_GT(trial_work, 0.0);
  // At least the first round's search share.
  EXPECT_GE(work - trial_work, static_cast<double>(BranchAndBoundAllocator::kFirstRound) / 2.0);
  EXPECT_EQ(statistics.find("exact_decisions").value_or(-1.0), 0.0);
  EXPECT_GT(allocator.last_gap(), 0.0);
  const ChoiceList useful = mdp.useful_choices(mdp.start());
  EXPECT_NE(std::find(useful.begin(), useful.end(), choice), useful.end());
}

TEST(BranchAndBound, SameSeedSameDecisionsWhateverTheThreads) {
  const Problem problem = testing::random_instance(21, 5, 4, 14);
  const Mdp mdp(problem);
  const AllocatorFactory factory = make_allocator_factory("branch-and-bound", mdp, {{"iterations", "2"}});
  MonteCarloOptions monte_carlo;
  monte_carlo.episodes = 400;
  monte_carlo.seed = 5;
  monte_carlo.threads = 1;
  const MonteCarloResult one = run_monte_carlo(mdp, factory, monte_carlo);
  monte_carlo.threads = 2;
  const MonteCarloResult two = run_monte_carlo(mdp, factory, monte_carlo);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_EQ(one.statistics.find(kIterationsCounter), two.statistics.find(kIterationsCounter));
  // (A sum of doubles over two threads' shares: equal up to the order of the additions.)
  EXPECT_NEAR(one.statistics.find("gap_sum").value_or(-1.0), two.statistics.find("gap_sum").value_or(1.0), 1e-9);
  EXPECT_GT(one.statistics.find("gap_sum").value_or(0.0), 0.0);
}

}  // namespace
}  // namespace ontime
