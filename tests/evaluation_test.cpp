#include <gtest/gtest.h>

#include <cmath>

#include "ontime/allocator_registry.hpp"
#include "ontime/error.hpp"
#include "ontime/evaluation.hpp"
#include "ontime/random.hpp"
#include "ontime/simulator.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// Chooses uniformly at random: not stationary, so it cannot be evaluated exactly.
class RandomAllocator final : public Allocator {
 public:
  explicit RandomAllocator(int skeletons) : skeletons_(skeletons) {}
  std::string_view name() const noexcept override { return "random"; }
  int choose(const State&) override { return static_cast<int>(generator_() % static_cast<std::uint64_t>(skeletons_)); }
  bool is_stationary() const noexcept override { return false; }

 private:
  int skeletons_;
  SplitMix64 generator_{5};
};

// Sampled rates against exact values, over the five instances and four allocators: each
// deviation is measured in standard errors of the exact p. A correct simulator lands within
// 1.96 of them about 95% of the time and within 4 essentially always.
TEST(Evaluation, MonteCarloAgreesWithExactEvaluation) {
  constexpr std::uint64_t kEpisodes = 20'000;
  int cases = 0, inside = 0;
  for (int i = 1; i <= 5; ++i) {
    const Problem problem = testing::paper_instance("instance" + std::to_string(i));
    const Mdp mdp(problem);
    for (const char* name : {"dp", "dp-rerun", "greedy", "round-robin", "optimal"}) {
      const AllocatorFactory factory = make_allocator_factory(name, mdp);
      const auto allocator = factory();
      const double exact = evaluate_exactly(mdp, *allocator).success_probability;
      MonteCarloOptions options;
      options.episodes = kEpisodes;
      options.seed = 1000 + static_cast<std::uint64_t>(i);
      const MonteCarloResult sampled = run_monte_carlo(mdp, factory, options);
      const double standard_error = std::sqrt(exact * (1 - exact) / kEpisodes);
      const double deviation = std::abs(sampled.success_rate - exact);
      if (standard_error == 0) {
        EXPECT_EQ(sampled.success_rate, exact) << name << " instance" << i;
        continue;
      }
      ++cases;
      inside += deviation <= 1.96 * standard_error;
      EXPECT_LE(deviation, 4.0 * standard_error) << name << " instance" << i << ": " << sampled.success_rate << " vs " << exact;
    }
  }
  // At least 19 of 25 within 1.96 standard errors (a binomial(25, 0.95) falls below that with
  // probability < 0.2%).
  EXPECT_GE(inside, cases - 6) << inside << " of " << cases;
}

TEST(Evaluation, ResultsDoNotDependOnTheThreadCount) {
  const Problem problem = testing::paper_instance("instance3");
  const Mdp mdp(problem);
  const AllocatorFactory factory = make_allocator_factory("dp-rerun", mdp);
  MonteCarloOptions options;
  options.episodes = 5'000;
  options.seed = 77;
  options.threads = 1;
  const MonteCarloResult one = run_monte_carlo(mdp, factory, options);
  for (const unsigned threads : {2U, 3U, 8U}) {
    options.threads = threads;
    const MonteCarloResult many = run_monte_carlo(mdp, factory, options);
    EXPECT_EQ(many.successes, one.successes) << threads;
    EXPECT_EQ(many.decision_time.decisions, one.decision_time.decisions) << threads;
  }
  options.seed = 78;
  EXPECT_NE(run_monte_carlo(mdp, factory, options).successes, one.successes);
}

TEST(Evaluation, ConfidenceIntervalFollowsSpec) {
  EXPECT_DOUBLE_EQ(ci95_half_width(0.5, 100), 1.96 * 0.05);
  EXPECT_DOUBLE_EQ(ci95_half_width(1.0, 100), 0.0);
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  MonteCarloOptions options;
  options.episodes = 1'000;
  const MonteCarloResult result = run_monte_carlo(mdp, make_allocator_factory("greedy", mdp), options);
  EXPECT_DOUBLE_EQ(result.success_rate, static_cast<double>(result.successes) / 1000.0);
  EXPECT_DOUBLE_EQ(result.ci95, ci95_half_width(result.success_rate, 1000));
  EXPECT_GT(result.decision_time.decisions, 1000U);
  EXPECT_LE(result.decision_time.median_us, result.decision_time.p99_us);
}

TEST(Evaluation, EveryAllocatorMeetsTheSameHiddenWorld) {
  const Problem problem = testing::paper_instance("instance1");
  const HiddenWorld first(problem, 123), second(problem, 123), other(problem, 124);
  bool differs = false;
  for (int a = 0; a < problem.action_count(); ++a) {
    EXPECT_EQ(first.planning_time(a), second.planning_time(a));
    EXPECT_EQ(first.execution_time(a), second.execution_time(a));
    differs = differs || first.planning_time(a) != other.planning_time(a);
  }
  EXPECT_TRUE(differs);
  // Effort on an action finds it exactly at its hidden planning time.
  const int action = 0;
  const Steps truth = first.planning_time(action);
  for (Steps spent = 0; spent < truth - 1; ++spent) EXPECT_FALSE(first.observe(action, spent).refined);
  EXPECT_TRUE(first.observe(action, truth - 1).refined);
}

TEST(Evaluation, ExactEvaluationNeedsAStationaryAllocator) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  RandomAllocator random(3);
  EXPECT_THROW(evaluate_exactly(mdp, random), UsageError);
  MonteCarloOptions options;
  options.episodes = 200;
  const MonteCarloResult sampled =
      run_monte_carlo(mdp, [] { return std::make_unique<RandomAllocator>(3); }, options);
  EXPECT_LE(sampled.success_rate, 0.5625 + 4 * std::sqrt(0.25 / 200));
}

TEST(Evaluation, ExactEvaluationStopsAtItsCap) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  const auto allocator = make_allocator_factory("round-robin", mdp)();
  EXPECT_THROW(evaluate_exactly(mdp, *allocator, 10), ResourceLimitError);
}

TEST(Evaluation, ErrorsInsideWorkersReachTheCaller) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  MonteCarloOptions options;
  options.episodes = 1'000;
  options.threads = 2;
  const AllocatorFactory broken = [] { return std::make_unique<RandomAllocator>(9); };  // out of range
  EXPECT_THROW(run_monte_carlo(mdp, broken, options), UsageError);
}

}  // namespace
}  // namespace ontime
