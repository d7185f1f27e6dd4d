#pragma once
// How well an instance's distributions (a prediction, a pooled fit, a world's own fit) explain
// the attempts of a planner log: the scores of docs/learning.md's held-out evaluation.
//
// Outcomes are taken in whole steps (fitting.hpp's discretisation) up to a horizon H: an attempt
// found at t <= H is the event T = t; found later, or cut off after c >= H steps, is T > H; cut
// off after c < H steps is T > c (right-censored). Execution times over H are "never".
//
// Computes, over the attempts of the actions scored:
// - planning NLL: the mean of -log P(outcome) (P(T = t) for an event, P(T > c) for a censored
//   attempt), in nats: the censoring-aware log score, a strictly proper scoring rule for the
//   coarsened outcome. A probability below `floor` is scored as `floor` (and counted), so that
//   one impossible outcome does not make the mean infinite;
// - integrated Brier score of the survival curve S(t) = P(T > t): the mean over t = 1..H of
//   Graf et al.'s (1999) inverse-probability-of-censoring weighted Brier score, the censoring
//   law estimated by Kaplan-Meier from the same attempts (with the cut-off of a collection as the
//   only censoring it is the plain Brier score of the known statuses); 0 is perfect, 0.25 is a
//   constant 1/2;
// - execution NLL: the mean of -log P(X = x) over the found attempts, with the same floor.
// Cost: O(attempts * H) time, O(H) memory beyond the steps.

#include <cstddef>
#include <span>
#include <string_view>

#include "ontime/model/planner_log.hpp"
#include "ontime/model/problem.hpp"

namespace ontime {

struct AttemptScoreOptions {
  Steps horizon = 0;          // H; 0: the instance's deadline
  double floor = 1e-6;        // the least probability an outcome is scored with
  bool skip_unknown = false;  // attempts of actions the instance lacks: skipped (true) or an error
};

struct AttemptScores {
  std::size_t attempts = 0;  // scored
  std::size_t found = 0;     // of which events within the horizon
  std::size_t censored = 0;  // of which T > c or T > H
  std::size_t skipped = 0;   // of actions the instance lacks (skip_unknown)
  double planning_nll = 0;
  double integrated_brier = 0;
  std::size_t executions = 0;  // found attempts (execution scored)
  double execution_nll = 0;
  std::size_t floored = 0;  // outcomes scored at the floor (planning and execution)
};

// The scores of `instance` on `attempts` (in steps of the instance's step). Throws UsageError for
// bad options, an action the instance lacks (unless skip_unknown; `source` names the log), or no
// attempt to score.
AttemptScores score_attempts(std::span<const RefinementAttempt> attempts, const Problem& instance,
                             std::string_view source, const AttemptScoreOptions& options = {});

}  // namespace ontime
