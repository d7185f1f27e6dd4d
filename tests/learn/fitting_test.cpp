#include "ontime/learn/fitting.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "ontime/allocators/optimal.hpp"
#include "ontime/learn/log_sampling.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

// One attempt of a log (RefinementAttempt has more optional fields than these tests use).
RefinementAttempt attempt(std::string action, double planning_seconds, bool found, double execution_seconds = 0,
                          std::optional<std::string> backtrack = std::nullopt) {
  RefinementAttempt made;
  made.action = std::move(action);
  made.planning_seconds = planning_seconds;
  made.found = found;
  made.execution_seconds = execution_seconds;
  made.backtrack = std::move(backtrack);
  return made;
}

// A heavy-tailed planning time: geometric over 1..40 (so partly beyond D = 22), 10% never.
Distribution heavy_tailed_planning() {
  std::vector<double> masses(41, 0.0);
  for (std::size_t t = 1; t <= 40; ++t) masses[t] = 0.9 * 0.15 * std::pow(0.85, static_cast<double>(t - 1));
  return Distribution::from_pmf(masses);
}

std::vector<Steps> draw(const Distribution& distribution, std::size_t count, std::uint64_t seed) {
  SplitMix64 generator(seed);
  std::vector<Steps> values;
  for (std::size_t i = 0; i < count; ++i) values.push_back(distribution.sample(generator));
  return values;
}

// P(T <= t) with everything beyond the deadline counted as "never".
double truncated_cdf(const Distribution& distribution, Steps t, Steps deadline) {
  return distribution.cdf(std::min(t, deadline));
}

// Dvoretzky-Kiefer-Wolfowitz (Massart's constant): with n independent draws, the empirical CDF
// is everywhere within this distance of the true CDF except with probability at most delta.
double dkw_bound(std::size_t n, double delta) {
  return std::sqrt(std::log(2.0 / delta) / (2.0 * static_cast<double>(n)));
}

TEST(Fitting, RoundsTimesUpToWholeSteps) {
  EXPECT_EQ(steps_to_complete(0.0, 1.0), 0);
  EXPECT_EQ(steps_to_complete(0.5, 2.0), 1);
  EXPECT_EQ(steps_to_complete(2.0, 1.0), 2);
  EXPECT_EQ(steps_to_complete(2.001, 1.0), 3);
  EXPECT_EQ(steps_to_complete(0.1 + 0.2, 0.1), 3);  // 0.30000000000000004 s is 3 steps of 0.1 s
  EXPECT_EQ(whole_steps_within(2.0, 1.0), 2);
  EXPECT_EQ(whole_steps_within(1.999, 1.0), 1);
  EXPECT_EQ(whole_steps_within(0.3, 0.1), 3);  // 0.3 / 0.1 = 2.9999999999999996
  EXPECT_EQ(whole_steps_within(0.05, 0.1), 0);
  EXPECT_EQ(steps_to_complete(1e300, 1.0), Distribution::kMaxStep + 1);  // clamped, beyond every deadline
}

TEST(Fitting, CensoredAttemptsLowerTheHazardInsteadOfBeingDropped) {
  // Two found at step 1, two cut off after the whole deadline: half the mass is "never".
  const Distribution fitted = estimate_planning({{1, 1}, {4, 4}, {}, {}}, 4);
  EXPECT_DOUBLE_EQ(fitted.pmf(1), 0.5);
  EXPECT_DOUBLE_EQ(fitted.never(), 0.5);
  // Found at 1 and 3, two cut off after 2 steps: h(1) = 1/4, h(2) = 0/3, h(3) = 1/1.
  const Distribution km = estimate_planning({{1, 3}, {2, 2}, {}, {}}, 4);
  EXPECT_DOUBLE_EQ(km.pmf(1), 0.25);
  EXPECT_DOUBLE_EQ(km.pmf(2), 0.0);
  EXPECT_DOUBLE_EQ(km.pmf(3), 0.75);
  EXPECT_NEAR(km.never(), 0.0, 1e-15);
  // Nobody at risk after the last cut-off: the log says nothing about that mass, so "never".
  const Distribution unknown = estimate_planning({{1}, {2}, {}, {}}, 5);
  EXPECT_DOUBLE_EQ(unknown.pmf(1), 0.5);
  EXPECT_DOUBLE_EQ(unknown.never(), 0.5);
  // Found after the deadline, or cut off after more steps than it: only survival is known.
  const Distribution late = estimate_planning({{2, 9}, {30}, {}, {}}, 3);
  EXPECT_NEAR(late.pmf(2), 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(late.never(), 2.0 / 3.0, 1e-15);
  // An attempt cut off before its first step ended carries no information.
  const Distribution early = estimate_planning({{1, 2}, {0, 0, 0}, {}, {}}, 2);
  EXPECT_DOUBLE_EQ(early.pmf(1), 0.5);
  EXPECT_DOUBLE_EQ(early.pmf(2), 0.5);
}

// Competing risks (SPEC §7): found at 1, backtracked at 1 (blaming "a"), found at 2, cut off after
// 1. At step 1 four are at risk: h = g = 1/4, so p(1) = q(1) = 1/4 and S(1) = 1/2; one is left at
// step 2 and is found: p(2) = 1/2. Without backtracks the estimate is Kaplan-Meier's, bit for bit.
TEST(Fitting, BacktracksAreASecondKindOfEventNotACutOff) {
  PlanningSample sample;
  sample.found = {1, 2};
  sample.censored = {1};
  sample.backtracked = {1};
  sample.blamed = {"a"};
  const AttemptEstimate estimate = estimate_attempts(sample, 3);
  EXPECT_DOUBLE_EQ(estimate.planning.pmf(1), 0.25);
  EXPECT_DOUBLE_EQ(estimate.planning.pmf(2), 0.5);
  EXPECT_DOUBLE_EQ(estimate.backtrack.pmf(1), 0.25);
  EXPECT_DOUBLE_EQ(estimate.backtrack.never(), 0.75);
  EXPECT_DOUBLE_EQ(estimate.planning.never() + (1 - estimate.backtrack.never()), 0.25 + 0.25);
  ASSERT_EQ(estimate.culprits.size(), 1U);
  EXPECT_EQ(estimate.culprits[0].id, "a");
  EXPECT_DOUBLE_EQ(estimate.culprits[0].probability, 1.0);
  PlanningSample plain;
  plain.found = {1, 2, 2, 5};
  plain.censored = {0, 3};
  EXPECT_EQ(estimate_attempts(plain, 6, 0.5).planning, estimate_planning(plain, 6, 0.5));
  EXPECT_EQ(estimate_attempts(plain, 6).backtrack.never(), 1.0);
  sample.blamed.clear();
  EXPECT_THROW(estimate_attempts(sample, 3), UsageError);
}

// A log with backtrack records fits an instance that backtracks; a record blaming an action that
// is not before it on the skeletons' path is refused naming the log.
TEST(Fitting, FitsBacktrackingFromTheLog) {
  const std::vector<RefinementAttempt> log{attempt("a", 1, true, 1), attempt("b", 2, false, 0, "a"),
                                           attempt("b", 1, false, 0, "a"), attempt("b", 3, true, 1),
                                           attempt("b", 1, true, 2)};
  const SkeletonList skeletons{"skeletons.json", {{"a", "b"}}};
  FitOptions options;
  options.deadline = 5;
  const FitResult fit = fit_problem(log, "log.jsonl", skeletons, options);
  ASSERT_TRUE(fit.problem.has_backtracking());
  const Action& b = fit.problem.action(1);
  EXPECT_DOUBLE_EQ(b.backtrack.pmf(1), 0.25);  // at step 1: 4 at risk, one backtracks, one is found
  EXPECT_DOUBLE_EQ(b.planning.pmf(1), 0.25);
  EXPECT_DOUBLE_EQ(b.backtrack.pmf(2), 0.25);  // at step 2: 2 at risk, one backtracks
  EXPECT_DOUBLE_EQ(b.planning.pmf(3), 0.25);
  EXPECT_EQ(fit.actions[1].backtracked, 2U);
  EXPECT_EQ(fit.actions[1].censored, 0U);
  EXPECT_FALSE(fit.problem.action(0).backtrack.never() < 1.0);

  const std::vector<RefinementAttempt> wrong{attempt("a", 1, false, 0, "b"), attempt("b", 1, true, 1)};
  try {
    fit_problem(wrong, "log.jsonl", skeletons, options);
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(
        std::string(error.what()).find("log.jsonl: action 'a': blames 'b': the culprit comes after the failing action"),
        std::string::npos)
        << error.what();
  }
}

// A log drawn from an instance that backtracks fits back to it: the planning and backtrack masses
// and the culprits' shares within a few standard errors of 20,000 attempts, and the optimum near.
TEST(Fitting, SampledBacktrackingLogsFitBack) {
  const Distribution one = Distribution::from_pmf({0.0, 1.0});
  std::vector<Action> actions{
      {"a", one, one},
      {"b", Distribution::from_pmf({0.0, 0.2, 0.2}), one, Distribution::from_pmf({0.0, 0.3, 0.1}),
       std::vector<Culprit>{{"a", 1.0}}},
      {"c", Distribution::from_pmf({0.0, 0.3, 0.3}), one, Distribution::from_pmf({0.0, 0.0, 0.4}),
       std::vector<Culprit>{{"a", 0.25}, {"b", 0.75}}}};
  const Problem original("bt", 8, 1.0, std::move(actions), {{0, 1, 2}, {0, 1}});
  LogSamplingOptions sampling;
  sampling.attempts_per_action = 20'000;
  sampling.seed = 3;
  const std::vector<RefinementAttempt> log = sample_planner_log(original, sampling);
  FitOptions options;
  options.deadline = 8;
  const FitResult fit = fit_problem(log, "log", SkeletonList{"s", {{"a", "b", "c"}, {"a", "b"}}}, options);
  const double error = 4 * std::sqrt(0.25 / 20'000.0);  // four standard errors of a proportion
  for (int a = 1; a <= 2; ++a) {
    for (Steps t = 1; t <= 2; ++t) {
      EXPECT_NEAR(fit.problem.action(a).planning.pmf(t), original.action(a).planning.pmf(t), error) << a << " " << t;
      EXPECT_NEAR(fit.problem.action(a).backtrack.pmf(t), original.action(a).backtrack.pmf(t), error) << a << " " << t;
    }
  }
  ASSERT_EQ(fit.problem.culprits(2).size(), 2U);
  for (const Problem::CulpritIndex& culprit : fit.problem.culprits(2)) {
    EXPECT_NEAR(culprit.probability, culprit.action == 0 ? 0.25 : 0.75, 4 * std::sqrt(0.25 / 8'000.0));
  }
  // Coupling: an episode starts at most D attempts, and each of action a's differs between the two
  // instances with probability at most the total variation of its outcome laws (found at t,
  // backtracked at t blaming c, never); the executions are fitted exactly here.
  double largest_tv = 0;
  for (int a = 0; a < 3; ++a) {
    const Action& x = original.action(a);
    const Action& y = fit.problem.action(a);
    double tv = std::abs(x.planning.never() - x.backtrack.pmf(1) - x.backtrack.pmf(2) -
                         (y.planning.never() - y.backtrack.pmf(1) - y.backtrack.pmf(2)));
    for (Steps t = 1; t <= 8; ++t) {
      tv += std::abs(x.planning.pmf(t) - y.planning.pmf(t));
      for (int c = 0; c < 2; ++c) {
        const auto weight = [c](const Problem& p, int action) {
          for (const Problem::CulpritIndex& culprit : p.culprits(action)) {
            if (culprit.action == c) return culprit.probability;
          }
          return 0.0;
        };
        tv += std::abs(x.backtrack.pmf(t) * weight(original, a) - y.backtrack.pmf(t) * weight(fit.problem, a));
      }
    }
    ASSERT_EQ(x.execution, y.execution);
    largest_tv = std::max(largest_tv, tv / 2);
  }
  const Mdp original_mdp(original), fitted_mdp(fit.problem);
  OptimalSolver exact(original_mdp), fitted(fitted_mdp);
  EXPECT_NEAR(fitted.solve(fitted_mdp.start()), exact.solve(original_mdp.start()), 8 * largest_tv);
}

TEST(Fitting, LaplaceSmoothingIsAddAlphaOverTheCategories) {
  // Uncensored: exactly (count + alpha) / (n + alpha (D + 1)) over 1..D and "never".
  const Distribution plain = estimate_planning({{1, 1, 2}, {}, {}, {}}, 2, 1.0);
  EXPECT_NEAR(plain.pmf(1), 3.0 / 6.0, 1e-15);
  EXPECT_NEAR(plain.pmf(2), 2.0 / 6.0, 1e-15);
  EXPECT_NEAR(plain.never(), 1.0 / 6.0, 1e-15);
  // With a cut-off attempt: h(1) = (1 + 1) / (2 + 3), h(2) = (0 + 1) / (0 + 2).
  const Distribution censored = estimate_planning({{1}, {1}, {}, {}}, 2, 1.0);
  EXPECT_NEAR(censored.pmf(1), 0.4, 1e-15);
  EXPECT_NEAR(censored.pmf(2), 0.3, 1e-15);
  EXPECT_NEAR(censored.never(), 0.3, 1e-15);
  // Execution: categories 0..D and "never"; times beyond D are "never".
  const std::vector<Steps> executions{0, 2, 2, 5};
  const Distribution execution = estimate_execution(executions, 3);
  EXPECT_DOUBLE_EQ(execution.pmf(0), 0.25);
  EXPECT_DOUBLE_EQ(execution.pmf(2), 0.5);
  EXPECT_DOUBLE_EQ(execution.never(), 0.25);
  const std::vector<Steps> one{0};
  const Distribution smoothed = estimate_execution(one, 1, 1.0);
  EXPECT_DOUBLE_EQ(smoothed.pmf(0), 0.5);
  EXPECT_DOUBLE_EQ(smoothed.pmf(1), 0.25);
  EXPECT_DOUBLE_EQ(smoothed.never(), 0.25);
  // No data and no smoothing: nothing is known to be executable.
  EXPECT_DOUBLE_EQ(estimate_execution(std::vector<Steps>{}, 4).never(), 1.0);
}

TEST(Fitting, RecoversAKnownPlanningDistributionWithinTheDkwBound) {
  const Steps deadline = 22;
  const Distribution truth = heavy_tailed_planning();
  const std::size_t n = 20'000;
  PlanningSample sample;
  for (const Steps t : draw(truth, n, 11)) {
    if (t == kNever) {
      sample.censored.push_back(deadline);  // cut off at the deadline
    } else {
      sample.found.push_back(t);
    }
  }
  const Distribution fitted = estimate_planning(sample, deadline);
  // Without censoring before D the estimate is the empirical CDF: DKW applies (delta = 1e-6).
  const double bound = dkw_bound(n, 1e-6);
  for (Steps t = 0; t <= deadline; ++t) {
    EXPECT_LE(std::abs(fitted.cdf(t) - truncated_cdf(truth, t, deadline)), bound) << "step " << t;
  }
  EXPECT_LE(std::abs(fitted.never() - truth.survival(deadline)), bound);
}

TEST(Fitting, RecoversAKnownDistributionFromCensoredData) {
  // Every attempt is also cut off at an independent time uniform over 0..30 steps; about 30%
  // of them end cut off. Kaplan-Meier stays within 5 Greenwood standard errors of the truth at
  // every step (normal approximation: each step fails with probability < 6e-7), while
  // dropping the cut-off attempts is biased far beyond that.
  const Steps deadline = 22;
  const Distribution truth = heavy_tailed_planning();
  const std::size_t n = 20'000;
  SplitMix64 cutoffs(5);
  PlanningSample sample;
  std::vector<Steps> found_only;
  for (const Steps t : draw(truth, n, 12)) {
    const auto cutoff = static_cast<Steps>(31 * uniform01(cutoffs));
    if (t != kNever && t <= cutoff) {
      sample.found.push_back(t);
      found_only.push_back(t);
    } else {
      sample.censored.push_back(cutoff);
    }
  }
  ASSERT_GT(sample.censored.size(), n / 4);
  const Distribution fitted = estimate_planning(sample, deadline);
  // Greenwood: Var S(t) = S(t)^2 sum_{s<=t} d_s / (n_s (n_s - d_s)).
  std::vector<double> found_at(deadline + 1, 0.0), leaving_at(deadline + 1, 0.0);
  for (const Steps t : sample.found) (t <= deadline ? found_at[t] : leaving_at[deadline]) += 1;
  for (const Steps c : sample.censored) leaving_at[std::min(c, deadline)] += 1;
  double at_risk = static_cast<double>(n) - leaving_at[0];
  double greenwood_sum = 0;
  double largest_naive_error = 0, largest_bound = 0;
  PlanningSample naive{found_only, {}, {}, {}};
  const Distribution dropped = estimate_planning(naive, deadline);
  for (Steps t = 1; t <= deadline; ++t) {
    if (at_risk > found_at[t]) greenwood_sum += found_at[t] / (at_risk * (at_risk - found_at[t]));
    at_risk -= found_at[t] + leaving_at[t];
    const double survival = fitted.survival(t);
    const double bound = 5.0 * survival * std::sqrt(greenwood_sum);
    EXPECT_LE(std::abs(fitted.cdf(t) - truncated_cdf(truth, t, deadline)), bound) << "step " << t;
    largest_bound = std::max(largest_bound, bound);
    largest_naive_error = std::max(largest_naive_error, std::abs(dropped.cdf(t) - truncated_cdf(truth, t, deadline)));
  }
  EXPECT_GT(largest_naive_error, 5 * largest_bound);
}

TEST(Fitting, RecoversAKnownExecutionDistributionWithinTheDkwBound) {
  const Steps deadline = 22;
  const Distribution truth = Distribution::from_pmf(
      {0.05, 0.1, 0.3, 0.25, 0.1, 0.05, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.05, 0.05});
  const std::size_t n = 20'000;
  std::vector<Steps> sample;
  for (const Steps x : draw(truth, n, 13)) sample.push_back(x == kNever ? deadline + 1 : x);
  const Distribution fitted = estimate_execution(sample, deadline);
  const double bound = dkw_bound(n, 1e-6);
  for (Steps x = 0; x <= deadline; ++x) {
    EXPECT_LE(std::abs(fitted.cdf(x) - truncated_cdf(truth, x, deadline)), bound) << "step " << x;
  }
  EXPECT_NEAR(fitted.never(), truth.survival(deadline), bound);
}

TEST(Fitting, RejectsBadEstimationOptions) {
  EXPECT_THROW(estimate_planning({{1}, {}, {}, {}}, 0), UsageError);
  EXPECT_THROW(estimate_planning({{1}, {}, {}, {}}, 5, -1.0), UsageError);
  EXPECT_THROW(estimate_planning({{0}, {}, {}, {}}, 5), UsageError);
  EXPECT_THROW(estimate_execution(std::vector<Steps>{-1}, 5), UsageError);
}

SkeletonList skeletons(std::vector<std::vector<std::string>> list) {
  return SkeletonList{"skeletons.json", std::move(list)};
}

TEST(Fitting, FitsAProblemForTheSkeletons) {
  const std::vector<RefinementAttempt> log{
      {"a", 0.4, true, 1.5, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt},   // 1 step, executes in 2
      {"a", 1.6, true, 0.0, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt},   // 2 steps, executes in 0
      {"a", 3.0, false, 0.0, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt},  // cut off after 3 steps
      {"b", 0.9, true, 9.0, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt},   // executes in 9 > D: never
      {"unused", 1.0, true, 1.0, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt},
  };
  FitOptions options;
  options.step_seconds = 1.0;
  options.deadline = 3;
  options.name = "fitted";
  const FitResult fit = fit_problem(log, "log.jsonl", skeletons({{"a", "b"}, {"a"}}), options);
  const Problem& problem = fit.problem;
  EXPECT_EQ(problem.name(), "fitted");
  EXPECT_EQ(problem.deadline(), 3);
  ASSERT_EQ(problem.action_count(), 2);  // "unused" is left out
  ASSERT_EQ(fit.actions.size(), 2u);
  EXPECT_EQ(fit.actions[0].id, "a");
  EXPECT_EQ(fit.actions[0].attempts, 3u);
  EXPECT_EQ(fit.actions[0].found, 2u);
  EXPECT_EQ(fit.actions[0].censored, 1u);
  const Action& a = problem.action(problem.find_action("a"));
  EXPECT_NEAR(a.planning.pmf(1), 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(a.planning.pmf(2), 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(a.planning.never(), 1.0 / 3.0, 1e-15);
  EXPECT_DOUBLE_EQ(a.execution.pmf(0), 0.5);
  EXPECT_DOUBLE_EQ(a.execution.pmf(2), 0.5);
  const Action& b = problem.action(problem.find_action("b"));
  EXPECT_DOUBLE_EQ(b.planning.pmf(1), 1.0);
  EXPECT_DOUBLE_EQ(b.execution.never(), 1.0);
  EXPECT_EQ(problem.skeleton_count(), 2);
}

TEST(Fitting, NamesTheSkeletonWhoseActionTheLogLacks) {
  const std::vector<RefinementAttempt> log{
      {"a", 0.4, true, 1.5, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt}};
  FitOptions options;
  options.deadline = 3;
  try {
    fit_problem(log, "log.jsonl", skeletons({{"a"}, {"a", "c"}}), options);
    FAIL() << "accepted a skeleton action without records";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "skeletons.json");
    EXPECT_EQ(error.place(), "skeletons[1][1]");
    EXPECT_NE(error.rule().find("'c' has no record in the log log.jsonl"), std::string::npos) << error.what();
  }
  options.laplace = -1;
  EXPECT_THROW(fit_problem(log, "log.jsonl", skeletons({{"a"}}), options), UsageError);
}

// The probability that two versions of one distribution differ under a maximal coupling,
// over the outcomes the MDP can tell apart (everything beyond the deadline is "never").
double total_variation(const Distribution& p, const Distribution& q, Steps deadline) {
  double sum = std::abs(p.survival(deadline) - q.survival(deadline));
  for (Steps t = 0; t <= deadline; ++t) sum += std::abs(p.pmf(t) - q.pmf(t));
  return sum / 2;
}

TEST(Fitting, SampledLogsFitBackToTheInstanceOptimum) {
  // Coupling argument: run both instances' hidden worlds from maximal couplings of every
  // action's distributions; under any policy the episodes differ only when some coupled draw
  // differs, so |V* - V*_fitted| <= sum of the total variations. The project's target is 0.01.
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem original = testing::paper_instance(name);
    LogSamplingOptions sampling;
    sampling.attempts_per_action = 20'000;
    sampling.seed = 21;
    const std::vector<RefinementAttempt> log = sample_planner_log(original, sampling);
    SkeletonList list{"instance", {}};
    for (int k = 0; k < original.skeleton_count(); ++k) {
      std::vector<std::string>& ids = list.skeletons.emplace_back();
      for (const int action : original.skeleton(k)) ids.push_back(original.action(action).id);
    }
    FitOptions options;
    options.step_seconds = original.step_seconds();
    options.deadline = original.deadline();
    options.name = name;
    const Problem fitted = fit_problem(log, "sampled", list, options).problem;
    double coupling_bound = 0;
    for (int a = 0; a < original.action_count(); ++a) {
      if (original.position(a) < 0) continue;
      const Action& truth = original.action(a);
      const Action& estimate = fitted.action(fitted.find_action(truth.id));
      coupling_bound += total_variation(truth.planning, estimate.planning, original.deadline()) +
                        total_variation(truth.execution, estimate.execution, original.deadline());
    }
    const Mdp original_mdp(original), fitted_mdp(fitted);
    OptimalSolver original_solver(original_mdp), fitted_solver(fitted_mdp);
    const double difference =
        std::abs(original_solver.solve(original_mdp.start()) - fitted_solver.solve(fitted_mdp.start()));
    EXPECT_LE(difference, coupling_bound) << name;
    EXPECT_LE(difference, 0.01) << name;
  }
}

// Whatever the step, the log sampled from an instance is one the log reader accepts.
TEST(Fitting, SampledLogsAlwaysParseWithTheLogReader) {
  const Problem paper = testing::paper_instance("instance1");
  for (const double step : {1e300, 1e-300, 4.9e-324, 0.37}) {
    const Problem scaled(paper.name(), paper.deadline(), step, {paper.actions().begin(), paper.actions().end()},
                         [&paper] {
                           std::vector<std::vector<int>> skeletons;
                           for (int k = 0; k < paper.skeleton_count(); ++k) {
                             const auto skeleton = paper.skeleton(k);
                             skeletons.emplace_back(skeleton.begin(), skeleton.end());
                           }
                           return skeletons;
                         }());
    LogSamplingOptions sampling;
    sampling.attempts_per_action = 200;
    const std::vector<RefinementAttempt> log = sample_planner_log(scaled, sampling);
    std::string text;
    for (const RefinementAttempt& attempt : log) text += planner_log_line(attempt);
    EXPECT_EQ(parse_planner_log(text, "sampled").size(), log.size()) << step;
  }
}

TEST(Fitting, ATimeBeyondTheLargestDoubleIsRefusedBeforeSampling) {
  const Problem paper = testing::paper_instance("figure1");
  std::vector<std::vector<int>> skeletons;
  for (int k = 0; k < paper.skeleton_count(); ++k) {
    const auto skeleton = paper.skeleton(k);
    skeletons.emplace_back(skeleton.begin(), skeleton.end());
  }
  const Problem scaled(paper.name(), paper.deadline(), 1e300, {paper.actions().begin(), paper.actions().end()},
                       skeletons);
  LogSamplingOptions sampling;
  sampling.cutoff_steps = 2'000'000'000;
  EXPECT_THROW(sample_planner_log(scaled, sampling), UsageError);
}

TEST(Fitting, ALaplaceAlphaThatSwampsTheLogIsRefused) {
  const Problem paper = testing::paper_instance("figure1");
  LogSamplingOptions sampling;
  sampling.attempts_per_action = 50;
  const std::vector<RefinementAttempt> log = sample_planner_log(paper, sampling);
  SkeletonList list{"instance", {}};
  for (int k = 0; k < paper.skeleton_count(); ++k) {
    std::vector<std::string>& ids = list.skeletons.emplace_back();
    for (const int action : paper.skeleton(k)) ids.push_back(paper.action(action).id);
  }
  FitOptions options;
  options.deadline = paper.deadline();
  options.laplace = 1e308;
  try {
    fit_problem(log, "log", list, options);
    ADD_FAILURE() << "alpha 1e308 was accepted";
  } catch (const UsageError& error) {
    EXPECT_EQ(std::string(error.what()),
              "laplace: the Laplace smoothing alpha must be between 0 and 1e+06, larger values swamp the log (got "
              "1e+308)");
  }
  options.laplace = 1e6;  // the largest alpha: the fitted PMFs keep their mass
  const Problem fitted = fit_problem(log, "log", list, options).problem;
  for (const Action& action : fitted.actions()) {
    double planning = 0;
    for (const double mass : action.planning.masses()) planning += mass;
    EXPECT_GT(planning, 0.1) << action.id;
  }
}

TEST(Fitting, AStreamedLogHasTheSameAttemptsInTheSameOrder) {
  const Problem paper = testing::paper_instance("instance3");
  LogSamplingOptions options;
  options.attempts_per_action = 50;
  options.seed = 9;
  const std::vector<RefinementAttempt> whole = sample_planner_log(paper, options);
  std::vector<std::string> streamed;
  sample_planner_log(paper, options,
                     [&](const RefinementAttempt& attempt) { streamed.push_back(planner_log_line(attempt)); });
  ASSERT_EQ(streamed.size(), whole.size());
  for (std::size_t i = 0; i < whole.size(); ++i) EXPECT_EQ(streamed[i], planner_log_line(whole[i])) << i;
}

}  // namespace
}  // namespace ontime
