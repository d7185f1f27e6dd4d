#include "ontime/allocators/first_found.hpp"

#include <bit>
#include <limits>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/known_dead.hpp"

namespace ontime {

int FirstFoundAllocator::choose(const State& state) {
  int best = -1;
  int best_level = std::numeric_limits<int>::max();
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (known_dead(*mdp_, state, k)) continue;
    // The least j with PT_k < budget * 2^j: the attempt at which this skeleton is still
    // under its budget.
    const int level =
        static_cast<int>(std::bit_width(std::uint64_t{state.spent[static_cast<std::size_t>(k)]} / budget_));
    if (level < best_level) {
      best = k;
      best_level = level;
      if (level == 0) break;  // no skeleton after it comes before it
    }
  }
  return best >= 0 ? best : 0;
}

AllocatorKind first_found_kind() {
  return {
      .name = "first-found",
      .summary = "baseline: skeletons in found order, each until its action uses up a budget that doubles per round",
      .capabilities = {Capability::stationary, Capability::chains},
      .parameters = {Parameter::integer(
          "budget", 4, 1, 65535, "steps on a skeleton's action before the next one is tried; doubled each round")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        return [model = &mdp, budget = parameters.integer("budget")] {
          return std::make_unique<FirstFoundAllocator>(*model, budget);
        };
      },
      .commit_rule = kEagerCommitRule};
}

}  // namespace ontime
