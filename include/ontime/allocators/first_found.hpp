#pragma once
// `first-found` (baseline): the habit of PDDLStream's focused algorithm, which refines the
// skeletons in the order the task planner found them, each with a fixed budget per attempt,
// and doubles the budget when every skeleton has used it up.
//
// The step goes to the lowest-index skeleton (index 0: found first) that is not known dead
// (known_dead.hpp: nothing left to refine, or CT + 1 + ET_k > D) and whose current action has
// had fewer than `budget` steps (PT_k < budget). So a skeleton is refined until it is refined
// in full or an action of it uses up the budget without a motion; then the next one is tried.
// When every live skeleton has used it up, the budget doubles (budget * 2, * 4, ...: the
// smallest level at which some live skeleton is still under it) and the skeletons are tried
// again in found order. With every skeleton dead the episode is lost: skeleton 0.
//
// The choice is a function of the state alone: skeleton k's level is the least j with
// PT_k < budget * 2^j, i.e. bit_width(PT_k / budget), and the step goes to the lowest level,
// ties to the lowest index. So it needs no memory of earlier decisions (a live session makes it
// anew whenever a skeleton arrives) and its success can be evaluated exactly. It reads only
// what has been observed, never the planning or execution distributions: it models a planner
// that has no model of its motion planner. No optimality guarantee.
// Cost: O(K) per decision (one pass over the skeletons), no allocation.

#include <cstdint>

#include "ontime/allocators/allocator.hpp"
#include "ontime/mdp/mdp.hpp"

namespace ontime {

class FirstFoundAllocator final : public Allocator {
 public:
  // The Mdp must outlive the allocator; `budget` >= 1 steps per action per attempt.
  FirstFoundAllocator(const Mdp& mdp, std::uint64_t budget) noexcept : mdp_(&mdp), budget_(budget) {}

  std::string_view name() const noexcept override { return "first-found"; }
  int choose(const State& state) override;

  // The budget of the first round, in steps per action per attempt.
  std::uint64_t budget() const noexcept { return budget_; }

 private:
  const Mdp* mdp_;
  std::uint64_t budget_;
};

}  // namespace ontime
