#pragma once
// PS of Eq. (1) when the robot acts while planning (SPEC §10): the chance (or, with rewards, the
// expected reward) that refining one skeleton contiguously, action after action, while the robot
// executes each of its actions as soon as it is refined and the robot is free, finishes by the
// deadline.
//
// Plan-first Eq. (1) carries ET, the execution still to come once refinement ends. Here the robot
// works meanwhile, so what matters is its backlog w: the steps it still needs, from now, for the
// skeleton's refined actions (the action it runs, then the refined ones after it). For skeleton k
// at position l, `spent` steps on its current action a, time T and backlog w:
//   PS(k, l, spent, T, w) = (1 / S_a(spent)) * sum_{t>=1, T+t<=D} p_a(spent + t) * H(k, l, T + t, max(w - t, 0))
// (after t steps of planning the robot has run t steps of its backlog), where, with x ~ e_a,
//   H(k, l, T', v) = sum_x e_a(x) * R_k(T' + v + x) over finishes within D, for the last action;
//   H(k, l, T', v) = sum_x e_a(x) * AGG_{k' in N(k,l)} PS(k', l+1, 0, T', v + x), otherwise.
// It is at least plan-first Eq. (1) of the same skeleton, whose executions all wait for the last
// refinement: here each starts no later. AGG is Eq. (1)'s: sum, max or self.
//
// Cost: the values with nothing spent are memoised on first use, one per (skeleton, position,
// T, w) reached; a query is one sum over at most D - T planning steps of such values, each a sum
// over the execution support. No table is built up front, so a long deadline costs only what
// its queries reach.

#include <cstdint>
#include <unordered_map>

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/solve/contiguous_success.hpp"

namespace ontime {

class ConcurrentContiguousSuccess {
 public:
  // The values of `mdp`'s skeletons with Eq. (1)'s `aggregation`; memoised as they are asked for.
  // Throws UsageError (check_supported) when the problem has backtracking.
  ConcurrentContiguousSuccess(const ConcurrentMdp& mdp, Aggregation aggregation);

  // Eq. (1) here has no give-up term: UsageError naming the rule when `mdp` has backtracking
  // (SPEC §7), before any allocator built on these values is made.
  static void check_supported(const ConcurrentMdp& mdp);

  // PS(k, l, spent, time, backlog); 0 when the backlog alone passes the deadline.
  double value(int k, int l, Steps spent, Steps time, std::int64_t backlog);
  // The same for live skeleton k in `state` (its backlog: ConcurrentMdp::robot_free(state, k) -
  // CT); for a skeleton refined in full, its reward at the end of that backlog (0 past D).
  double value(const ConcurrentState& state, int k);

  // How the skeletons that share an action are combined.
  Aggregation aggregation() const noexcept { return aggregation_; }

 private:
  double fresh(int k, int l, Steps time, std::int64_t backlog);
  double after_found(int k, int l, Steps time, std::int64_t backlog);

  const ConcurrentMdp* mdp_;
  Aggregation aggregation_;
  Steps deadline_;
  std::unordered_map<std::uint64_t, double> fresh_;  // (k, l, T, w) packed
};

}  // namespace ontime
