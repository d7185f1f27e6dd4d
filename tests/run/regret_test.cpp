#include "ontime/run/regret.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

MonteCarloResult run_with_regret(const Mdp& mdp, const char* allocator, std::uint64_t episodes, std::uint64_t seed,
                                 unsigned threads = 2) {
  MonteCarloOptions options;
  options.episodes = episodes;
  options.seed = seed;
  options.threads = threads;
  options.time_decisions = false;
  return run_monte_carlo(mdp, with_regret(mdp, make_allocator_factory(allocator, mdp), 0), options);
}

// The optimal allocator loses nothing at any decision: every episode's sum is 0 (to rounding).
TEST(Regret, TheOptimalAllocatorHasNone) {
  for (int i = 1; i <= 5; ++i) {
    const Problem problem = testing::paper_instance("instance" + std::to_string(i));
    const Mdp mdp(problem);
    const auto estimate = regret_estimate(run_with_regret(mdp, "optimal", 500, 3).statistics);
    ASSERT_TRUE(estimate.has_value());
    EXPECT_EQ(estimate->optimum, OptimalSolver(mdp).solve(mdp.start()));
    EXPECT_EQ(estimate->episodes, 500U);
    EXPECT_NEAR(estimate->mean, 0.0, 1e-12) << "instance " << i;
    EXPECT_NEAR(estimate->ci95, 0.0, 1e-12) << "instance " << i;
  }
}

// For stationary allocators the regret is known exactly, V* less the exact evaluation: the
// estimate's 95% interval must hold it (over 4 allocators and 5 instances, at a 95% level each,
// at most a few misses; and every miss by less than twice its half-width), up to the fixed
// point's unit (an allocator that loses the same in every episode has a zero-width interval),
// and the interval is narrower than the sampled success rate's.
TEST(Regret, TheEstimateHoldsTheExactRegretOfStationaryAllocators) {
  int cases = 0, inside = 0, narrower = 0;
  for (int i = 1; i <= 5; ++i) {
    const Problem problem = testing::paper_instance("instance" + std::to_string(i));
    const Mdp mdp(problem);
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    for (const char* name : {"dp", "dp-rerun", "greedy", "round-robin"}) {
      SCOPED_TRACE(std::string(name) + " on instance " + std::to_string(i));
      const auto allocator = make_allocator_factory(name, mdp)();
      const double exact = optimum - evaluate_exactly(mdp, *allocator).success_probability;
      const MonteCarloResult run = run_with_regret(mdp, name, 4'000, 40 + static_cast<std::uint64_t>(i));
      const auto estimate = regret_estimate(run.statistics);
      ASSERT_TRUE(estimate.has_value());
      EXPECT_EQ(estimate->optimum, optimum);
      ++cases;
      const double miss = std::abs(estimate->mean - exact);
      if (miss <= estimate->ci95 + kRegretUnit) ++inside;
      EXPECT_LE(miss, 2.0 * estimate->ci95 + kRegretUnit) << "estimate " << estimate->mean << " exact " << exact;
      if (estimate->ci95 < run.ci95) ++narrower;
    }
  }
  EXPECT_GE(inside, cases - 3);
  EXPECT_GE(narrower, cases - 2);
}

// The losses are exact and the episodes' sums merged in fixed point: the estimate is the same to
// the bit for any thread count.
TEST(Regret, TheThreadCountChangesNothing) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  const auto one = regret_estimate(run_with_regret(mdp, "greedy", 600, 9, 1).statistics);
  const auto two = regret_estimate(run_with_regret(mdp, "greedy", 600, 9, 2).statistics);
  ASSERT_TRUE(one && two);
  EXPECT_GT(one->mean, 0.0);
  EXPECT_EQ(one->mean, two->mean);
  EXPECT_EQ(one->ci95, two->ci95);
}

TEST(Regret, NoCountersNoEstimate) { EXPECT_FALSE(regret_estimate(Statistics{}).has_value()); }

}  // namespace
}  // namespace ontime
