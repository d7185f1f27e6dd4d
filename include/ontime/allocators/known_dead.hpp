#pragma once
// What a planner without a model knows of a skeleton's prospects: whether the state alone
// (not the planning or execution distributions) rules the skeleton out. Shared by the
// baselines that model such planners (`first-found`, `found-order-round-robin`).
//
// A skeleton is known dead when it has nothing left to refine (while the episode runs, its
// refined actions did not execute in time), or when the execution time of its refined actions
// leaves no room for one more step of effort: the next motion is found at CT + 1 at the
// earliest and executes in 0 steps or more, so CT + 1 + ET_k > D rules the skeleton out. This
// also covers the "never" and too-slow execution times, which the MDP saturates at D + 1.
// Any skeleton the model says can still succeed (Mdp::can_succeed) passes this test. With chains
// (SPEC §9) ET_k is the static part of the execution, a lower bound of what is still to come, so
// the test still only rules out.
// Cost: O(1).

#include <cstddef>
#include <cstdint>

#include "ontime/mdp/mdp.hpp"
#include "ontime/mdp/state.hpp"

namespace ontime {

// Whether the state alone rules skeleton k out, as above.
inline bool known_dead(const Mdp& mdp, const State& state, int k) noexcept {
  if (mdp.next_action(state, k) < 0) return true;
  return std::int64_t{state.time} + 1 + state.execution[static_cast<std::size_t>(k)] > mdp.deadline();
}

}  // namespace ontime
