// LiveLedger (include/ontime/run/live_ledger.hpp): the seconds of a live session, mapped to steps.

#include "ontime/run/live_ledger.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// Slices closer than this to a whole number count as that number: sums of step_seconds on a
// clock are not exact multiples of it.
constexpr double kSliceTolerance = 1e-9;

void check_seconds(double seconds, const char* what) {
  if (!(seconds >= 0) || std::isnan(seconds)) {
    throw UsageError(std::string(what) + " must be a time >= 0 seconds (got " + std::to_string(seconds) + ")");
  }
}

}  // namespace

void LiveLedger::start(const Clock& clock, LiveOptions options, double step_seconds, Steps deadline) {
  if (!(options.decision_share > 0 && options.decision_share <= 1e6)) {
    throw UsageError("decision_share must be in (0, 1e6] slices (got " + std::to_string(options.decision_share) + ")");
  }
  clock_ = &clock;
  options_ = options;
  step_seconds_ = step_seconds;
  deadline_ = deadline;
  timeline_.reserve(static_cast<std::size_t>(deadline));
  started_ = clock_->now();
  last_report_ = started_;
}

Steps LiveLedger::steps_at(double seconds) const noexcept {
  const double slices = std::ceil(seconds / step_seconds_ - kSliceTolerance);
  return slices <= 0 ? 0 : slices >= deadline_ ? deadline_ : static_cast<Steps>(slices);
}

Steps LiveLedger::whole_steps(double seconds, const char* what) const {
  check_seconds(seconds, what);
  const double slices = std::ceil(seconds / step_seconds_ - kSliceTolerance);
  return std::isinf(seconds) || slices >= static_cast<double>(kNever) ? kNever
                                                                      : static_cast<Steps>(std::max(0.0, slices));
}

Steps LiveLedger::effort_of(double planning) const noexcept {
  return static_cast<Steps>(std::max(1.0, std::floor(planning / step_seconds_ + kSliceTolerance)));
}

bool LiveLedger::fits(double finish) const noexcept {
  return finish <= deadline_seconds() + kSliceTolerance * step_seconds_;
}

void LiveLedger::charge_outside(double seconds) {
  check_seconds(seconds, "outside time");
  if (std::isinf(seconds)) throw UsageError("outside time must be finite");
  charged_outside_ += seconds;
  totals_.outside += seconds;
}

DecisionBudget LiveLedger::budget(const DecisionBudget& asked) const {
  const ThinkingModel* model = clock_->thinking_model();
  if (!asked.is_set()) {
    const double left = deadline_seconds() - elapsed();
    const double seconds = std::max(1e-9, std::min(options_.decision_share * step_seconds_, left));
    return model != nullptr ? DecisionBudget::iterations(model->iterations_within(seconds))
                            : DecisionBudget::seconds(seconds);
  }
  if (model != nullptr && asked.max_seconds()) {
    // On a modelled clock a time budget is the iterations that fit in it: real time would make
    // the search, and so the report, depend on the machine.
    const std::uint64_t fit = model->iterations_within(*asked.max_seconds());
    return DecisionBudget::iterations(asked.max_iterations() ? std::min(*asked.max_iterations(), fit) : fit);
  }
  return asked;
}

void LiveLedger::charge_thinking(std::uint64_t iterations) const {
  if (clock_->thinking_model() != nullptr) clock_->charge_thinking(iterations);
}

LiveStep& LiveLedger::record_decision(int skeleton, int action, double begin, Steps steps_charged, int started) {
  decided_at_ = clock_->now();
  LiveStep step;
  step.skeleton = skeleton;
  step.action = action;
  step.started = started;
  step.start = elapsed_at(begin);
  step.outside_seconds = begin - last_report_;
  step.decision_seconds = decided_at_ - begin;
  // Steps the clock already moved on while the caller was away are counted with this step.
  step.steps_charged = steps_charged;
  totals_.outside += step.outside_seconds;
  totals_.decision += step.decision_seconds;
  if (started >= 0) last_report_ = decided_at_;  // a start ends at once: nothing awaits a report
  timeline_.push_back(step);
  return timeline_.back();
}

double LiveLedger::record_call(double reported, bool idle) {
  double planning = reported - decided_at_;
  if (idle && planning < step_seconds_) {
    // An idle step holds its whole slice, as in the model; otherwise a session whose allocator
    // idles would never see time pass.
    charged_outside_ += step_seconds_ - planning;
    planning = step_seconds_;
  }
  LiveStep& step = timeline_.back();
  step.planning_seconds = planning;
  step.overrun_seconds = std::max(0.0, planning - step_seconds_);
  totals_.planning += planning;
  totals_.overrun += step.overrun_seconds;
  return planning;
}

void LiveLedger::record_observing(double reported) {
  last_report_ = clock_->now();
  const double observing = last_report_ - reported;
  timeline_.back().observe_seconds = observing;
  totals_.decision += observing;
}

LiveTotals LiveLedger::totals() const {
  LiveTotals totals = totals_;
  totals.elapsed = elapsed();
  return totals;
}

}  // namespace ontime
