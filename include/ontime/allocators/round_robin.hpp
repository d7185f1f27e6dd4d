#pragma once
// `round-robin` (baseline, SPEC §3): at step CT choose skeleton CT mod K, whatever its
// prospects; a skeleton with nothing left to refine spends the step idle.
// Cost: O(1) per decision; needs no distributions.

#include "ontime/allocators/allocator.hpp"

namespace ontime {

class RoundRobinAllocator final : public Allocator {
 public:
  // Cycles over `skeleton_count` skeletons (K >= 1).
  explicit RoundRobinAllocator(int skeleton_count) noexcept : skeleton_count_(skeleton_count) {}

  std::string_view name() const noexcept override { return "round-robin"; }
  int choose(const State& state) override { return state.time % skeleton_count_; }

 private:
  int skeleton_count_;
};

}  // namespace ontime
