#pragma once
// The models of an evaluation acting while planning (SPEC §10) in which the allocator may decide
// with a belief (SPEC §10 "Beliefs"): the world's ConcurrentMdp, which keeps hopeless skeletons
// when there is a belief (HopelessSkeletons::kept) so that its states tell the allocator nothing
// only the world's distributions imply, and the belief's, on which the allocators decide, shown
// each state as that model holds it (seen_by_belief). Without a belief, one canonical model for
// both. What `ontime evaluate --belief`, `ontime run --belief` and their Python forms share.
// Cost: the models' tables, built once (ConcurrentMdp); a factory's allocators cost what their
// kind costs, plus one canonicalised copy of the state per move with a belief.

#include <memory>
#include <string_view>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/model/problem.hpp"

namespace ontime {

class ConcurrentBeliefModels {
 public:
  // The models of `world`, and of `planned` (the world's skeletons with the belief's distributions,
  // with_distributions_of) when it is not null.
  ConcurrentBeliefModels(const Problem& world, const Problem* planned);

  // The world's model: the episodes and exact values are drawn from it.
  const ConcurrentMdp& world() const noexcept { return *world_; }
  // Allocators of kind `name` (parameters `values`) deciding on the belief's model, shown the
  // world's states as that model holds them; without a belief, on the world's model. Throws what
  // make_concurrent_allocator_factory throws. This object must outlive the factory and its allocators.
  ConcurrentAllocatorFactory factory(std::string_view name, const ParameterValues& values = {}) const;

 private:
  std::unique_ptr<const ConcurrentMdp> world_;
  std::unique_ptr<const ConcurrentMdp> planned_;  // null without a belief
};

}  // namespace ontime
