#pragma once
// `found-order-round-robin` (baseline): effort shared in turn among the skeletons not known
// dead (known_dead.hpp: nothing left to refine, or CT + 1 + ET_k > D), in the order the task
// planner found them: with n such skeletons, at step CT the (CT mod n)-th of them (counting
// from 0, lowest index first). With every skeleton dead the episode is lost: skeleton 0.
//
// Unlike `round-robin` it spends no step on a skeleton it can see is lost. The choice is a
// function of the state alone (a live session makes it anew whenever a skeleton arrives) and
// reads only what has been observed, never the distributions: it models a planner that shares
// its motion planner in turn and has no model of it. No optimality guarantee.
// Cost: O(K) per decision (two passes over the skeletons), no allocation.

#include "ontime/allocators/allocator.hpp"
#include "ontime/mdp/mdp.hpp"

namespace ontime {

class FoundOrderRoundRobinAllocator final : public Allocator {
 public:
  // The Mdp must outlive the allocator.
  explicit FoundOrderRoundRobinAllocator(const Mdp& mdp) noexcept : mdp_(&mdp) {}

  std::string_view name() const noexcept override { return "found-order-round-robin"; }
  int choose(const State& state) override;

 private:
  const Mdp* mdp_;
};

}  // namespace ontime
