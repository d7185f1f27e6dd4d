#pragma once
// A session in which the robot acts while planning (SPEC §10): the API a caller's own motion
// planner and robot drive, and the one place the library's concurrent episodes step through.
//
//   ontime::ConcurrentSession session(mdp, allocator);
//   while (session.status() == ontime::Status::running) {
//     const auto decision = session.choose();
//     if (decision.is_start()) { robot.execute(decision.start); continue; }  // takes no step
//     // ... one step of planning on decision.action (-1: the planner idles) while the robot moves ...
//     if (found) session.report_refined(execution_steps); else session.report_not_yet();
//   }
//
// choose() asks the allocator for the next move. A start is carried out at once (it takes no
// time: the robot begins executing that action, and the skeletons not through it are dropped) and
// may end the episode, when it is the last action of a skeleton: success when its execution ends
// by the deadline. A step awaits its report (carry_out(world) makes it in a World), after which the
// robot has run one more step of its current execution. The session fails when no skeleton can
// finish by the deadline any more.
//
// Exogenous chains and expiry (SPEC §9): the session simulates the chains from its seed (the
// stream plan-first Session draws them from), one path by step of CT: every step moves them by one
// draw of their joint transition, whatever the report says (its `chains` is not used), and an
// action whose execution depends on a chain has it drawn when it starts, from the chain's state
// then (ConcurrentMdp::sample_start_execution). A start is carried out only while the action may
// start (ConcurrentMdp::startable; UsageError otherwise). Live, the chains follow the clock: the
// state before every move and after every report holds their state at its CT, one step of their
// path per step of CT however many a call or a decision took (as a plan-first live session carried
// out in a world), and a chain-dependent execution lasts the steps drawn at its start (its seconds:
// those steps times step_seconds; the seconds reported with its motion are not used). A session
// that owns its problem carries the chains' joint state over to each new problem (the skeletons
// change, the chains do not).
//
// A live session (constructed with a Clock) runs on the robot's seconds as a live Session does
// (session.hpp, docs/live.md; the ledger is the same, live_ledger.hpp). The deadline is
// D * step_seconds after the session began, and the state the allocator sees is derived from the
// seconds gone before every move:
//   CT   = ceil(elapsed / step_seconds)
//   r    = ceil(end of the current execution / step_seconds) - CT, at least 0: the whole steps the
//          robot's motion still needs (its end is its start plus its execution seconds, or where
//          the robot reported it: report_execution_finished, report_execution_left)
//   PT_k += max(1, floor(planning seconds / step_seconds)) per unsuccessful call
// A start begins the motion when the robot is free (now, or when the motion before it ends), and
// its seconds are the ones reported with it (report_refined_seconds; steps convert at
// step_seconds each). Decisions (starts too) and planner overruns are charged; an idle planner
// step holds its slice. The last action of a skeleton started ends the episode: success when its
// execution ends within the deadline in seconds. With a manual clock advanced by exactly one slice
// per planner step and no time elsewhere, a live session makes exactly ConcurrentMdp's transitions.
//
// Cost: a move copies one state (ConcurrentMdp's words); nothing else is allocated per move but,
// live, one timeline entry (reserved up front) and one per execution, and with chains one word of
// their path per step of CT (amortised).

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/live_ledger.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/world.hpp"
#include "ontime/util/random.hpp"

namespace ontime {

// One move of a concurrent session.
struct ConcurrentDecision {
  int start = -1;     // the action the robot starts executing now (a move that takes no time), or -1
  int skeleton = -1;  // a step: the skeleton whose next action the planner refines (-1: it idles)
  int action = -1;    // that action (-1: the planner idles; the robot executes either way)
  // Whether the move is a start (else a step).
  bool is_start() const noexcept { return start >= 0; }
};

class ConcurrentSession {
 public:
  // Makes the allocator of a session whose skeletons change: called with the first ConcurrentMdp
  // and again with every new one. An empty maker: the caller decides every move (decide()).
  using AllocatorMaker = std::function<std::unique_ptr<ConcurrentAllocator>(const ConcurrentMdp&)>;

  // Calls allocator.begin_episode(seed). The Mdp and the allocator must outlive the session.
  ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, std::uint64_t seed = 0);
  // A session without an allocator: the caller decides every move (decide()). `seed` draws the
  // simulated chains (SPEC §9), as the allocator's session's seed does.
  explicit ConcurrentSession(const ConcurrentMdp& mdp, std::uint64_t seed = 0);
  // The same two live on `clock` (which must outlive the session); the deadline starts now. Throw
  // UsageError for a decision share outside (0, 1e6].
  ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, std::uint64_t seed, const Clock& clock,
                    LiveOptions options = {});
  ConcurrentSession(const ConcurrentMdp& mdp, const Clock& clock, LiveOptions options = {});
  // A session that owns its problem and its allocator, so that skeletons can arrive and leave while
  // it runs (a task planner streaming them, as Session's owning form); live on `clock` unless null.
  ConcurrentSession(const Problem& problem, AllocatorMaker make_allocator, std::uint64_t seed,
                    const Clock* clock = nullptr, LiveOptions options = {});

  ConcurrentSession(ConcurrentSession&&) noexcept = default;
  ConcurrentSession& operator=(ConcurrentSession&&) noexcept = default;
  ConcurrentSession(const ConcurrentSession&) = delete;
  ConcurrentSession& operator=(const ConcurrentSession&) = delete;
  ~ConcurrentSession() = default;

  // Asks the allocator for the next move and carries out a start at once. Throws
  // std::logic_error when the session is over, a step awaits its report or it has no allocator;
  // UsageError for a move the state does not allow. A live session first brings its state up to
  // the clock: when no skeleton can finish any more, it ends as a failure and the decision is empty
  // (no start, skeleton and action -1).
  ConcurrentDecision choose();
  // The caller's move, checked as choose() checks an allocator's (std::logic_error when the session
  // has an allocator); live, brought up to the clock first as choose() is.
  ConcurrentDecision decide(const ConcurrentMdp::Move& move);

  // Carries out the step just decided in `world` (world.step(action, effort already spent on it);
  // a step in which the planner idles never reaches the world) and reports it. Returns the status
  // after the step.
  Status carry_out(World& world);
  // Reports the step just decided: no motion found, or found with its execution time in steps
  // (kNever: it cannot be executed). Throws std::logic_error without a pending step, UsageError
  // for a motion reported on an idle step, a negative execution time or a backtrack.
  Status report_not_yet();
  Status report_refined(Steps execution_steps);
  Status report(const Observation& observation);
  // A live session's report of a found motion with its execution time in seconds (infinity: it
  // cannot be executed). Throws UsageError for a negative or NaN time, std::logic_error for a
  // session that is not live.
  Status report_refined_seconds(double execution_seconds);
  // Live sessions: the robot's execution of `action`, the one executing now, needs `seconds` more
  // from now (later or sooner than its motion's execution time said; 0: it has ended). Throws
  // UsageError for another action or a negative or non-finite time, std::logic_error as
  // report_execution_finished and for a session that is not live.
  Status report_execution_left(int action, double seconds);
  // The robot reports that its execution of `action` ended (a real robot may finish sooner than the
  // execution time its motion was found with; on the step clock, an execution ends by itself once
  // its steps have passed). For the action executing now the robot becomes idle, so that the next
  // start may come at once; for an action started earlier, whose execution ended when the next one
  // began, nothing changes. Throws UsageError for an action the robot did not start (naming the
  // rule), std::logic_error while a step awaits its report or after the end.
  Status report_execution_finished(int action);

  // Sessions that own their problem: a skeleton arrives (as Session::add_skeleton: known actions
  // are shared, new ones come with their distributions). What is known carries over: CT, the robot's
  // execution and what it executed, the actions refined (their execution times) and the effort spent
  // on each (ConcurrentMdp::state_of); a skeleton not through what the robot executed arrives
  // dropped. The allocator is made anew and decides from the current state. Returns its index.
  // Throws UsageError for a broken rule (the session is then unchanged), std::logic_error while a
  // step awaits its report, after the end, or for a session that does not own its problem.
  int add_skeleton(const std::vector<std::string>& action_ids, std::vector<Action> new_actions = {});
  // Sessions that own their problem: every dropped skeleton (not through what the robot executed, or
  // unable to finish by the deadline) leaves, the others keeping their order; returns how many left.
  // Nothing changes when none is dropped or all are (the session has then failed, or waits for more
  // skeletons). Same errors as add_skeleton.
  int retire_dropped();
  // Sessions that own their problem: while more skeletons are expected, the session does not end
  // when none of those found so far can finish (the deadline still ends it, as no step is left).
  void expect_more_skeletons(bool expected);
  // Whether some skeleton can still finish by the deadline.
  bool can_succeed() const { return mdp_->any_live(state_); }
  // The problem the session steps through (an owning session's grows and shrinks).
  const Problem& problem() const noexcept { return mdp_->problem(); }

  // Where the episode stands: running, then success or failure.
  Status status() const noexcept { return status_; }
  // The current state of SPEC §10.
  const ConcurrentState& state() const noexcept { return state_; }
  // The MDP the session steps through.
  const ConcurrentMdp& mdp() const noexcept { return *mdp_; }
  // After success, the skeleton whose last action the robot started (the lowest index when several
  // end with it); -1 before.
  int solution() const noexcept { return solution_; }
  // What the episode earned (SPEC §8): the solution's reward at the finish of its last execution (1
  // without rewards); 0 before success or after a failure.
  double reward() const noexcept { return reward_; }
  // Steps used so far (CT).
  Steps steps_used() const noexcept { return ConcurrentMdp::time(state_); }
  // The step at which the robot's last execution ends, after success; -1 before.
  Steps finish() const noexcept { return finish_; }
  // The actions started, in order.
  const std::vector<int>& started() const noexcept { return started_; }
  // What the session saw of each action's refinement (effort and whether it was found), by index.
  const std::vector<ActionAttempt>& attempts() const noexcept { return attempts_; }
  // The same, moved out.
  std::vector<ActionAttempt> take_attempts() noexcept { return std::move(attempts_); }

  // Whether the session runs on a Clock's seconds.
  bool is_live() const noexcept { return live_.is_live(); }
  // Live sessions: D * step_seconds, and the seconds gone (frozen when the session ended).
  double deadline_seconds() const noexcept { return live_.deadline_seconds(); }
  double elapsed_seconds() const;
  // Live sessions: time the clock did not see, added to the seconds gone (as Session's).
  void charge_outside(double seconds);
  // Live sessions: one entry per move (a start has `started`), the robot's executions from start to
  // end in seconds, and what was charged.
  const std::vector<LiveStep>& timeline() const noexcept { return live_.timeline(); }
  const std::vector<LiveExecution>& executions() const noexcept { return live_.executions(); }
  LiveTotals totals() const { return live_.totals(); }
  // Live sessions, after success: when the last execution ends, in seconds since the start; -1 before.
  double finish_seconds() const noexcept { return finish_seconds_; }

 private:
  ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator* allocator, std::uint64_t seed);
  // Carries out a move; live, the decision began at clock reading `begin` with CT `steps_before`.
  ConcurrentDecision carry_out_move(const ConcurrentMdp::Move& move, double begin = 0, Steps steps_before = 0);
  ConcurrentDecision start(int action);
  void end_if_stuck();
  // Live: the whole steps the robot's current execution still needs at CT `time`.
  Steps robot_left_at(Steps time) const;
  // Live: what the clock says at CT `time` (r, and with chains or expiry their state then).
  ConcurrentMdp::ClockReading clock_reading(Steps time);
  // The simulated chains' joint state at step `time` (0 without chains), their path drawn from
  // exogenous_ as far as it is needed.
  std::uint16_t chains_at(Steps time);
  // Live: the state brought up to the clock before a move; false when the session ended meanwhile.
  bool catch_up();
  // report() with the execution in seconds (NaN: from the steps), and its live half.
  Status report_with_seconds(const Observation& observation, double execution_seconds);
  Status report_on_clock(const Observation& observation, double execution_seconds);
  void require_live(const char* what) const;
  void check_changeable(const char* what) const;
  // An owning session keeps each refined action's execution steps (for the states of new problems).
  void remember_execution(const Observation& observation);
  void change_skeletons(const Problem& next);

  const ConcurrentMdp* mdp_;
  ConcurrentAllocator* allocator_;  // null: the caller decides
  ConcurrentState state_;
  ConcurrentState before_;  // the state before the pending step (reused)
  Status status_ = Status::running;
  bool pending_ = false;
  int pending_skeleton_ = -1;  // the pending step's choice (ConcurrentMdp::kWait: the planner idles)
  int pending_action_ = -1;
  int solution_ = -1;
  double reward_ = 0;
  Steps finish_ = -1;
  std::vector<int> started_;
  std::vector<ActionAttempt> attempts_;
  std::uint64_t seed_ = 0;
  SplitMix64 exogenous_{0};                // the simulated chains' draws (chains or expiry, SPEC §9)
  std::vector<std::uint16_t> chain_path_;  // their joint state by step, drawn as far as needed

  // Sessions that own their problem.
  std::unique_ptr<ConcurrentMdp> owned_mdp_;
  std::unique_ptr<ConcurrentAllocator> owned_allocator_;
  AllocatorMaker make_allocator_;
  std::uint64_t changes_ = 0;           // skeleton changes so far: the allocator's seed stream
  bool more_expected_ = false;          // expect_more_skeletons()
  std::vector<Steps> execution_steps_;  // per action, once refined (-1 before)

  // Live sessions only.
  LiveLedger live_;
  std::vector<double> execution_seconds_;  // per action, once refined
  double robot_free_ = 0;                  // when the current execution ends, elapsed seconds
  double finish_seconds_ = -1;
};

}  // namespace ontime
