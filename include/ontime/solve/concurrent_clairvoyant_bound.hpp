#pragma once
// `ConcurrentClairvoyantBound`: an upper bound on the chance that the robot acting while planning
// (SPEC §10) ends the episode in time from a state, computed exactly over the skeletons' tree.
//
// What it computes. Draw every action's planning time (its effort until found, conditioned on the
// effort PT already spent on the current one) and execution time once, as latent values. For a live
// skeleton k let S_k be the event that the policy devoted to k (the planner refines k's actions in
// order from now, the robot starts each as soon as it is refined and the robot is free) finishes
// k by D. Any policy that ends the episode through k has found and started each of k's actions no
// sooner than the devoted one (the planner works on one action at a time), so it succeeds only on
// S_k, and V*(s) <= P(union of S_k) (times the largest reward with rewards, SPEC §8). This class
// computes P(union of S_k) exactly: the devoted timelines of the skeletons through an action agree
// up to it (the step T at which it is found and the step F at which the robot has run it), and
// the subtrees below it depend on disjoint latent values, so given (T, F)
//   U(v, T, F) = 1{F <= D}                                  when a skeleton ends at v,
//              = 1 - prod over children c of (1 - E[U(c, T + t_c, max(F, T + t_c) + x_c)])  else,
// the expectation over c's planning time t_c (T + t_c <= D) and execution time x_c; from the state,
// the children of E at (CT, CT + r), refined actions adding their known execution to F, the
// current action's planning conditioned on its PT. It is at most the union bound (the sum of the
// devoted values) and at most ConcurrentValueBounds' grouped form, and far below them where
// skeletons share long prefixes (their devoted successes are nearly the same event).
// docs/theory.md, "Acting while planning: bounds on V* for the searches", has the proof.
//
// With backtracking (SPEC §7) it is the chance of the union in the relaxation in which the first
// give-up ends the episode (ConcurrentValueBounds): each attempt ends found, gives up or never, and
// S_k also holds when one of the devoted policy's attempts gives up by D; a give-up counts with the
// robot past the deadline (in the model it may discard a slow motion), so F runs to D + 1 and
//   U(v, T, F) = 1 if F <= D and a skeleton ends at v, else 1 - prod over c of (1 - E[U(c, ...)]),
// a give-up of c adding its chance to E[U(c, ...)]. Not with chains or expiry (SPEC §9): UsageError.
// Cost: the values of unrefined actions, U(v, T, F), are memoised (A * (D + 1)^2 doubles, with
// backtracking A * (D + 1) * (D + 2), each summed once over its planning and execution outcomes);
// a state costs a walk over its live refined and current actions with those outcomes. Not
// thread-safe (the memo): one per thread.

#include <vector>

#include "ontime/mdp/concurrent_mdp.hpp"

namespace ontime {

class ConcurrentClairvoyantBound {
 public:
  // The bound for the states of `mdp`, which must outlive it.
  explicit ConcurrentClairvoyantBound(const ConcurrentMdp& mdp);

  // P(union of S_k) at a state with some live skeleton (0 when none is live).
  double union_probability(const ConcurrentState& state);

 private:
  // U of action v (every action from v on unrefined), found at T, run by the robot until F.
  double fresh(int v, Steps time, Steps free);
  // 1 - prod over the children of v (the next actions of the skeletons through v; for v = -1 the
  // first actions) of (1 - their value), each child valued by `child`; or 1{free <= D} when a
  // skeleton ends at v.
  template <class ChildValue>
  double below(int v, Steps free, ChildValue&& child) const;
  // E over the planning (from `spent` steps of effort) and execution of action `a`, started on at
  // T with the robot free at F, of `after(T', F')`.
  template <class After>
  double expect(int a, Steps spent, Steps time, Steps free, After&& after) const;
  // The value of action v at a state: refined, current or fresh for the live skeletons through it.
  double at_state(const ConcurrentState& state, int v, Steps time, Steps free);
  // With backtracking: whether an action below v (v = -1: anywhere) may give up.
  bool gives_up_below(int v) const {
    return backtracking_ && gives_up_below_[v < 0 ? gives_up_below_.size() - 1 : static_cast<std::size_t>(v)] != 0;
  }

  const ConcurrentMdp* mdp_;
  Steps deadline_;
  bool backtracking_;
  std::size_t free_side_ = 0;               // the values of F memoised: D + 1, with backtracking D + 2
  std::vector<char> gives_up_below_;        // per action, then the roots (index A)
  std::vector<std::vector<int>> children_;  // per action, then the roots (index A): next actions
  std::vector<char> ends_;                  // per action: some skeleton ends there
  std::vector<double> memo_;                // [v][T][F]; negative: not computed
};

}  // namespace ontime
