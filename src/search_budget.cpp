#include "ontime/search_budget.hpp"

#include <cmath>
#include <limits>

#include "ontime/error.hpp"

namespace ontime {

SearchBudget SearchBudget::iterations(std::uint64_t count) {
  if (count == 0) throw UsageError("a search budget needs at least one iteration");
  SearchBudget budget;
  budget.iterations_ = count;
  return budget;
}

SearchBudget SearchBudget::seconds(double seconds) {
  if (!(std::isfinite(seconds) && seconds > 0)) throw UsageError("a search time budget must be a positive number of seconds");
  SearchBudget budget;
  budget.seconds_ = seconds;
  return budget;
}

SearchBudget SearchBudget::either(std::uint64_t count, double seconds) {
  SearchBudget budget = SearchBudget::seconds(seconds);
  budget.iterations_ = SearchBudget::iterations(count).iterations_;
  return budget;
}

BudgetMonitor::BudgetMonitor(const SearchBudget& budget) noexcept
    : max_iterations_(budget.max_iterations().value_or(std::numeric_limits<std::uint64_t>::max())),
      timed_(budget.max_seconds().has_value()) {
  if (timed_) {
    deadline_ = std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                    std::chrono::duration<double>(*budget.max_seconds()));
  }
}

}  // namespace ontime
