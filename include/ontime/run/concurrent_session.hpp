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
// finish by the deadline any more. Steps are the model's clock; a live form on the robot's clock
// is not there yet.
//
// Cost: a move copies one state (ConcurrentMdp's words); nothing else is allocated per move.

#include <cstdint>
#include <vector>

#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/world.hpp"

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
  // Calls allocator.begin_episode(seed). The Mdp and the allocator must outlive the session.
  ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, std::uint64_t seed = 0);
  // A session without an allocator: the caller decides every move (decide()).
  explicit ConcurrentSession(const ConcurrentMdp& mdp);

  // Asks the allocator for the next move and carries out a start at once. Throws
  // std::logic_error when the session is over, a step awaits its report or it has no allocator;
  // UsageError for a move the state does not allow.
  ConcurrentDecision choose();
  // The caller's move, checked as choose() checks an allocator's (std::logic_error when the session
  // has an allocator).
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
  // The robot reports that its execution of `action` ended (a real robot may finish sooner than the
  // execution time its motion was found with; on the step clock, an execution ends by itself once
  // its steps have passed). For the action executing now the robot becomes idle, so that the next
  // start may come at once; for an action started earlier, whose execution ended when the next one
  // began, nothing changes. Throws UsageError for an action the robot did not start (naming the
  // rule), std::logic_error while a step awaits its report or after the end.
  Status report_execution_finished(int action);

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

 private:
  ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator* allocator);
  ConcurrentDecision carry_out_move(const ConcurrentMdp::Move& move);
  void end_if_stuck();

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
};

}  // namespace ontime
