#pragma once
// The budget of one decision of an anytime allocator, passed with every decision in the manner
// of OMPL's PlannerTerminationCondition: a number of search iterations, a wall-clock time, a
// stop condition that another thread or the caller's own clock can trip, or any mix of them,
// whichever ends first. A search always runs at least one iteration, so that its answer rests
// on at least one sample.
//
// A default-constructed budget is "unset": the allocator decides with its own default budget
// (its parameters). Iteration budgets give the same answers for the same seed on any machine;
// time and stop-condition budgets depend on the machine and its load.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>

namespace ontime {

class DecisionBudget {
 public:
  // Unset: the allocator's own default budget applies.
  DecisionBudget() = default;

  // Throw UsageError for zero iterations or a time that is not a positive number. A time of
  // kUnlimitedSeconds or more can never end first: no clock deadline is computed for it (the
  // arithmetic would overflow), so "whichever ends first" stays true.
  static DecisionBudget iterations(std::uint64_t count);
  static DecisionBudget seconds(double seconds);
  static DecisionBudget either(std::uint64_t count, double seconds);
  // Ends when `stop()` returns true (checked between iterations; it must be thread-safe if
  // another thread trips it).
  static DecisionBudget until(std::function<bool()> stop);

  // Adds a stop condition to this budget (whichever ends first).
  DecisionBudget& or_until(std::function<bool()> stop);

  // About 31 years: longer times cannot end a search first.
  static constexpr double kUnlimitedSeconds = 1e9;

  // Whether any limit or stop condition is set (else the allocator's default budget applies).
  bool is_set() const noexcept { return iterations_ || seconds_ || stop_; }
  // The iteration limit, if any.
  std::optional<std::uint64_t> max_iterations() const noexcept { return iterations_; }
  // The wall-clock limit in seconds, if any (kUnlimitedSeconds or more never ends first).
  std::optional<double> max_seconds() const noexcept { return seconds_; }
  // The stop condition, or an empty function when there is none.
  const std::function<bool()>& stop_condition() const noexcept { return stop_; }

 private:
  std::optional<std::uint64_t> iterations_;
  std::optional<double> seconds_;
  std::function<bool()> stop_;
};

// Watches one decision against its budget, which must outlive it. An unset budget never ends
// on its own (the allocator passes its default budget instead).
class BudgetMonitor {
 public:
  // Starts the clock of a time budget now: the decision's seconds count from here.
  explicit BudgetMonitor(const DecisionBudget& budget) noexcept;

  // True once `iterations_done` (>= 1) iterations exhaust the budget. Reads the clock only
  // for time budgets.
  bool exhausted(std::uint64_t iterations_done) const {
    if (iterations_done == 0) return false;
    if (iterations_done >= max_iterations_) return true;
    if (timed_ && std::chrono::steady_clock::now() >= deadline_) return true;
    return stop_ != nullptr && (*stop_)();
  }

 private:
  std::uint64_t max_iterations_;
  bool timed_;
  std::chrono::steady_clock::time_point deadline_;
  const std::function<bool()>* stop_ = nullptr;
};

}  // namespace ontime
