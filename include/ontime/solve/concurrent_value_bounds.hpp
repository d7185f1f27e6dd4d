#pragma once
// Certified bounds on V*(state) of the acting-while-planning MDP (SPEC §10), cheap enough for
// every leaf of a search (mcts, branch-and-bound).
//
// Both rest on the devoted value P_k = ConcurrentContiguousSuccess::value(state, k) with
// aggregation `self`: the expected reward of the policy that refines live skeleton k alone,
// action after action, while the robot executes each of k's actions as soon as it is refined and
// the robot is free (for a skeleton refined in full: its reward at the end of its backlog). A
// skeleton k is *eligible* when no other live skeleton is a proper prefix of it and none with a
// lower index has the same actions: an ineligible one can never be the skeleton whose last start
// ends the episode (SPEC §10), and for an eligible one the devoted policy earns exactly P_k.
//   lower(state) = max over eligible k of P_k: the value of an actual policy, so at most V*;
//   upper(state) = min(R_cap, sum over eligible k of P_k), R_cap the largest reward an eligible
//   skeleton can still earn (R_k at its earliest finish; 1 without rewards): with each action's
//   planning and execution time a fixed latent draw, any policy that ends the episode through k
//   has refined and started each of k's actions no sooner than the devoted policy, so it succeeds
//   only where the devoted policy does, and earns at most its reward (SPEC §8's rewards do not
//   rise with the finish); the union of these events over k bounds V*. Without rewards, also
//   1 - prod over groups g of (1 - min(1, sum over k in g of P_k)), the skeletons grouped by their
//   next unrefined action: groups share no unrefined action, so their events are independent.
//   Tighter still, without chains or expiry, R_cap times the chance of the union of those events
//   itself, computed exactly over the skeletons' tree (ConcurrentClairvoyantBound).
// docs/theory.md, "Acting while planning", has the proofs. A state where no skeleton can finish
// is worth 0; without rewards one with a live skeleton refined in full is worth 1 (both exact).
//
// With exogenous chains or expiry (SPEC §9) P_k is the devoted value of the relaxed problem
// (ConcurrentContiguousSuccess::Timing::relax: each execution drawn from a chain when it starts at
// its fastest over the chain's states, nothing expires or is blocked), which is at least the
// devoted policy's value in the model and no more than that policy's value in the relaxation:
//   upper(state) is the same formula over these values, still at least V* (the coupling of the
//   proof gives every execution in the model at least its relaxed time, and expiry only removes
//   starts);
//   lower(state) = the largest expected reward of a start that ends the episode now (a last
//   action the robot may start; 0 when there is none): the value of that start, at most V*.
//
// With backtracking (SPEC §7) the devoted value P_k (ConcurrentContiguousSuccess::value) has the
// give-up term (a give-up that blames an executed action blocks k), still the exact value of the
// devoted policy, so lower(state) is as above (with chains or expiry too: the best ending start).
// The union bound is taken in the relaxation in which the first give-up ends the episode with
// R_cap, at least what the model earns after it (ConcurrentContiguousSuccess::give_up_relaxed: the
// relaxed devoted policy's reward A_k and give-up chance G_k):
//   upper(state) = min(R_cap, sum over eligible k of A_k + R_cap * sum over k of G_k),
// the second sum over the live skeletons no lower-indexed one spells again (a give-up on the
// actions a skeleton below a live prefix adds ends the relaxed episode too). Without rewards also
// the grouped form over A_k + G_k; without chains or expiry also R_cap times the chance of the union
// of these events, over the tree (ConcurrentClairvoyantBound, which counts a give-up as an event).
//
// Cost: per state O(K^2) to find the eligible skeletons and group them, plus K queries of
// ConcurrentContiguousSuccess (each a sum over at most D - CT planning steps of memoised values),
// with chains or expiry plus one pass over the execution times of each startable action; memory:
// that memo. Not thread-safe (the memo): one object per thread.

#include <optional>
#include <vector>

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/solve/concurrent_clairvoyant_bound.hpp"
#include "ontime/solve/concurrent_contiguous_success.hpp"

namespace ontime {

class ConcurrentValueBounds {
 public:
  // An interval [lower, upper] around V*(state).
  struct Interval {
    double lower = 0;
    double upper = 0;
  };

  // Bounds for the states of `mdp`, which must outlive this object; any problem of the model
  // (backtracking, chains, expiry, rewards).
  explicit ConcurrentValueBounds(const ConcurrentMdp& mdp);

  // Both bounds at `state` (any state of the MDP, terminal or not).
  Interval bounds(const ConcurrentState& state);
  // The lower bound alone: the best devoted policy's value (with chains or expiry: the best
  // start that ends the episode now).
  double lower(const ConcurrentState& state) { return bounds(state).lower; }
  // The upper bound alone: the union bound over the devoted policies (with chains or expiry: of
  // the relaxed problem).
  double upper(const ConcurrentState& state) { return bounds(state).upper; }

 private:
  // How live skeleton k stands among the live ones: eligible; below a live proper prefix (it
  // never ends the episode); or a twin (the same actions as a live one of lower index).
  enum class Standing { eligible, below_prefix, twin };
  // With chains or expiry: the largest expected reward of starting now an action whose every
  // outcome ends the episode (0 when there is none).
  double ending_start(const ConcurrentState& state) const;
  Standing standing(const ConcurrentState& state, int k) const;
  // A group of skeletons sharing their next unrefined action, and their summed chance.
  struct Group {
    int next;
    double chance;
  };

  const ConcurrentMdp* mdp_;
  ConcurrentContiguousSuccess devoted_;
  std::optional<ConcurrentClairvoyantBound> clairvoyant_;  // without chains or expiry
  std::vector<Group> groups_;                              // scratch
};

}  // namespace ontime
