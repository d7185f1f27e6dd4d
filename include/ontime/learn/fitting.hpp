#pragma once
// Learning an instance from a planner log (paper §V, model-based approach): each action's
// planning- and execution-time distributions estimated by maximum likelihood, in whole steps.
//
// Discretisation. A time of s seconds takes ceil(s / step) steps (a planning time of 0 counts
// as 1 step: the first step found it). An attempt cut off after s seconds without a motion
// survived floor(s / step) whole steps. A relative slack of 1e-9 absorbs the rounding of
// values written as decimals (3 * 0.1 seconds is 3 steps of 0.1, not 4).
//
// Planning time, with right-censoring. The planning distribution over the categories
// 1..D and "never" (> D) is estimated through its discrete hazard: at step t, n_t attempts are
// still at risk (found at t or later, or cut off after t or later steps) and d_t of them are
// found at t. The maximum-likelihood hazard is d_t / n_t, and p(t) = h(t) * prod_{s<t} (1-h(s))
// (the Kaplan-Meier estimator): an attempt cut off after c steps counts as "not yet" at every
// step up to c and is never dropped. With Laplace smoothing alpha, h(t) = (d_t + alpha) /
// (n_t + alpha (D - t + 2)), which is exactly the add-alpha estimate over the D + 1 categories
// when nothing is censored. Where no attempt is at risk (and alpha = 0) the hazard is 0: mass
// the log says nothing about goes to "never". Mass beyond the deadline is "never".
//
// Execution time (never censored): the empirical PMF over 0..D, times beyond D counting as
// "never", with add-alpha smoothing over the D + 2 categories.
//
// Backtracking (SPEC §7): a record that says which earlier action it blamed ended its attempt
// then, without a motion: an event of the second kind (estimate_attempts below), not a cut-off.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "ontime/model/distribution.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/model/skeleton_file.hpp"

namespace ontime {

// Steps to complete s seconds of work: ceil(s / step), with the slack above; s >= 0, step > 0.
Steps steps_to_complete(double seconds, double step_seconds);
// Whole steps that fit in s seconds: floor(s / step), with the slack above.
Steps whole_steps_within(double seconds, double step_seconds);

// Planning observations of one action, in steps.
struct PlanningSample {
  std::vector<Steps> found;     // planning time of each attempt that found a motion, >= 1
  std::vector<Steps> censored;  // steps survived by each attempt cut off without a motion, >= 0
  // Backtracking (SPEC §7): the step at which each attempt that gave up did so (>= 1), and the
  // action it blamed.
  std::vector<Steps> backtracked;
  std::vector<std::string> blamed;
};

// The estimators described above. Throws UsageError for a deadline out of range,
// a negative alpha, or observations out of range.
Distribution estimate_planning(const PlanningSample& sample, Steps deadline, double laplace = 0);

// With backtracking (SPEC §7) an attempt ends in one of two ways, found or backtracked, or is cut
// off: competing risks. At step t, with n_t attempts at risk, d_t found and b_t backtracked there,
// the hazards are h(t) = (d_t + alpha) / (n_t + alpha (D - t + 2)) and g(t) = b_t / (the same
// denominator), and p(t) = h(t) S(t - 1), q(t) = g(t) S(t - 1), S(t) = prod_{u<=t} (1 - h(u) - g(u))
// (the Aalen-Johansen estimator of the two cumulative incidences; with no backtrack it is the
// Kaplan-Meier estimate above, and then it is that function's result bit for bit). The culprits
// are the blamed actions' shares of the backtracks, in the order each was first blamed.
struct AttemptEstimate {
  Distribution planning;
  Distribution backtrack;         // all "never" without backtracks
  std::vector<Culprit> culprits;  // empty without backtracks
};
// The estimators of planning and backtracking described above (estimate_planning's result and errors without
// backtracks); UsageError also for a backtracked attempt that names no blamed action.
AttemptEstimate estimate_attempts(const PlanningSample& sample, Steps deadline, double laplace = 0);
// The execution estimator described above; UsageError as estimate_planning, or for a negative time.
Distribution estimate_execution(std::span<const Steps> execution_steps, Steps deadline, double laplace = 0);

struct FitOptions {
  double step_seconds = 1.0;  // length of one step
  Steps deadline = 1;         // D
  double laplace = 0;         // alpha >= 0
  std::string name;           // instance name
  std::string description;    // instance description (may be empty)
};

// What the log said about one action.
struct ActionFit {
  std::string id;
  std::size_t attempts = 0;     // records of the action
  std::size_t found = 0;        // of which found a motion
  std::size_t censored = 0;     // of which were cut off
  std::size_t backtracked = 0;  // of which gave up and blamed an earlier action
};

struct FitResult {
  Problem problem;
  std::vector<ActionFit> actions;  // in the order of problem.actions()
};

// A library of per-action distributions: one skeleton of one action for each action of the log,
// in the order of its first record (e.g. a collection of every doorway move of a building, which
// no list of skeletons covers). `source` names the log in messages. Throws UsageError for a log
// of more than Problem::kMaxSkeletons actions.
SkeletonList single_action_skeletons(std::span<const RefinementAttempt> attempts, std::string_view source);

// The instance for `skeletons` fitted from `attempts` (records of actions no skeleton uses are
// ignored). `log_source` names the log in messages. Throws InputError at the skeleton file's
// place when a skeleton's action has no record in the log, UsageError for bad options.
FitResult fit_problem(std::span<const RefinementAttempt> attempts, std::string_view log_source,
                      const SkeletonList& skeletons, const FitOptions& options);

}  // namespace ontime
