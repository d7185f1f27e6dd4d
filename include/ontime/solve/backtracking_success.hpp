#pragma once
// Eq. (1) of SPEC §3 under backtracking (SPEC §7): the probability that refining one skeleton
// contiguously, action after action, finishes refinement and execution by the deadline, when an
// attempt may also give up and send refinement back to an earlier action. dp and dp-rerun use it
// for an instance with backtracking (ContiguousSuccessTable stays theirs otherwise, bit for bit).
//
// For skeleton k at position l with a fresh attempt on its action a, CT and ET, and B the
// restore values of the actions before l that later actions may blame:
//   V(k, l, CT, ET, B) = sum_{t=1}^{D-CT} p_a(t) F(k, l, CT + t, ET, B)
//                      + sum_{t=1}^{D-CT} q_a(t) sum_c w_a(c) V(k, pos(c), CT + t, B_c, B before c)
//   F = E_a(D - CT' - ET) for the last action, else
//   F = sum_x e_a(x) AGG_{k' in N(k, l)} V(k', l + 1, CT', ET + x, B with B_l = ET when a is blamed)
// with `spent` steps already on the current action conditioning its attempt as Eq. (1) does:
//   PS = (1 / S_a(spent)) sum_t [p_a(spent + t) F(..., CT + t, ...) + q_a(spent + t) (backtrack term)],
// S_a(spent) = P(the attempt neither found nor backtracked in `spent` steps). A backtrack
// continues with the skeleton itself from its culprit (the culprit's members restart with it;
// the aggregation is Eq. (1)'s for the skeletons sharing an action on the way forward). With
// every backtrack probability zero V is Eq. (1)'s PS (CT and ET then enter only as their sum).
//
// Unlike Eq. (1) V depends on CT and ET separately (a backtrack keeps the time and restores the
// execution), and on the restore values later backtracks may use, so it is not tabulated up
// front: values are memoised as they are asked for (a query the first time costs
// O(positions x D x (|supp e| |N| + |culprits|)) recursively, later ones a hash lookup). One
// evaluator per allocator: it is not thread-safe.

#include <absl/container/flat_hash_map.h>

#include <cstdint>
#include <string>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/contiguous_success.hpp"

namespace ontime {

class BacktrackingSuccess {
 public:
  // Throws UsageError for a problem without backtracking (ContiguousSuccessTable serves it).
  BacktrackingSuccess(const Mdp& mdp, Aggregation aggregation);

  // PS of skeleton k in `state` (0 when it has nothing left to refine).
  double success_probability(const State& state, int k);

  // Values memoised so far.
  std::size_t memoised() const noexcept { return memo_.size(); }

 private:
  // V(k, l, ct, et, restores) for a fresh attempt at position l; `restores` holds, for every
  // position before l whose action some action may blame, its restore value (by position).
  double fresh(int k, int l, std::int64_t ct, std::int64_t et, const std::vector<std::uint16_t>& restores);
  // The part of a step that ends the attempt at CT' = ct with a motion, or a backtrack.
  double found_continuation(int k, int l, std::int64_t ct, std::int64_t et, const std::vector<std::uint16_t>& restores);
  double backtrack_continuation(int k, int l, std::int64_t ct, const std::vector<std::uint16_t>& restores);

  const Mdp* mdp_;
  Aggregation aggregation_;
  Steps deadline_;
  // Keys: skeleton, position, CT, ET and the restores before it, as text of 16-bit values.
  absl::flat_hash_map<std::string, double> memo_;
};

}  // namespace ontime
