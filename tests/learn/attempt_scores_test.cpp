#include "ontime/learn/attempt_scores.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// One action: found at step 1 with 0.6, at 2 with 0.2, never with 0.2; executes in 0 or 1 step.
Problem one_action(Steps deadline = 3) {
  const Action action{"a", Distribution::from_pmf({0.0, 0.6, 0.2}), Distribution::from_pmf({0.5, 0.5})};
  return {"one", deadline, 1.0, {action}, {{0}}};
}

RefinementAttempt scored_attempt(std::string action, double planning, bool found, double execution) {
  RefinementAttempt record;
  record.action = std::move(action);
  record.planning_seconds = planning;
  record.found = found;
  record.execution_seconds = execution;
  return record;
}
RefinementAttempt found(double planning, double execution) { return scored_attempt("a", planning, true, execution); }
RefinementAttempt cut_off(double planning) { return scored_attempt("a", planning, false, 0); }

TEST(AttemptScores, HandComputedLogAndBrierScores) {
  // Found at 1 and at 2; cut off after 1 (1.5 s); found at 5, past the horizon 3: T > 3.
  const std::vector<RefinementAttempt> log = {found(1.0, 1.0), found(2.0, 0.0), cut_off(1.5), found(5.0, 0.5)};
  const AttemptScores scores = score_attempts(log, one_action(), "log");
  EXPECT_EQ(scores.attempts, 4U);
  EXPECT_EQ(scores.found, 2U);
  EXPECT_EQ(scores.censored, 2U);
  EXPECT_EQ(scores.floored, 0U);
  // -log of P(T=1) = 0.6, P(T=2) = 0.2, P(T>1) = 0.4, P(T>3) = 0.2.
  EXPECT_NEAR(scores.planning_nll, -(std::log(0.6) + std::log(0.2) + std::log(0.4) + std::log(0.2)) / 4, 1e-15);
  // Executions of 1, 0 and 1 steps, each with probability 1/2.
  EXPECT_EQ(scores.executions, 3U);
  EXPECT_NEAR(scores.execution_nll, std::log(2.0), 1e-15);
  // Censoring by Kaplan-Meier: K(1) = 1, K(2) = K(3) = 2/3 (one of three at risk cut off at 1).
  // S = 0.4, 0.2, 0.2 at t = 1, 2, 3. At t = 1 every status is known, weight 1:
  // (0.16 + 0.36 + 0.36 + 0.36) / 4 = 0.31. At t = 2 and 3: the cut-off attempt's status is
  // unknown; found at 1: 0.04 / K(1); found at 2: 0.04 / K(2); T > 3: 0.64 / K(t):
  // (0.04 + 0.06 + 0.96) / 4 = 0.265. The mean over the three: 0.28.
  EXPECT_NEAR(scores.integrated_brier, 0.28, 1e-15);
}

TEST(AttemptScores, ImpossibleOutcomesAtTheFloorAndAShorterHorizon) {
  // Found at 3 has probability 0, and so has an execution of 2 steps: both scored at the floor.
  const std::vector<RefinementAttempt> log = {found(3.0, 0.0), found(1.0, 2.0)};
  const AttemptScores scores = score_attempts(log, one_action(4), "log", {.floor = 1e-4});
  EXPECT_EQ(scores.floored, 2U);
  EXPECT_NEAR(scores.planning_nll, -(std::log(1e-4) + std::log(0.6)) / 2, 1e-12);
  EXPECT_NEAR(scores.execution_nll, -(std::log(0.5) + std::log(1e-4)) / 2, 1e-12);
  const AttemptScores shorter = score_attempts(log, one_action(4), "log", {.horizon = 1, .floor = 1e-4});
  // Horizon 1: found at 3 is T > 1 (0.4); the execution of 2 steps is over the horizon: P(X > 1) = 0.
  EXPECT_EQ(shorter.found, 1U);
  EXPECT_EQ(shorter.censored, 1U);
  EXPECT_NEAR(shorter.planning_nll, -(std::log(0.4) + std::log(0.6)) / 2, 1e-15);
  EXPECT_NEAR(shorter.execution_nll, -(std::log(0.5) + std::log(1e-4)) / 2, 1e-12);
  // At t = 1 both statuses are known: (1 - 0.4)^2 for T > 1, 0.4^2 for T = 1.
  EXPECT_NEAR(shorter.integrated_brier, (0.36 + 0.16) / 2, 1e-15);
}

TEST(AttemptScores, UnknownActionsAndBadOptions) {
  std::vector<RefinementAttempt> log = {found(1.0, 0.0), scored_attempt("b", 1.0, false, 0)};
  EXPECT_THROW(score_attempts(log, one_action(), "log"), UsageError);
  const AttemptScores scores = score_attempts(log, one_action(), "log", {.skip_unknown = true});
  EXPECT_EQ(scores.attempts, 1U);
  EXPECT_EQ(scores.skipped, 1U);
  EXPECT_THROW(score_attempts(log, one_action(), "log", {.horizon = 4}), UsageError);
  EXPECT_THROW(score_attempts(log, one_action(), "log", {.floor = 0}), UsageError);
  const std::vector<RefinementAttempt> none = {scored_attempt("b", 1.0, false, 0)};
  EXPECT_THROW(score_attempts(none, one_action(), "log", {.skip_unknown = true}), UsageError);
}

}  // namespace
}  // namespace ontime
