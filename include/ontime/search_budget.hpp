#pragma once
// The budget of an anytime search (in the manner of OMPL's PlannerTerminationCondition):
// a number of iterations, a wall-clock time, or both, whichever ends first. A search always
// runs at least one iteration, so that its answer rests on at least one sample.
//
// Iteration budgets give the same answers for the same seed on any machine; time budgets
// depend on the machine and its load.

#include <chrono>
#include <cstdint>
#include <optional>

namespace ontime {

class SearchBudget {
 public:
  static SearchBudget iterations(std::uint64_t count);
  static SearchBudget seconds(double seconds);
  // Ends at whichever limit comes first.
  static SearchBudget either(std::uint64_t count, double seconds);

  std::optional<std::uint64_t> max_iterations() const noexcept { return iterations_; }
  std::optional<double> max_seconds() const noexcept { return seconds_; }

 private:
  SearchBudget() = default;
  std::optional<std::uint64_t> iterations_;
  std::optional<double> seconds_;
};

// Watches one search against its budget.
class BudgetMonitor {
 public:
  explicit BudgetMonitor(const SearchBudget& budget) noexcept;

  // True once `iterations_done` (>= 1) iterations exhaust the budget. Reads the clock only
  // for time budgets.
  bool exhausted(std::uint64_t iterations_done) const noexcept {
    if (iterations_done == 0) return false;
    if (iterations_done >= max_iterations_) return true;
    return timed_ && std::chrono::steady_clock::now() >= deadline_;
  }

 private:
  std::uint64_t max_iterations_;
  bool timed_;
  std::chrono::steady_clock::time_point deadline_;
};

}  // namespace ontime
