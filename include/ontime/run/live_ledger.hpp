#pragma once
// The ledger of a session on the robot's clock (docs/live.md): the seconds gone and what they were
// charged to, for a plan-first live Session (session.hpp) and a live ConcurrentSession
// (concurrent_session.hpp) alike, so that both map seconds to the MDP's steps by one rule.
//
// The deadline is D * step_seconds seconds after the ledger started. Everything the clock sees
// counts against it, and time the clock did not see is added with charge_outside(). Seconds map to
// steps with a tolerance of 1e-9 slices (sums of step_seconds on a clock are not exact multiples):
//   CT     = ceil(elapsed / step_seconds), at most D                (steps_at)
//   effort = max(1, floor(planning seconds / step_seconds))         (effort_of: a call's slices)
//   steps  = ceil(seconds / step_seconds), kNever for infinity      (whole_steps: an execution)
// One timeline entry per move (a decision and the planner's call after it, or a start), and the
// robot's executions, each from its start to its end in elapsed seconds.
//
// Cost: a clock read per call that asks for the time; the timeline is reserved up front.

#include <cstdint>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/decision_budget.hpp"
#include "ontime/model/distribution.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {

struct LiveOptions {
  // Share of a slice an anytime allocator may think per decision when the caller passes no
  // budget of its own; in (0, 1e6].
  double decision_share = 0.5;
};

// One step of a live session, in seconds since the session began. A concurrent session's start
// (SPEC §10: the robot begins an action, no planner call) is an entry of its own with `started`.
struct LiveStep {
  int skeleton = -1;
  int action = -1;               // -1: an idle step (or a start)
  double start = 0;              // when the decision began
  double outside_seconds = 0;    // caller's time since the previous report (or the start)
  double decision_seconds = 0;   // the allocator's thinking
  double planning_seconds = 0;   // the planner's call: its slice and any overrun
  double overrun_seconds = 0;    // beyond the slice
  double observe_seconds = 0;    // the allocator taking in the outcome (a search moving its tree)
  Steps steps_charged = 0;       // CT after the report minus CT before the decision
  bool refined = false;          // the call found a motion
  double execution_seconds = 0;  // of that motion, when refined
  int started = -1;              // a start: the action the robot began executing; -1 for a step
};

// One execution of the robot, in seconds since the session began: `action` from `start` to `end`
// (the end its motion's execution time gives, or the one the robot reported).
struct LiveExecution {
  int action = -1;
  double start = 0;
  double end = 0;
  friend bool operator==(const LiveExecution&, const LiveExecution&) = default;
};

// What a live session charged, in seconds (decision: the allocator's choices and what it did with
// their outcomes).
struct LiveTotals {
  double decision = 0, planning = 0, overrun = 0, outside = 0;
  double elapsed = 0;  // at the end of the session (or now, while it runs)
};

// The search iterations an allocator has run so far (its "iterations" counter; 0 if none).
template <class AnyAllocator>
std::uint64_t search_iterations_of(const AnyAllocator& allocator) {
  Statistics statistics;
  allocator.collect_statistics(statistics);
  return static_cast<std::uint64_t>(statistics.find(kIterationsCounter).value_or(0.0));
}

class LiveLedger {
 public:
  // A ledger that is not live (is_live() false) until start().
  LiveLedger() = default;
  // Starts the ledger on `clock` (which must outlive it) now, for a deadline of `deadline` steps
  // of `step_seconds`. Throws UsageError for a decision share outside (0, 1e6].
  void start(const Clock& clock, LiveOptions options, double step_seconds, Steps deadline);

  // Whether start() was called.
  bool is_live() const noexcept { return clock_ != nullptr; }
  // The clock (live ledgers only).
  const Clock& clock() const noexcept { return *clock_; }
  // The clock's reading now.
  double now() const { return clock_->now(); }
  // The options given to start().
  const LiveOptions& options() const noexcept { return options_; }
  // Seconds per step, and the deadline D * step_seconds.
  double step_seconds() const noexcept { return step_seconds_; }
  double deadline_seconds() const noexcept { return static_cast<double>(deadline_) * step_seconds_; }
  // Seconds gone since the start at clock reading `clock_time`, with the outside time charged.
  double elapsed_at(double clock_time) const noexcept { return clock_time - started_ + charged_outside_; }
  // Seconds gone now; frozen once the session ended (end()).
  double elapsed() const { return ended_at_ >= 0 ? ended_at_ : elapsed_at(clock_->now()); }
  // The session ended `elapsed` seconds after its start (elapsed() stays there); end() ends it now.
  // Both do nothing on a ledger that is not live.
  void end_at(double elapsed) noexcept {
    if (clock_ != nullptr) ended_at_ = elapsed;
  }
  void end() {
    if (clock_ != nullptr) ended_at_ = elapsed();
  }

  // CT at `seconds` gone: ceil(seconds / step_seconds), in [0, D].
  Steps steps_at(double seconds) const noexcept;
  // The whole steps `seconds` take: ceil(seconds / step_seconds), at least 0; kNever for infinity.
  // Throws UsageError for a negative or NaN time (naming `what`).
  Steps whole_steps(double seconds, const char* what = "execution time") const;
  // The slices of effort a planner call of `planning` seconds counts: max(1, floor(planning /
  // step_seconds)).
  Steps effort_of(double planning) const noexcept;
  // Whether an execution ending `finish` seconds after the start ends within the deadline.
  bool fits(double finish) const noexcept;

  // Adds `seconds` the clock did not see to the seconds gone. Throws UsageError for a negative or
  // non-finite time.
  void charge_outside(double seconds);
  // The budget of a decision made now, given the caller's `asked` (unset: decision_share of a slice,
  // at most the seconds left). On a modelled clock a time budget becomes the iterations that fit.
  DecisionBudget budget(const DecisionBudget& asked) const;
  // On a modelled clock: a decision ran `iterations` units of search; the clock moves on by its cost.
  void charge_thinking(std::uint64_t iterations) const;

  // A decision that began at clock reading `begin` ends now: a timeline entry for `skeleton`'s
  // `action` (or a start of `started`), with the outside time since the last report and
  // `steps_charged` steps the clock moved on meanwhile. Returns the entry.
  LiveStep& record_decision(int skeleton, int action, double begin, Steps steps_charged, int started = -1);
  // The planner's call after the last decision ended now (clock reading `reported`): its seconds.
  // An idle call (the planner refined nothing) holds its whole slice, as in the model, the rest of
  // it charged as outside time. Charges the planning and any overrun to the last entry.
  double record_call(double reported, bool idle);
  // The allocator finished taking in the outcome reported at clock reading `reported`: its thinking.
  void record_observing(double reported);
  // An execution of `action` begins `start` seconds after the session's start and should end at
  // `end`; the last one's end may move (move_last_execution_end).
  void record_execution(int action, double start, double end) { executions_.push_back({action, start, end}); }
  // The robot reported that its current execution ends at `end` seconds instead.
  void move_last_execution_end(double end) noexcept {
    if (!executions_.empty()) executions_.back().end = end;
  }

  // One entry per move; the last one (after record_decision).
  const std::vector<LiveStep>& timeline() const noexcept { return timeline_; }
  LiveStep& last_step() noexcept { return timeline_.back(); }
  // The robot's executions, in order.
  const std::vector<LiveExecution>& executions() const noexcept { return executions_; }
  // What was charged, with the seconds gone.
  LiveTotals totals() const;

 private:
  const Clock* clock_ = nullptr;
  LiveOptions options_;
  double step_seconds_ = 1;
  Steps deadline_ = 0;
  double started_ = 0;
  double charged_outside_ = 0;  // charge_outside() and idle slices so far
  double last_report_ = 0;      // clock time of the last report (or the start)
  double decided_at_ = 0;       // clock time the last decision was made
  double ended_at_ = -1;        // elapsed seconds when the session ended
  std::vector<LiveStep> timeline_;
  std::vector<LiveExecution> executions_;
  LiveTotals totals_;
};

}  // namespace ontime
