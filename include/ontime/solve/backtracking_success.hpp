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
// O(positions x D x (|supp e| |N| + |culprits|)), later ones a hash lookup). Every value depends
// only on values at a later CT (an attempt takes at least one step), so they are settled with an
// explicit stack, deepest first, rather than by recursion that the deadline would make deep. A
// key is five integers: the restore lists are interned (one number per distinct list), so a
// decision after warm-up allocates nothing. One evaluator per allocator: it is not thread-safe.

#include <absl/container/flat_hash_map.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/contiguous_success.hpp"
#include "ontime/solve/interned_lists.hpp"

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
  // A fresh attempt at position l of skeleton k at time ct with execution et, and the restore
  // values of the positions before l (an interned list: restore_parent_ and restore_value_).
  struct Key {
    std::int32_t skeleton;
    std::int32_t position;
    std::int32_t time;
    std::int32_t execution;
    std::uint32_t restores;
    bool operator==(const Key&) const = default;
    template <typename H>
    friend H AbslHashValue(H hash, const Key& key) {
      return H::combine(std::move(hash), key.skeleton, key.position, key.time, key.execution, key.restores);
    }
  };

  // V of `key`, settling every value it needs first.
  double fresh(const Key& key);
  // The sum over the attempt's steps for `key`, its attempt already `spent` steps old (not
  // divided by the survival). Values it needs that are not known yet are pushed on pending_ and
  // `ready` is cleared (the sum is then incomplete).
  double attempt(const Key& key, Steps spent, bool& ready);
  // The value of a needed key: 0 past the deadline, memoised, or pending (0, not ready).
  double need(const Key& key, bool& ready);
  // Settles pending_ until it is empty.
  void settle();

  const Mdp* mdp_;
  Aggregation aggregation_;
  Steps deadline_;
  absl::flat_hash_map<Key, double> memo_;
  std::vector<Key> pending_;
  InternedLists<std::uint16_t> restores_;  // the restore lists of the keys
};

}  // namespace ontime
