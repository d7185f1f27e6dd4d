#pragma once
// `dp` (the paper's DP, SPEC §3): the best linear contiguous policy over single skeletons.
//
// Computes PS(k, 0, 0, 0) of Eq. (1) with aggregation `self` for every skeleton (with
// backtracking, SPEC §7, its extension: backtracking_success.hpp; with chains or expiry, SPEC §9,
// the exact value of refining the skeleton alone: timed_contiguous_success.hpp), picks the largest
// once (ties: lowest index) and refines only that skeleton for the whole episode.
// Acting while planning (SPEC §10) the registry's kind picks the skeleton by Eq. (1) acting while
// planning from the start (ConcurrentContiguousSuccess, aggregation `self`) and follows it by the
// eager commit rule; with chains or expiry, where waiting for a chain may pay, it picks the skeleton
// of the largest devoted optimum (ConcurrentDevotedOptimum) and makes that optimum's moves.
// No guarantee beyond optimality among "one skeleton, refined contiguously" policies.
// Cost: one ContiguousSuccessTable build at construction; O(1) per decision.

#include "ontime/allocators/allocator.hpp"
#include "ontime/solve/contiguous_success.hpp"

namespace ontime {

class DpAllocator final : public Allocator {
 public:
  // Computes PS(k, 0, 0, 0) (or its extension, as above) of every skeleton of `mdp` and picks the largest.
  explicit DpAllocator(const Mdp& mdp);
  // Refines `chosen_skeleton`, picked before (the factory picks once for all its allocators).
  explicit DpAllocator(int chosen_skeleton) noexcept : chosen_(chosen_skeleton) {}

  std::string_view name() const noexcept override { return "dp"; }
  int choose(const State&) override { return chosen_; }

  // The skeleton refined for the whole episode.
  int chosen_skeleton() const noexcept { return chosen_; }

 private:
  int chosen_;
};

}  // namespace ontime
