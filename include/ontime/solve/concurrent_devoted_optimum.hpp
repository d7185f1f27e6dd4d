#pragma once
// The devoted optimum when the robot acts while planning (SPEC §10): for skeleton k and a state s,
// the largest expected reward (the success probability without rewards) of a policy that refines
// k alone and chooses when the robot starts each of k's actions, that is, V* of the state devoted
// to k (ConcurrentMdp::devoted_to: every other skeleton dropped), where the only moves are k's
// steps, k's starts and the planner idling.
//
// What it is for: with exogenous chains or expiry (SPEC §9) starting an action as soon as it may
// start is not the best a policy devoted to k can do, since waiting for a chain (a door to open, a
// queue to clear) may pay; the devoted eager policy (ConcurrentContiguousSuccess, Timing::exact)
// never waits. dp and dp-rerun acting while planning value a skeleton by this optimum there and make
// its move: a commit rule chosen by the value. Without chains, expiry or backtracking the two
// coincide (the forced start of ConcurrentMdp: every live skeleton goes through the refined child).
//
// Guarantees: value() is ConcurrentSolver's optimum of the devoted state, to the bit, and move() its
// best move (the solver's tie order), so a policy that makes move() in every state is stationary.
// In the full MDP that move earns value() from s, unless another skeleton ends along k before k
// does (the episode then ends through it, with its reward): value() is what the policy devoted to
// k expects, the ranking dp and dp-rerun use.
// Cost: one ConcurrentSolver memo shared by every skeleton and query: the devoted states reachable
// from those asked about, each solved once (ResourceLimitError past `max_states`); a query of a
// state reached before is a copy of the state and one hash lookup.

#include <cstddef>
#include <memory>

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/solve/concurrent_solver.hpp"

namespace ontime {

class ConcurrentDevotedOptimum {
 public:
  // The devoted optima of `mdp`'s skeletons, solved as they are asked for, holding at most
  // `max_states` states in all.
  explicit ConcurrentDevotedOptimum(const ConcurrentMdp& mdp,
                                    std::size_t max_states = ConcurrentSolver::kDefaultMaxStates);

  // V* of `state` devoted to live skeleton k; 0 once k is dropped.
  double value(const ConcurrentState& state, int k);
  // The best move of `state` devoted to live skeleton k: a start of k's next action, a step on k or
  // the planner idling; where that state has none (nothing can finish), the devoted eager move
  // (ConcurrentContiguousSuccess::devoted_move). Where it idles the planner (k and its prefixes
  // refined in full) while another live skeleton has an action left to refine, and there is no
  // backtracking, a step on the first such group instead (ConcurrentMdp::refine_choices): the state
  // devoted to k after it is the same, and the planner's time is not thrown away, as an idle planner
  // is not a useful move there (ConcurrentMdp::useful_moves).
  ConcurrentMdp::Move move(const ConcurrentState& state, int k);

 private:
  const ConcurrentMdp* mdp_;
  ConcurrentSolver solver_;
};

}  // namespace ontime
