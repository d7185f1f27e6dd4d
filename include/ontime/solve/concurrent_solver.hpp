#pragma once
// The exact solver of the acting-while-planning MDP (SPEC §10): expectimax over the reachable
// states of ConcurrentMdp, memoised.
//
// Computes V*(s), the maximum expected reward (the success probability without rewards), over
// every policy that chooses, at each state, a start (while the robot is idle: a refined child of
// what it executed, on a live skeleton) or a step (the planner refines one group of live
// skeletons sharing their next action, or idles when none has work left), and the move that
// attains it.
//
// Guarantees: the value is exact up to floating-point rounding; the moves left out are never
// better (docs/theory.md, "Acting while planning"): without backtracking an idle planner while
// some live skeleton has work left and any move but the start when every live skeleton goes on
// through one refined child of what the robot executed (ConcurrentMdp::forced_start), and,
// without rewards, any move once a live skeleton is refined in full and fits
// (ConcurrentMdp::certain_success: worth 1). With backtracking (SPEC §7) every move is considered
// but at a certain success; with chains or expiry (SPEC §9) there is no forced start nor certain
// success (waiting for a chain may pay), and a start whose execution a chain's state draws is a
// chance move over that draw. Plan-first is one
// policy of this MDP, so V* is at least the plan-first optimum (OptimalSolver) of the same problem.
// Ties: the move is the first, in this order, whose value is within kTieTolerance of the largest:
// the steps, ascending by skeleton, then the planner idling, then the starts, ascending by action;
// so the robot starts an action only when starting is worth more than planning on while it waits.
// Without backtracking, chains or expiry the memo is keyed by ConcurrentMdp::merge_backlogs
// (states whose refined motions differ only within what one skeleton alone runs, with the same
// sums, share their value), and the key itself is the state expanded: a key's value does not depend
// on which of its states was met first, so solvers that meet them in other orders (the search, the
// layered solver) have its bits.
//
// Branch and bound (set_bounds, `solve --method search`): given certified intervals around V* of
// the states not solved yet, a state's moves get intervals from their successors (exact where
// solved); the move of the largest lower end is solved first, then only the moves whose upper
// end reaches within kTieTolerance of its value. The others can be neither the largest nor tied
// with it, so the value and the move of every state solved are the memoised solver's to the bit
// (each value summed over the same outcomes in the same order from the same successor values),
// while far fewer states are solved where the bounds are tight.
//
// Cost: time and memory linear in the reachable states, which grow with the skeletons, the
// deadline and the execution times the robot may still run (one word each, per refined action);
// each state costs its words (4 + 2K + A, two bytes each) and a hash-table slot. The solver stops
// with ResourceLimitError past `max_states` states, never by running out of memory, and walks the
// states with an explicit stack (no recursion), so any deadline is safe.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <utility>

#include "ontime/mdp/concurrent_mdp.hpp"

namespace ontime {

class ConcurrentSolver {
 public:
  static constexpr double kTieTolerance = 1e-12;
  static constexpr std::size_t kDefaultMaxStates = 10'000'000;

  using Move = ConcurrentMdp::Move;
  // A stationary policy: the move it makes in a running state (a start the state allows, or a
  // step on a live skeleton with work left, or kWait).
  using Policy = std::function<Move(const ConcurrentState&)>;

  // The optimum of `mdp`, holding at most `max_states` states (ResourceLimitError past them).
  explicit ConcurrentSolver(const ConcurrentMdp& mdp, std::size_t max_states = kDefaultMaxStates);
  // Exact evaluation of `policy` instead of the optimum: solve() then gives V^policy, walking the
  // states the policy reaches (no move is left out or forced, and no state is worth 1 before the
  // policy's plan ends; a step asked for at the deadline ends the episode, worth 0). A move the
  // state does not allow throws UsageError.
  ConcurrentSolver(const ConcurrentMdp& mdp, Policy policy, std::size_t max_states = kDefaultMaxStates);
  ~ConcurrentSolver();
  ConcurrentSolver(const ConcurrentSolver&) = delete;
  ConcurrentSolver& operator=(const ConcurrentSolver&) = delete;

  // V*(root); solves every state reachable from it that is not known yet. Throws
  // ResourceLimitError at the state cap and Cancelled when the stop condition holds (the states
  // solved so far are kept).
  double solve(const ConcurrentState& root);

  // The best move in a state already solved that is not terminal, or nullopt.
  std::optional<Move> best_move(const ConcurrentState& state) const;
  // The value solve() gives `state` when that needs no solving: a state already solved, or one
  // worth 0 (no skeleton can finish) or, for the optimum, 1 (ConcurrentMdp::certain_success);
  // nullopt otherwise. O(1) after copying the state's key.
  std::optional<double> value(const ConcurrentState& state) const;

  // Certified bounds {lower, upper} around V* of a live state (lower <= V* <= upper).
  using Bounds = std::function<std::pair<double, double>(const ConcurrentState&)>;
  // Branch and bound with `bounds` (class comment); the optimum only (a policy's value ignores
  // them). Empty: every move solved.
  void set_bounds(Bounds bounds);

  // A condition checked every few thousand states while solving.
  void set_stop(std::function<bool()> stop);

  // States memoised so far.
  std::size_t states() const noexcept;
  // The most memory a solve of `problem` may hold under a cap of `max_states` states: each
  // state's words and hash-table slot, the table's power-of-two growth, the old and the new
  // table while it grows, and the stack of states waiting for their successors.
  static double max_bytes(const Problem& problem, std::size_t max_states);
  // The MDP solved.
  const ConcurrentMdp& mdp() const noexcept { return *mdp_; }

 private:
  struct Impl;
  const ConcurrentMdp* mdp_;
  std::unique_ptr<Impl> impl_;
};

// The value of a state that needs no solving: 0 when no skeleton can finish any more; for the
// optimum (`optimum`, not a policy's value), 1 when ConcurrentMdp::certain_success holds; nullopt
// otherwise. O(K * A_max).
std::optional<double> settled_value(const ConcurrentMdp& mdp, const ConcurrentState& state, bool optimum = true);

// Q of `move` in `state`, a running state of `mdp` that allows it: the expected reward over its
// outcomes in the MDP's order, value(next) at each successor (a start that ends the episode: its
// reward). A step at the deadline ends the episode: 0. With value = V* it is Q*; cost: the
// outcomes, one call of value each.
template <class Value>
double move_value(const ConcurrentMdp& mdp, const ConcurrentState& state, const ConcurrentMdp::Move& move,
                  Value&& value) {
  double q = 0.0;
  if (move.is_start()) {
    mdp.for_each_start_outcome(state, move.start, [&](double probability, const ConcurrentMdp::StartOutcome& outcome) {
      q += probability * (outcome.ends ? outcome.reward : value(outcome.next));
    });
  } else if (ConcurrentMdp::time(state) < mdp.deadline()) {
    mdp.for_each_step_outcome(state, move.refine,
                              [&](double probability, const ConcurrentState& next) { q += probability * value(next); });
  }
  return q;
}

}  // namespace ontime
