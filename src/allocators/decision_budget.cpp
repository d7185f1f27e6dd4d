#include "ontime/allocators/decision_budget.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "ontime/util/error.hpp"

namespace ontime {

DecisionBudget DecisionBudget::iterations(std::uint64_t count) {
  if (count == 0) throw UsageError("a decision budget needs at least one iteration");
  DecisionBudget budget;
  budget.iterations_ = count;
  return budget;
}

DecisionBudget DecisionBudget::seconds(double seconds) {
  if (!(seconds > 0) || std::isnan(seconds)) {
    throw UsageError("a decision time budget must be a positive number of seconds");
  }
  DecisionBudget budget;
  budget.seconds_ = seconds;
  return budget;
}

DecisionBudget DecisionBudget::either(std::uint64_t count, double seconds) {
  DecisionBudget budget = DecisionBudget::seconds(seconds);
  budget.iterations_ = DecisionBudget::iterations(count).iterations_;
  return budget;
}

DecisionBudget DecisionBudget::until(std::function<bool()> stop) {
  DecisionBudget budget;
  budget.or_until(std::move(stop));
  return budget;
}

DecisionBudget& DecisionBudget::or_until(std::function<bool()> stop) {
  if (!stop) throw UsageError("a decision budget's stop condition must be callable");
  if (stop_) {
    stop_ = [first = std::move(stop_), second = std::move(stop)] { return first() || second(); };
  } else {
    stop_ = std::move(stop);
  }
  return *this;
}

BudgetMonitor::BudgetMonitor(const DecisionBudget& budget) noexcept
    : max_iterations_(budget.max_iterations().value_or(std::numeric_limits<std::uint64_t>::max())),
      timed_(budget.max_seconds().has_value() && *budget.max_seconds() < DecisionBudget::kUnlimitedSeconds),
      stop_(budget.stop_condition() ? &budget.stop_condition() : nullptr) {
  if (timed_) {
    deadline_ = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                       std::chrono::duration<double>(*budget.max_seconds()));
  }
}

}  // namespace ontime
