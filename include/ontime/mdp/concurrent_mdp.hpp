#pragma once
// The acting-while-planning MDP of SPEC §10: one planner and one robot body work at once.
//
// The planner spends each step on one action, as in SPEC §2 (the hazard, then an execution time
// drawn when the motion is found). Meanwhile the robot executes refined actions one at a time
// along the executed prefix E, a node of the skeletons' prefix tree: it is either idle at E or
// executing E's last action with r steps left. While it is idle it may start a refined child c of
// E (a move that takes no time: E becomes E + c, r the execution time of c) or wait. Starting c
// commits the robot: the skeletons not through c are dropped. The episode succeeds when the robot
// starts the last action of a skeleton k and finishes it by the deadline D, at step f, with the
// reward R_k(f) of SPEC §8 (1 without rewards); it fails when no skeleton can finish by D.
//
// A state is a short array of 16-bit words (ConcurrentState), in this order:
//   CT; r (0: the robot is idle); E (0: nothing executed, else 1 + the index of E's last action);
//   the chains' joint state (SPEC §9; 0 without chains); per skeleton l_k (kDropped once it is not through E or cannot
//   finish by D) and PT_k; per action its execution time x_a (D + 1 for too slow or never) while it is refined, below E
//   and on a live skeleton, kUnknown otherwise.
// States are canonical: what cannot change the value (dropped skeletons, executions no live
// skeleton will run) holds fixed values, so that states with equal futures are equal. A skeleton
// is live when it is through E and its earliest finish (below) is at most D; once dropped it
// never comes back (the earliest finish never decreases).
//
// Moves: a start (robot idle; a refined child of E on a live skeleton), instantaneous; a step:
// the planner refines the next action of one group of live skeletons sharing it (or idles,
// kWait), the robot executes one step, CT grows by one. Within a step both work at once; a motion
// found in the step from CT to CT + 1 can start at CT + 1 at the earliest.
//
// Backtracking (SPEC §7, §10 "With backtracking"): a step may also end the attempt by giving up
// and blaming a culprit c. When c is not executed, every skeleton through c goes back to c (its
// motion and everything refined below it discarded, effort on them too). When c is executed or
// executing, its motion cannot be undone: what was refined below it and not started is discarded
// all the same (every live skeleton goes back to E, effort lost), and the action that gave up is
// blocked, the skeletons through it dropped. With backtracking a skeleton that cannot finish by D stays in the state
// (a backtrack may discard a slow motion and make it able again, and refining it may cause such a
// backtrack), so "live" then means through E only, and the failure test reads the earliest
// finish.
//
// Exogenous chains and expiry (SPEC §9, §10 "With chains"): every step moves the chains by one
// step of their joint transition, whatever the move; a start takes no time and moves nothing. An
// action whose execution depends on a chain has it drawn when it starts, from the chain's state
// then (its word holds kDrawnAtStart while it is refined and not started); an action that expires
// can be started only up to its step `after` and while its chain is in no blocking state. The
// robot may wait whenever it is idle, also with a plan refined in full: with chains or expiry the
// solvers use neither the forced start nor the certain success.
//
// Cost: a move copies and canonicalises one state, O(K * A_max + A) word operations; the tables
// (hazards, execution outcomes: the plan-first Mdp's, so that both models read the same numbers
// to the bit) are built once.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/model/problem.hpp"

namespace ontime {

// A state of SPEC §10, the words described above.
using ConcurrentState = std::vector<std::uint16_t>;

// What the states hold of a skeleton that is through E but can no longer finish by D: `dropped`
// (canonical: it reads as not live, and the executions only it would run are forgotten), or `kept`
// (it stays live until E leaves it, as every skeleton does with backtracking). Kept, the states
// say nothing the model's distributions alone imply, which is what an allocator deciding with
// other distributions (a belief, SPEC §10 "Beliefs") must be shown: the skeletons it believes able
// are its own to judge. The values of the states and of every policy are the same either way.
enum class HopelessSkeletons { dropped, kept };

class ConcurrentMdp {
 public:
  // An execution time that is not known (not refined, or no live skeleton will run it).
  static constexpr std::uint16_t kUnknown = 0xFFFF;
  // l_k of a skeleton that is dropped (not through E, or unable to finish by the deadline).
  static constexpr std::uint16_t kDropped = 0xFFFF;
  // The step choice in which the planner idles (the robot still executes).
  static constexpr int kWait = -1;
  // CT, PT and the saturated D + 1 fit a word and stay apart from kUnknown.
  static_assert(Problem::kMaxDeadline + 1 < kUnknown);
  // x_a of a refined action whose execution is drawn from a chain's state when it starts.
  static constexpr std::uint16_t kDrawnAtStart = 0xFFFE;
  static_assert(Problem::kMaxDeadline + 1 < kDrawnAtStart);

  // One move: a start of `start` (an action index), or a step refining skeleton `refine`'s next
  // action (kWait: the planner idles).
  struct Move {
    int start = -1;
    int refine = kWait;
    // Whether the move starts an action (else it is a step).
    bool is_start() const noexcept { return start >= 0; }
    friend bool operator==(const Move&, const Move&) = default;
  };

  // Any acting mode is read as concurrent (the model of this class). `hopeless`: whether a
  // skeleton that can no longer finish by D is dropped from the states (the default) or kept.
  explicit ConcurrentMdp(const Problem& problem, HopelessSkeletons hopeless = HopelessSkeletons::dropped);
  ~ConcurrentMdp();
  ConcurrentMdp(const ConcurrentMdp&) = delete;
  ConcurrentMdp& operator=(const ConcurrentMdp&) = delete;

  // The problem, read plan-first (the acting mode is this class's), its deadline D and its K.
  const Problem& problem() const noexcept { return *problem_; }
  // The deadline D in steps.
  Steps deadline() const noexcept { return deadline_; }
  // The number of skeletons K.
  int skeleton_count() const noexcept { return skeleton_count_; }
  // Whether some attempt may give up and blame a culprit (SPEC §7).
  bool has_backtracking() const noexcept { return backtracking_; }
  // Whether some execution depends on a chain or some action expires (SPEC §9).
  bool is_timed() const noexcept { return timed_; }

  // The start: CT 0, the robot idle, nothing executed or refined (canonical).
  ConcurrentState start() const;

  // CT: the steps used.
  static Steps time(const ConcurrentState& state) noexcept { return state[0]; }
  // r: the steps the robot still needs for the action it executes, 0 while it is idle.
  static Steps robot_left(const ConcurrentState& state) noexcept { return state[1]; }
  // The last action of E, -1 while nothing has been started.
  static int executed(const ConcurrentState& state) noexcept { return static_cast<int>(state[2]) - 1; }
  // The chains' joint state (Mdp::joint_chain_state; 0 without chains).
  static std::uint16_t chains(const ConcurrentState& state) noexcept { return state[3]; }
  // Whether skeleton k is through E and (unless hopeless skeletons are kept) can still finish by D.
  static bool is_live(const ConcurrentState& state, int k) noexcept { return refined_word(state, k) != kDropped; }
  // l_k of a live skeleton: its actions refined.
  static int refined(const ConcurrentState& state, int k) noexcept { return refined_word(state, k); }
  // PT_k of a live skeleton: the steps spent on its next action.
  Steps spent(const ConcurrentState& state, int k) const noexcept {
    return state[kHeader + static_cast<std::size_t>(skeleton_count_ + k)];
  }
  // x_a, kDrawnAtStart or kUnknown.
  std::uint16_t execution(const ConcurrentState& state, int action) const noexcept {
    return state[kHeader + 2 * static_cast<std::size_t>(skeleton_count_) + static_cast<std::size_t>(action)];
  }
  // Whether some skeleton can still finish by D (else the state is worth 0).
  bool any_live(const ConcurrentState& state) const noexcept;
  // Position of E's last action + 1: how many actions of a skeleton through E have been started.
  int executed_depth(const ConcurrentState& state) const noexcept;
  // When the robot is free if it runs live skeleton k's refined actions after E back to back from
  // now: CT + r + their execution times (an execution drawn when it starts: its fastest).
  std::int64_t robot_free(const ConcurrentState& state, int k) const noexcept;
  // The plan-first Mdp of the same problem: its hazards and execution outcomes are this model's.
  const Mdp& plan_first_mdp() const noexcept { return mdp_; }
  // The fastest execution `action` may take within D: the least step of its execution
  // distribution, or with an execution drawn from a chain when it starts, the least over every
  // state of the chain; kNever when none is within D. O(1).
  Steps fastest_execution(int action) const noexcept { return fastest_execution_[static_cast<std::size_t>(action)]; }

  // The earliest step at which live skeleton k can finish: the robot free at CT + r, then each
  // action of k after E in order, started when the robot is free and the action refined (now,
  // for a refined one; for the rest, the planner on k alone with each action's fastest planning,
  // the current one's given PT_k) and run for its execution (the fastest for an unrefined one).
  // With backtracking a refined motion at or below a culprit may be discarded and found again with
  // a faster execution, and the current attempt may give up and start afresh:
  // such a motion counts its fastest execution, and the current action the sooner of its
  // planning given PT_k and from 0. A lower bound on every finish of k; without backtracking the
  // finish of executing k as soon as possible once k is refined. Mdp::kUnreachableNeed or more
  // when k cannot finish at all.
  std::int64_t earliest_finish(const ConcurrentState& state, int k) const noexcept;

  // The children of E the robot may start now (refined, on a live skeleton, and with expiry not
  // past their step `after` nor blocked by their chain's state), ascending; empty while it
  // executes.
  std::vector<int> startable(const ConcurrentState& state) const;
  // The start that is as good as every other move (docs/theory.md, "Acting while planning"): the
  // robot is idle and every live skeleton goes through one child c of E, which is refined; -1
  // otherwise, and always with backtracking (an executed motion can no longer be blamed and
  // refined again, so committing may cost) or with chains or expiry (waiting may pay).
  int forced_start(const ConcurrentState& state) const noexcept;

  // The moves the exact solver considers (ConcurrentSolver), in its tie order: the forced start
  // alone when there is one; else, before the deadline, the step choices (refine_choices), then
  // kWait when none has work left or with backtracking, then the startable actions, ascending.
  // Empty when no skeleton can finish. Leaving the others out loses nothing (docs/theory.md,
  // "Acting while planning").
  std::vector<Move> useful_moves(const ConcurrentState& state) const;

  // What starting `action` (a startable child of E) leads to: the end of the episode, when it is
  // the last action of a live skeleton (`reward`: R_k at its finish, 0 past the deadline), or
  // `next` (canonical). Throws UsageError when the action is not startable.
  struct StartOutcome {
    bool ends = false;
    double reward = 0;
    ConcurrentState next;
  };
  // Starts `action` in `state`: the end of the episode or the next state, as above. An execution
  // drawn from a chain when it starts takes `drawn` steps (the world's draw; kNever or past D:
  // too slow), which is required for it (UsageError otherwise) and ignored for any other.
  StartOutcome start_action(const ConcurrentState& state, int action, Steps drawn = -1) const;
  // Calls visit(probability, outcome) for every outcome of starting `action`: one, or with an
  // execution drawn from a chain when it starts, one per execution time of the chain's state now.
  template <class Visitor>
  void for_each_start_outcome(const ConcurrentState& state, int action, Visitor&& visit) const;

  // The world's draw of `action`'s execution when it starts (SPEC §9): with an execution drawn from
  // a chain when it starts, one draw from the chain's state now (the distribution
  // for_each_start_outcome enumerates; kNever: none); -1 for any other action. O(1) draws.
  template <class Generator>
  Steps sample_start_execution(const ConcurrentState& state, int action, Generator& generator) const;

  // The step choices worth considering: one per group of live skeletons sharing their next action
  // (named by the lowest index), ascending; empty when no live skeleton has an action left to
  // refine. Without backtracking refining never lowers the value (docs/theory.md), so an idle
  // planner is worth considering only then; with backtracking it always is (an attempt may
  // discard motions).
  ChoiceList refine_choices(const ConcurrentState& state) const;

  // Calls visit(probability, next) for every outcome of one step in which the planner refines
  // skeleton `choice`'s next action (or idles, kWait), `next` canonical. Outcomes of zero
  // probability are skipped. Throws UsageError for a choice that is not live with work left.
  template <class Visitor>
  void for_each_step_outcome(const ConcurrentState& state, int choice, Visitor&& visit) const;

  // The step in which the planner refines skeleton `choice`'s next action (or idles, kWait) and
  // `observation` is what it revealed (a world's answer): the canonical next state, the same as
  // for_each_step_outcome's for that outcome. An execution time beyond the deadline (or kNever)
  // is stored as D + 1. Throws UsageError for a choice for_each_step_outcome refuses, a step at
  // the deadline, a motion found or a backtrack on an idle step, or a culprit the action cannot
  // blame.
  ConcurrentState step(const ConcurrentState& state, int choice, const Observation& observation) const;

  // What the robot's clock says after a step or before a move (a live session,
  // run/concurrent_session.hpp): CT (at least the state's), the steps the robot's current
  // execution still needs (0: idle), and the slices of effort an unsuccessful call counted beyond
  // the model's one.
  struct ClockReading {
    Steps time = 0;
    Steps robot_left = 0;
    Steps extra_effort = 0;
    // Exogenous chains (SPEC §9): their joint state at `time` for on_clock (a session that follows
    // them along its clock); -1 keeps the state's. step() reads the observation's instead.
    int chains = -1;
  };
  // step() with CT, r and the effort read off the clock instead of one step each: the planner's
  // PT grows by 1 + extra_effort on a miss. step(state, choice, observation) is this with CT + 1,
  // r - 1 and no extra effort. Throws what step() throws.
  ConcurrentState step(const ConcurrentState& state, int choice, const Observation& observation,
                       const ClockReading& clock) const;
  // The state brought up to the clock between steps: CT raised to clock.time, r set to
  // clock.robot_left, the chains' joint state set to clock.chains unless it is -1 (canonical;
  // extra_effort is not used). Throws UsageError for a joint state the chains do not have.
  ConcurrentState on_clock(const ConcurrentState& state, const ClockReading& clock) const;

  // The state of what is known, for a session whose skeletons change (run/concurrent_session.hpp):
  // CT `time`, the robot's `robot_left`, the executed prefix ending with action `executed` (-1:
  // none), and per action its execution time in steps once refined (-1: not refined) and the steps
  // of effort spent on it (its PT while unrefined). A skeleton has refined its leading actions
  // whose execution is known; canonical (the skeletons not through the prefix, or unable to finish,
  // dropped). Both spans have an entry per action. With exogenous chains (SPEC §9) `chains` is
  // their joint state now, and a refined action whose execution a chain draws when it starts holds
  // kDrawnAtStart whatever its entry says (UsageError for a joint state the chains do not have).
  ConcurrentState state_of(Steps time, Steps robot_left, int executed, std::span<const Steps> execution,
                           std::span<const Steps> effort, std::uint16_t chains = 0) const;

  // `state`, a state of a model of the same skeletons and deadline (the instance's own with
  // hopeless skeletons kept, say), as this model holds it: canonical, the skeletons this model's
  // distributions count as hopeless dropped unless it keeps them, and the executions no live
  // skeleton runs forgotten. How an allocator deciding with other distributions sees the world's
  // states (seen_by_belief, allocators/concurrent_allocator.hpp). O(K * A_max + A).
  ConcurrentState canonical(const ConcurrentState& state) const;

  // `state` with every skeleton dropped but live skeleton k and those whose path is a prefix of k's
  // (canonical): the state of a policy devoted to k, in which only steps and starts along k (and the
  // planner idling) are moves, and an episode still ends through such a prefix. O(K * A_max + A).
  ConcurrentState devoted_to(const ConcurrentState& state, int k) const;

  // The state with the robot's current execution finished now (r = 0; canonical): what a robot
  // that finished sooner than its motion's execution time reports. The state itself while it is
  // idle.
  ConcurrentState execution_finished(const ConcurrentState& state) const;

  // When some live skeleton is refined in full (the lowest index of them, k): the move that runs
  // it as soon as it can, the start of k's next action while the robot is idle and (with expiry,
  // SPEC §9) that action may start now, else a step in which the planner idles. Without rewards,
  // chains or expiry that is optimal (certain_success); it is the commit rule the allocators follow
  // once a plan is complete. The default Move (the planner idles) when there is no such skeleton
  // (complete_plan(state) < 0).
  Move run_complete_plan(const ConcurrentState& state) const;
  // The lowest index of a live skeleton refined in full whose execution from now, back to back,
  // ends by D; -1 when there is none.
  int complete_plan(const ConcurrentState& state) const noexcept;

  // Whether value_key may merge executions: neither backtracking (SPEC §7) nor chains or expiry
  // (SPEC §9), under which the order and the timing of a skeleton's motions matter.
  // Kept hopeless skeletons are not merged either (keys are the states themselves).
  bool merges_backlogs() const noexcept { return !keeps_hopeless_ && !timed_; }
  // Whether a skeleton that can no longer finish by D stays in the states (HopelessSkeletons::kept,
  // or backtracking).
  bool keeps_hopeless() const noexcept { return keeps_hopeless_; }
  // A key of `state` (canonical) such that two states with equal keys have equal optimal values
  // V* and allow the same moves, for the exact solver's memo (docs/theory.md, "Backlogs"): where
  // merges_backlogs(), the execution times of the refined actions that only one live skeleton k
  // runs, from the first such action after E on, are summed into that first action (the rest
  // hold 0), and when k is the only live skeleton and the robot executes, into r. Once the robot
  // starts an action no other live skeleton runs, k is the only live one and runs its refined
  // actions back to back (the forced start), so only their sum can change V*. The state itself
  // otherwise. The key is itself a state of the model whose key it is (merging twice changes
  // nothing), which the exact solvers expand in place of the states it stands for. Policy values
  // are not keyed so: a policy may read each execution time.
  // Cost: O(K * A_max) word operations.
  void merge_backlogs(ConcurrentState& key) const;

  // Without rewards (SPEC §8), chains or expiry (SPEC §9): whether some live skeleton is refined
  // in full and ends by D when executed as soon as possible (complete_plan). The planner idling
  // meanwhile, nothing is attempted, nothing given up: the state is worth 1.
  bool certain_success(const ConcurrentState& state) const noexcept;

 private:
  static constexpr std::size_t kHeader = 4;

  static std::uint16_t refined_word(const ConcurrentState& state, int k) noexcept {
    return state[kHeader + static_cast<std::size_t>(k)];
  }
  static std::uint16_t& refined_word(ConcurrentState& state, int k) noexcept {
    return state[kHeader + static_cast<std::size_t>(k)];
  }
  std::uint16_t& spent_word(ConcurrentState& state, int k) const noexcept {
    return state[kHeader + static_cast<std::size_t>(skeleton_count_ + k)];
  }
  std::uint16_t& execution_word(ConcurrentState& state, int action) const noexcept {
    return state[kHeader + 2 * static_cast<std::size_t>(skeleton_count_) + static_cast<std::size_t>(action)];
  }
  bool through_executed(const ConcurrentState& state, int k) const noexcept;
  // Drops the skeletons that are not live and forgets the executions no live skeleton runs.
  void canonicalise(ConcurrentState& state) const;
  // `joint` as the chains' joint state word; UsageError for one the chains do not have.
  std::uint16_t checked_chains(int joint) const;
  [[noreturn]] static void reject_choice(int choice);
  // The attempt on `action` (the next action of `group`'s live skeletons) gave up and blames
  // `culprit`; `next` has the step's time and robot applied. Not canonical.
  void give_up(ConcurrentState& next, const ConcurrentState& state, int action, int culprit) const;
  // Whether `k` (kept in the state) can still finish by D.
  bool can_finish(const ConcurrentState& state, int k) const noexcept { return earliest_finish(state, k) <= deadline_; }

  std::unique_ptr<const Problem> problem_;  // the problem, plan-first, so that mdp_ can read it
  Mdp mdp_;                                 // its hazards and execution outcomes
  Steps deadline_;
  int skeleton_count_;
  int action_count_;
  // Per action and PT in [0, D]: the fewest further steps until its motion can be found, kNever
  // when it cannot (the planning PMF's next positive step after PT).
  std::vector<Steps> next_finish_;
  std::vector<Steps> fastest_execution_;  // per action; kNever when none is finite
  bool backtracking_ = false;
  bool keeps_hopeless_ = false;        // backtracking_, or HopelessSkeletons::kept
  std::vector<std::uint8_t> culprit_;  // per action: 1 when some action may blame it
  bool timed_ = false;
  // Moves the chains one step from `state`'s joint state into `next` (already canonical) and calls
  // visit(probability * step probability, next) per step; without chains, once.
  template <class Visitor>
  void for_each_chain_step(ConcurrentState& next, double probability, Visitor&& visit) const;
  // Whether `action` may start at the state's CT in its chains' state (SPEC §9 expiry).
  bool may_start_now(const ConcurrentState& state, int action) const noexcept;
  // x_a of a refined action, its fastest (D + 1 for none) while it is drawn when it starts.
  std::int64_t known_execution(const ConcurrentState& state, int action) const noexcept {
    const std::uint16_t word = execution(state, action);
    if (word != kDrawnAtStart) return word;
    const Steps fastest = fastest_execution_[static_cast<std::size_t>(action)];
    return fastest == kNever ? std::int64_t{deadline_} + 1 : fastest;
  }
  // Whether `action` may still start at step `start` (its step `after`, SPEC §9).
  bool before_expiry(int action, std::int64_t start) const noexcept {
    const Steps last = problem_->action(action).start_by;
    return last == kNever || start <= last;
  }
};

template <class Visitor>
void ConcurrentMdp::for_each_chain_step(ConcurrentState& next, double probability, Visitor&& visit) const {
  if (!mdp_.has_chains()) {
    visit(probability, static_cast<const ConcurrentState&>(next));
    return;
  }
  for (const Mdp::ChainStep& step : mdp_.chain_steps(next[3])) {
    if (step.probability <= 0) continue;
    ConcurrentState moved = next;
    moved[3] = step.next;
    visit(probability * step.probability, static_cast<const ConcurrentState&>(moved));
  }
}

template <class Visitor>
void ConcurrentMdp::for_each_start_outcome(const ConcurrentState& state, int action, Visitor&& visit) const {
  const int chain = problem_->execution_chain(action);
  if (chain < 0) {
    visit(1.0, static_cast<const StartOutcome&>(start_action(state, action)));
    return;
  }
  const Distribution& drawn =
      problem_->action(action).execution_by_state[static_cast<std::size_t>(mdp_.chain_state(chains(state), chain))];
  double in_time = 0.0;
  for (Steps x = 0; x <= deadline_; ++x) {
    const double mass = drawn.pmf(x);
    if (mass <= 0) continue;
    in_time += mass;
    visit(mass, static_cast<const StartOutcome&>(start_action(state, action, x)));
  }
  // Too slow or never: one outcome, as in SPEC §2.
  if (1.0 - in_time > 1e-15)
    visit(1.0 - in_time, static_cast<const StartOutcome&>(start_action(state, action, kNever)));
}

template <class Generator>
Steps ConcurrentMdp::sample_start_execution(const ConcurrentState& state, int action, Generator& generator) const {
  if (execution(state, action) != kDrawnAtStart) return -1;
  const int chain = problem_->execution_chain(action);
  return problem_->action(action)
      .execution_by_state[static_cast<std::size_t>(mdp_.chain_state(chains(state), chain))]
      .sample(generator);
}

template <class Visitor>
void ConcurrentMdp::for_each_step_outcome(const ConcurrentState& state, int choice, Visitor&& visit) const {
  ConcurrentState next = state;
  ++next[0];
  if (next[1] > 0) --next[1];
  if (choice == kWait) {
    canonicalise(next);
    for_each_chain_step(next, 1.0, visit);
    return;
  }
  if (choice < 0 || choice >= skeleton_count_ || !is_live(state, choice) ||
      refined(state, choice) >= problem_->skeleton_length(choice)) {
    reject_choice(choice);
  }
  const int action = problem_->action_at(choice, refined(state, choice));
  const Steps pt = spent(state, choice);
  const double found = mdp_.hazard(action, pt);
  const double back = mdp_.backtrack_hazard(action, pt);
  // The live skeletons whose next action is `action` share it (SPEC §1): one step for all of them.
  const auto for_group = [&](auto&& change) {
    for (const int m : problem_->members(action)) {
      if (is_live(state, m) && refined(state, m) < problem_->skeleton_length(m) &&
          problem_->action_at(m, refined(state, m)) == action) {
        change(m);
      }
    }
  };
  // Without backtracking the miss is 1 - found, as the plan-first Mdp computes it (the same bits).
  const double missed_probability = back > 0.0 ? 1.0 - found - back : 1.0 - found;
  if (missed_probability > 0.0) {
    ConcurrentState missed = next;
    for_group([&](int m) { ++spent_word(missed, m); });
    canonicalise(missed);
    for_each_chain_step(missed, missed_probability, visit);
  }
  if (found > 0.0) {
    const auto refine = [&](std::uint16_t execution, double probability) {
      ConcurrentState refined_state = next;
      execution_word(refined_state, action) = execution;
      for_group([&](int m) {
        ++refined_word(refined_state, m);
        spent_word(refined_state, m) = 0;
      });
      canonicalise(refined_state);
      for_each_chain_step(refined_state, probability, visit);
    };
    if (problem_->execution_chain(action) >= 0) {
      refine(kDrawnAtStart, found);  // drawn when it starts (SPEC §9)
    } else {
      for (const Mdp::ExecutionOutcome& outcome : mdp_.execution_outcomes(action)) {
        refine(static_cast<std::uint16_t>(outcome.steps), found * outcome.probability);
      }
    }
  }
  if (back > 0.0) {
    for (const Problem::CulpritIndex& culprit : problem_->culprits(action)) {
      if (culprit.probability <= 0) continue;
      ConcurrentState gave_up = next;
      give_up(gave_up, state, action, culprit.action);
      canonicalise(gave_up);
      for_each_chain_step(gave_up, back * culprit.probability, visit);
    }
  }
}

}  // namespace ontime
