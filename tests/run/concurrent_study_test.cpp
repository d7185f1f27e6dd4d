// The computation-time studies (Figs. 4-6) acting while planning (SPEC §10): the reference's
// episodes are run_monte_carlo's to the episode and near its exact value, the anytime study's
// optimum is ConcurrentSolver's, and the searcher's time per decision reaches it as its
// time-budget (one iteration per search at a time too short for a second, thousands at 10^4 times).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/experiments.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

StudySettings study_settings(std::uint64_t episodes) {
  StudySettings settings;
  settings.episodes = episodes;
  settings.seed = 3;
  settings.threads = 2;
  settings.parameters = ParameterValues{{"backup", "bellman"}, {"leaf", "upper"}};
  return settings;
}

TEST(ConcurrentStudy, TheReferencesEpisodesAreMonteCarlosAndNearItsExactValue) {
  const ConcurrentMdp mdp(testing::paper_instance("instance4").with_acting(Acting::concurrent));
  const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(4'000));
  StudySettings settings = study_settings(episodes);
  settings.parameters.set("iterations", "100");  // the searcher's default budget, kept small
  const ComputeTimeStudy study = compute_time_study(mdp, settings);
  const ConcurrentAllocatorFactory reference = make_concurrent_allocator_factory("dp-rerun", mdp);
  MonteCarloOptions options;
  options.episodes = episodes;
  options.seed = settings.seed;
  options.threads = 1;
  EXPECT_EQ(study.reference.successes, run_monte_carlo(mdp, reference, options).successes);
  const double exact = evaluate_exactly(mdp, *reference()).success_probability;
  const double rate = static_cast<double>(study.reference.successes) / static_cast<double>(episodes);
  EXPECT_NEAR(rate, exact, 4 * std::sqrt(exact * (1 - exact) / static_cast<double>(episodes)));
  EXPECT_EQ(study.searcher.episodes, episodes);
}

TEST(ConcurrentStudy, TheSearchersTimePerDecisionIsItsTimeBudget) {
  const ConcurrentMdp mdp(testing::paper_instance("instance4").with_acting(Acting::concurrent));
  const StudySettings settings = study_settings(static_cast<std::uint64_t>(testing::repetitions_to_check(200)));
  const AnytimeStudy study = anytime_study(mdp, {-3, 4}, settings);
  ConcurrentSolver solver(mdp);
  EXPECT_EQ(study.optimum, solver.solve(mdp.start()));
  EXPECT_GT(study.reference_decision_seconds, 0.0);
  ASSERT_EQ(study.points.size(), 2U);
  const AllocatorKind& mcts = allocator_registry().find("mcts");
  // A thousandth of dp-rerun's decision is below any search's first iteration: one per search.
  EXPECT_EQ(iterations_per_search(mcts, study.points[0].searcher.statistics).value_or(0), 1.0);
  EXPECT_GT(iterations_per_search(mcts, study.points[1].searcher.statistics).value_or(0), 100.0);
  EXPECT_GE(study.points[1].searcher.successes, study.points[0].searcher.successes);
}

TEST(ConcurrentStudy, AnAllocatorWithoutACommitRuleIsRefusedBeforeAnyWork) {
  // Every built-in kind has a commit rule: an extension's kind without one stands in.
  AllocatorKind plan_first_only = allocator_registry().find("dp-rerun");
  plan_first_only.name = "plan-first-only";
  plan_first_only.commit_rule.clear();
  plan_first_only.make_concurrent = {};
  allocator_registry().add(plan_first_only);
  StudySettings settings = study_settings(10);
  settings.reference = "plan-first-only";
  const std::vector<StudyInstance> instances{
      {testing::paper_instance("instance4").with_acting(Acting::concurrent), "instance4.json", "instance4"}};
  try {
    check_study_request(StudyKind::compute_time, instances, settings);
    ADD_FAILURE() << "a kind without a commit rule was taken as the reference acting while planning";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("'plan-first-only' does not act while planning"), std::string::npos)
        << error.what();
  }
  allocator_registry().remove("plan-first-only");
}

}  // namespace
}  // namespace ontime
