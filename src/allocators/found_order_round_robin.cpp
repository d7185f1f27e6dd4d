#include "ontime/allocators/found_order_round_robin.hpp"

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/known_dead.hpp"

namespace ontime {

int FoundOrderRoundRobinAllocator::choose(const State& state) {
  const int count = mdp_->skeleton_count();
  int live = 0;
  for (int k = 0; k < count; ++k) live += known_dead(*mdp_, state, k) ? 0 : 1;
  if (live == 0) return 0;
  int turn = state.time % live;
  for (int k = 0; k < count; ++k) {
    if (known_dead(*mdp_, state, k)) continue;
    if (turn == 0) return k;
    --turn;
  }
  return 0;  // not reached: `live` skeletons passed the same test
}

AllocatorKind found_order_round_robin_kind() {
  return {
      .name = "found-order-round-robin",
      .summary = "baseline: the skeletons not known dead in turn, in found order, the (CT mod n)-th of n at step CT",
      .capabilities = {Capability::stationary, Capability::chains},
      .parameters = {},
      .make = [](const Mdp& mdp, const ParameterReader&) -> AllocatorFactory {
        return [model = &mdp] { return std::make_unique<FoundOrderRoundRobinAllocator>(*model); };
      },
      .commit_rule = kEagerCommitRule};
}

}  // namespace ontime
