#include "ontime/allocators/belief_models.hpp"

namespace ontime {

ConcurrentBeliefModels::ConcurrentBeliefModels(const Problem& world, const Problem* planned)
    : world_(std::make_unique<const ConcurrentMdp>(
          world, planned != nullptr ? HopelessSkeletons::kept : HopelessSkeletons::dropped)),
      planned_(planned != nullptr ? std::make_unique<const ConcurrentMdp>(*planned) : nullptr) {}

ConcurrentAllocatorFactory ConcurrentBeliefModels::factory(std::string_view name, const ParameterValues& values) const {
  if (!planned_) return make_concurrent_allocator_factory(name, *world_, values);
  return seen_by_belief(*planned_, make_concurrent_allocator_factory(name, *planned_, values));
}

}  // namespace ontime
