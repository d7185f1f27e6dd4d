#include "ontime/allocators/round_robin.hpp"

#include "ontime/allocators/allocator_registry.hpp"

namespace ontime {

AllocatorKind round_robin_kind() {
  return {.name = "round-robin",
          .summary = "baseline: skeleton CT mod K at step CT, whatever its prospects",
          .capabilities = {Capability::stationary, Capability::chains},
          .parameters = {},
          .make = [](const Mdp& mdp, const ParameterReader&) -> AllocatorFactory {
            return [count = mdp.skeleton_count()] { return std::make_unique<RoundRobinAllocator>(count); };
          },
          .commit_rule = kEagerCommitRule};
}

}  // namespace ontime
