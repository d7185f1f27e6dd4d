#include "ontime/allocators/dp.hpp"

#include "ontime/allocators/allocator_registry.hpp"

namespace ontime {
namespace {

int best_single_skeleton(const Mdp& mdp) {
  const ContiguousSuccessTable table(mdp, Aggregation::self);
  int best = 0;
  double best_value = -1;
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    const double value = table.success_probability(k, 0, 0, 0);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  return best;
}

}  // namespace

DpAllocator::DpAllocator(const Mdp& mdp) : chosen_(best_single_skeleton(mdp)) {}

AllocatorKind dp_kind() {
  return {.name = "dp",
          .summary = "the paper's DP: the single skeleton most likely to succeed alone, refined for the whole episode",
          .capabilities = {Capability::stationary},
          .parameters = {},
          .make = [](const Mdp& mdp, const ParameterReader&) -> AllocatorFactory {
            const int chosen = DpAllocator(mdp).chosen_skeleton();
            return [chosen] { return std::make_unique<DpAllocator>(chosen); };
          }};
}

}  // namespace ontime
