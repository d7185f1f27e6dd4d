#pragma once
// Internal: the budget parameters every anytime allocator declares (`iterations`, `time-budget`)
// read into a DecisionBudget, in the two forms the registry needs.

#include <cstdint>
#include <limits>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/decision_budget.hpp"

namespace ontime::detail {

// The allocator's own default budget: its iterations, its time budget, or both (whichever ends
// first); only a time budget when the time was given and the iterations were not.
inline DecisionBudget default_budget(const ParameterReader& parameters) {
  const double seconds = parameters.real("time-budget");
  const std::uint64_t iterations = seconds > 0 && !parameters.given("iterations")
                                       ? std::numeric_limits<std::uint64_t>::max()
                                       : parameters.integer("iterations");
  return seconds > 0 ? DecisionBudget::either(iterations, seconds) : DecisionBudget::iterations(iterations);
}

// Only what the caller gave (AllocatorNeeds::decision_budget): unset without either, so that a
// live session's share of a slice applies.
inline DecisionBudget given_budget(const ParameterReader& parameters) {
  const bool iterations = parameters.given("iterations");
  const double seconds = parameters.given("time-budget") ? parameters.real("time-budget") : 0.0;
  if (!iterations) return seconds > 0 ? DecisionBudget::seconds(seconds) : DecisionBudget{};
  return seconds > 0 ? DecisionBudget::either(parameters.integer("iterations"), seconds)
                     : DecisionBudget::iterations(parameters.integer("iterations"));
}

}  // namespace ontime::detail
