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
//
// With backtracking (SPEC §7, §10 "With backtracking") an attempt may also give up after t steps
// (q_a) and blame a culprit c (w_a(c)) at position p. With the robot eager, refined action i
// starts at S_i = max(F_i, found_i), F_i the step the robot is done with the actions before it;
// a give-up observed at T' finds c executed iff S_p < T'. Then c's motion stays, the action that
// gave up is blocked and the skeleton is dropped: 0. Else refinement goes back to c with the time
// kept, and the robot is free at S_p (c was found before T' <= S_p, so S_p = F_p), as §7. In
// absolute times, F the robot's free step before position l and B the starts S_i, i < l:
//   V(k, l, spent, T, F, B) = (1 / S_a(spent)) sum_{t >= 1, T + t <= D}
//       [ p_a(spent + t) G(T + t) + q_a(spent + t) sum_c w_a(c) [S_p >= T + t] V(k, p, 0, T + t, S_p, B below p) ]
//   G(T') = sum_x e_a(x) R_k(max(F, T') + x) within D, for the last action; otherwise
//   G(T') = sum_x e_a(x) AGG_{k' in N(k,l)} V(k', l + 1, 0, T', max(F, T') + x, B + max(F, T'))
// with S_a(spent) = 1 - sum_{u <= spent} (p_a(u) + q_a(u)). With aggregation self it is the exact
// value of the policy that refines k alone and starts each of its actions as soon as it is refined
// and the robot is free (docs/theory.md), unless another skeleton is a prefix of k (the episode
// would end through it). With every give-up probability zero it is the value above. These values
// are memoised per (skeleton, position, T, F, starts), the lists of starts interned, and settled
// with an explicit stack (a give-up sends a value back to an earlier position at a later time, so
// recursion could go D deep). The first query of a state costs O(positions x D x (|supp e| |N| +
// |culprits|)) per value it reaches; later ones a hash lookup or one sum over the attempt.
//
// With exogenous chains or expiry (SPEC §9, §10 "With chains and expiry") an execution drawn from a
// chain is known only when its action starts, from the chain's state then, and an action may start
// only up to its step `after` and outside its chain's blocking states: the robot's backlog is no
// longer a number, and the sums above have no term for the chains. What they compute, with
// aggregation `self`, is the value of one policy, the devoted eager one (devoted_move: the planner
// on k alone, each of k's actions started as soon as it is refined, the robot is free and the
// action may start; the planner idles while a complete plan waits for its next action), and that
// policy has an exact value with chains too, as plan-first Eq. (1) with chains has
// (timed_contiguous_success.hpp):
//   P_k(s) = sum_o P(o | s, devoted_move(s, k)) ([o ends the episode] R(o) + [else] P_k(o)),
// the sum over the outcomes of the move in SPEC §10 (a step's refinement outcome and the chains'
// step; a start's draw from its chain's state), the chains read in s and following their model
// from there (docs/theory.md, "Eq. (1) with chains and expiry"). Timing::exact takes it
// (aggregation `self` only: `sum` and `max` have no form there): the memoised policy evaluation of
// ConcurrentSolver, one memo per skeleton shared by every later query of the object. Cost: at most
// the states that policy reaches from the states asked about (ResourceLimitError past
// ConcurrentSolver::kDefaultMaxStates per skeleton); a query of a state already reached is one
// hash lookup. Without chains or expiry Timing::exact changes nothing.

#include <absl/container/flat_hash_map.h>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/solve/contiguous_success.hpp"
#include "ontime/solve/interned_lists.hpp"

namespace ontime {

class ConcurrentSolver;

class ConcurrentContiguousSuccess {
 public:
  // How a problem with exogenous chains or expiry (SPEC §9) is taken.
  enum class Timing {
    // The exact value of the devoted eager policy (above), with aggregation `self` only
    // (check_supported).
    exact,
    // The relaxation of ConcurrentValueBounds' upper bound: every execution drawn from a chain
    // when it starts takes its fastest over the chain's states (ConcurrentMdp::fastest_execution),
    // and no action expires or is blocked. With `self` the value is then at least what the devoted
    // policy earns in the model (docs/theory.md, "Acting while planning: bounds on V* for the
    // searches"), not its value. Without backtracking (SPEC §7): the give-up term is not relaxed.
    // Without chains or expiry it changes nothing.
    relax,
  };

  // The values of `mdp`'s skeletons with Eq. (1)'s `aggregation`; memoised as they are asked for.
  // Throws UsageError (check_supported) when the problem has chains or expiry and `timing` is exact
  // with an aggregation other than `self`.
  ConcurrentContiguousSuccess(const ConcurrentMdp& mdp, Aggregation aggregation, Timing timing = Timing::exact);
  ~ConcurrentContiguousSuccess();
  ConcurrentContiguousSuccess(const ConcurrentContiguousSuccess&) = delete;
  ConcurrentContiguousSuccess& operator=(const ConcurrentContiguousSuccess&) = delete;
  ConcurrentContiguousSuccess(ConcurrentContiguousSuccess&&) noexcept;
  ConcurrentContiguousSuccess& operator=(ConcurrentContiguousSuccess&&) noexcept;

  // With chains or expiry (SPEC §9) only the devoted policy's exact value (aggregation `self`) is
  // a form of Eq. (1): UsageError naming the rule for `sum` or `max` there, before any allocator
  // built on these values is made. Every aggregation is taken without them; backtracking (SPEC §7)
  // is taken (the give-up term above; with chains, in the devoted policy's value).
  static void check_supported(const ConcurrentMdp& mdp, Aggregation aggregation);

  // The move of the devoted eager policy of live skeleton k in a running state: while the robot is
  // idle and k's next action to execute is refined (and, with chains or expiry, may start now:
  // ConcurrentMdp::startable), its start; else a step on k while k has an action left to refine;
  // else the planner idles (kWait). kWait too once k is dropped. The commit rule of dp-rerun acting
  // while planning without chains or expiry (the best skeleton's devoted move; with them dp-rerun
  // makes the devoted optimum's move, concurrent_devoted_optimum.hpp). O(K) without chains or expiry; with them
  // O(K * A_max) for the startable actions.
  static ConcurrentMdp::Move devoted_move(const ConcurrentMdp& mdp, const ConcurrentState& state, int k);

  // PS(k, l, spent, time, backlog); 0 when the backlog alone passes the deadline. Without
  // backtracking only (with it a value needs the restore values: UsageError), and with chains or
  // expiry only under Timing::relax (else UsageError: the backlog is not a number).
  double value(int k, int l, Steps spent, Steps time, std::int64_t backlog);
  // The same for live skeleton k in `state` (its backlog: ConcurrentMdp::robot_free(state, k) -
  // CT); for a skeleton refined in full, its reward at the end of that backlog (0 past D). With
  // backtracking, V above from the state (the executed actions blamed: 0; each refined action not
  // started keeps its robot-free time and its start, the robot going on eagerly from now). With
  // chains or expiry and Timing::exact, P_k(state) above (ResourceLimitError past the state cap).
  double value(const ConcurrentState& state, int k);

  // How the skeletons that share an action are combined.
  Aggregation aggregation() const noexcept { return aggregation_; }

  // With backtracking (SPEC §7), the devoted policy of live skeleton k from `state` (the planner on
  // k alone, the robot eager along k) in the relaxation in which the first give-up ends the episode
  // (ConcurrentValueBounds' upper end): `reward`, its expected reward from finishing k with no
  // give-up before; `give_up`, the chance that one of k's attempts gives up by the deadline (its
  // robot's backlog may be past D: a give-up in the model may discard a slow motion). With
  // aggregation self only; executions relaxed as `Timing` says. Memoised per (skeleton, position,
  // time, robot's free step) with nothing spent, A * D^2 pairs at most; a query is one sum over at
  // most D - CT planning steps. Without backtracking `give_up` is 0 and `reward` is value(state, k)
  // up to rounding.
  struct GiveUpRelaxed {
    double reward = 0;
    double give_up = 0;
  };
  // The pair above for live skeleton k at `state` (a skeleton refined in full: its reward at the
  // end of its backlog, no give-up).
  GiveUpRelaxed give_up_relaxed(const ConcurrentState& state, int k);

 private:
  double fresh(int k, int l, Steps time, std::int64_t backlog);
  double after_found(int k, int l, Steps time, std::int64_t backlog);
  // (k, l, T, w or F) packed into one word, the key of both memos (each part below 2^16, k and l
  // below 2^8).
  static std::uint64_t memo_key(int k, int l, Steps time, std::int64_t last);
  // R_k at `finish`, 0 past the deadline (1 without rewards).
  double ending(int k, std::int64_t finish) const;
  // The execution outcomes of `action`; relaxed (Timing::relax), an execution drawn from a chain
  // when it starts takes its fastest, written into `fastest`.
  std::span<const Mdp::ExecutionOutcome> execution_outcomes(int action,
                                                            std::array<Mdp::ExecutionOutcome, 1>& fastest) const;
  // 1 - sum over u <= spent of (p(u) + q(u)): the chance that an attempt on `action` lasts
  // `spent` steps.
  double attempt_survival(int action, Steps spent) const;
  // give_up_relaxed's sum over the attempt at position l of k, `spent` steps old, found or given up
  // at T + t (not divided by its survival); `free` the robot's free step (saturated at D + 1).
  GiveUpRelaxed relaxed_attempt(int k, int l, Steps spent, Steps time, std::int64_t free);
  // The same with nothing spent, memoised.
  GiveUpRelaxed relaxed_fresh(int k, int l, Steps time, std::int64_t free);

  // With backtracking: a fresh attempt at position l of skeleton k at time T, the robot free at
  // F (absolute, at least T, saturated at D + 1), and the interned list of the starts S_i of the
  // positions i < l (saturated at D + 1; 0 for one executed or one no later action may blame).
  struct GiveUpKey {
    std::int32_t skeleton;
    std::int32_t position;
    std::int32_t time;
    std::int32_t free;
    std::uint32_t restores;
    bool operator==(const GiveUpKey&) const = default;
    template <typename H>
    friend H AbslHashValue(H hash, const GiveUpKey& key) {
      return H::combine(std::move(hash), key.skeleton, key.position, key.time, key.free, key.restores);
    }
  };
  // V's sum over the attempt's steps for `key`, the attempt already `spent` steps old (not divided
  // by its survival); values not known yet are pushed on pending_ and `ready` cleared.
  double give_up_attempt(const GiveUpKey& key, Steps spent, bool& ready);
  // A needed value: 0 at the deadline, memoised, or pending (0, `ready` cleared).
  double give_up_need(const GiveUpKey& key, bool& ready);
  // give_up_attempt made complete: settles what it needs first.
  double give_up_settled(const GiveUpKey& key, Steps spent);
  double give_up_value(const ConcurrentState& state, int k);

  const ConcurrentMdp* mdp_;
  Aggregation aggregation_;
  bool relaxed_ = false;  // Timing::relax on a problem with chains or expiry
  // Timing::exact on a problem with chains or expiry: per skeleton, the devoted policy's evaluation.
  std::vector<std::unique_ptr<ConcurrentSolver>> devoted_;
  Steps deadline_;
  std::unordered_map<std::uint64_t, double> fresh_;                 // (k, l, T, w) packed
  absl::flat_hash_map<std::uint64_t, GiveUpRelaxed> relaxed_memo_;  // (k, l, T, F) packed
  // Per skeleton and position: whether an action from there on may give up.
  std::vector<std::vector<char>> gives_up_after_;
  absl::flat_hash_map<GiveUpKey, double> give_up_memo_;
  std::vector<GiveUpKey> pending_;
  InternedLists<std::uint32_t> restores_;  // the lists of starts of the give-up keys
};

}  // namespace ontime
