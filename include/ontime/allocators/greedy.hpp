#pragma once
// `greedy` (baseline, SPEC §3): the skeleton with the smallest sum over its actions of mean
// planning time plus mean execution time (means over the finite support, E[T | T finite]),
// chosen once (ties: lowest index) and refined for the whole episode.
// Blind to spread and heavy tails, which is what the paper's instances 3-5 expose. With chains
// (SPEC §9) the means of the averaged instance (chain_averaging.hpp), chains read at their start.
// Cost: O(sum of support sizes) at construction; O(1) per decision.

#include "ontime/allocators/allocator.hpp"
#include "ontime/mdp/mdp.hpp"

namespace ontime {

class GreedyAllocator final : public Allocator {
 public:
  // Picks the skeleton with the smallest sum of mean planning and execution times in `mdp`.
  explicit GreedyAllocator(const Mdp& mdp);

  std::string_view name() const noexcept override { return "greedy"; }
  int choose(const State&) override { return chosen_; }

  // The skeleton refined for the whole episode.
  int chosen_skeleton() const noexcept { return chosen_; }

 private:
  int chosen_;
};

}  // namespace ontime
