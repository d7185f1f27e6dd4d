#include "ontime/learn/online_adaptation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

// Instance 4 with the planning times of the two skeletons' first actions swapped: a prior that
// misleads dp-rerun.
Problem misleading_prior(const Problem& truth) {
  std::vector<Action> actions(truth.actions().begin(), truth.actions().end());
  std::swap(actions[static_cast<std::size_t>(truth.find_action("a1_1"))].planning,
            actions[static_cast<std::size_t>(truth.find_action("a2_1"))].planning);
  std::vector<std::vector<int>> skeletons;
  for (int k = 0; k < truth.skeleton_count(); ++k) {
    skeletons.emplace_back(truth.skeleton(k).begin(), truth.skeleton(k).end());
  }
  return {"prior", truth.deadline(), truth.step_seconds(), std::move(actions), std::move(skeletons)};
}

TEST(OnlineAdaptation, StartsFromThePriorsValueAndTheSameSeedGivesTheSameNumbers) {
  const Problem truth = testing::paper_instance("instance4");
  const Problem prior = misleading_prior(truth);
  AdaptationOptions options;
  options.strength = 2;
  options.episodes = 8;
  options.sequences = 40;
  options.threads = 1;
  const AdaptationResult one = run_adaptation(truth, prior, options);
  options.threads = 2;
  const AdaptationResult two = run_adaptation(truth, prior, options);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_EQ(one.exact, two.exact);
  ASSERT_EQ(one.exact.size(), 8u);
  // Episode 0 plans with the prior: dp-rerun of the prior, judged in the truth.
  const Mdp truth_mdp(truth);
  const Problem planned = with_distributions_of(truth, prior);
  const Mdp planned_mdp(planned);
  DpRerunAllocator allocator(planned_mdp);
  // (To rounding: the posterior's mean rebuilds the prior from its hazards, and the value is a mean
  // over the sequences.)
  EXPECT_NEAR(one.exact.front(), evaluate_exactly(truth_mdp, allocator).success_probability, 1e-12);
  // No allocator beats the optimum; the posterior's plans are better than the prior's.
  OptimalSolver solver(truth_mdp);
  const double optimum = solver.solve(truth_mdp.start());
  for (const double value : one.exact) EXPECT_LE(value, optimum + 1e-12);
  EXPECT_GT(one.exact.back(), one.exact.front());
}

TEST(OnlineAdaptation, WithTheTruthAsThePriorItIsTheAllocatorsValue) {
  const Problem truth = testing::paper_instance("instance2");
  AdaptationOptions options;
  options.episodes = 1;
  options.sequences = 3;
  const AdaptationResult result = run_adaptation(truth, truth, options);
  const Mdp mdp(truth);
  DpRerunAllocator allocator(mdp);
  EXPECT_NEAR(result.exact.at(0), evaluate_exactly(mdp, allocator).success_probability, 1e-12);
  options.strength = 0;
  EXPECT_THROW(run_adaptation(truth, truth, options), UsageError);
  options.strength = 1;
  options.solver = "no-such-allocator";
  EXPECT_THROW(run_adaptation(truth, truth, options), UsageError);
}

// A pooled model of found at 1, found at 2, cut off after 2, found at 1: Kaplan-Meier p(1) = 1/2,
// p(2) = 1/4, horizon 2. A validation group found at 1, then cut off after 1: the first attempt
// is foreseen with p(1) = 1/2; then a_1 = s/2 + 1, b_1 = s/2, so P(T > 1) = (s/2) / (s + 1).
TEST(OnlineAdaptation, StrengthScoresAreThePrequentialLogScore) {
  ConditionalData training;
  training.feature_count = 1;
  training.features = {0, 0, 0, 0};
  training.planning = {1, 2, 2, 1};
  training.found = {1, 1, 0, 1};
  training.execution_seconds = {1, 1, 0, 1};
  training.worlds = {"t", "t", "t", "t"};
  training.actions = {"a", "a", "a", "a"};
  ConditionalFitOptions fit;
  fit.kind = "pooled";
  fit.feature_names = {"f"};
  const auto model = fit_conditional_model(training, fit);
  ConditionalData validation;
  validation.feature_count = 1;
  validation.features = {0, 0};
  validation.planning = {1, 1};
  validation.found = {1, 0};
  validation.execution_seconds = {1, 0};
  validation.worlds = {"v", "v"};
  validation.actions = {"a", "a"};
  const std::vector<double> strengths = {1, 3};
  const std::vector<StrengthScore> scores = score_prior_strengths(*model, validation, strengths);
  ASSERT_EQ(scores.size(), 2u);
  for (const StrengthScore& score : scores) {
    const double s = score.strength;
    EXPECT_NEAR(score.nll, -(std::log(0.5) + std::log(s / 2 / (s + 1))) / 2, 1e-14) << s;
  }
  const std::vector<double> bad = {0};
  EXPECT_THROW(score_prior_strengths(*model, validation, bad), UsageError);
  EXPECT_THROW(score_prior_strengths(*model, validation, {}), UsageError);
}

// Every shipped example with backtracking (SPEC §7), the truth as its own prior: each episode's
// belief learns planning and backtracking together and stays a valid instance, episode 0 is
// dp-rerun's own value, no episode's plan beats the optimum, and the numbers do not depend on the
// thread count.
TEST(OnlineAdaptation, TakesEveryShippedExampleWithBacktracking) {
  for (const char* path : {"data/instances/backtracking/grasp-and-place.json", "data/instances/kitchen-grasps.json",
                           "data/instances/chains/cup-through-the-door.json"}) {
    SCOPED_TRACE(path);
    const Problem truth = load_problem(testing::source_path(path));
    ASSERT_TRUE(truth.has_backtracking());
    AdaptationOptions options;
    options.strength = 2;
    options.episodes = 4;
    options.sequences = 16;
    options.threads = 1;
    const AdaptationResult one = run_adaptation(truth, truth, options);
    options.threads = 2;
    const AdaptationResult two = run_adaptation(truth, truth, options);
    EXPECT_EQ(one.successes, two.successes);
    EXPECT_EQ(one.exact, two.exact);
    ASSERT_EQ(one.exact.size(), 4u);
    const Mdp mdp(truth);
    DpRerunAllocator allocator(mdp);
    EXPECT_NEAR(one.exact.front(), evaluate_exactly(mdp, allocator).success_probability, 1e-12);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    for (const double value : one.exact) EXPECT_LE(value, optimum + 1e-12);
    for (const std::uint64_t successes : one.successes) EXPECT_LE(successes, options.sequences);
  }
}

}  // namespace
}  // namespace ontime
