#pragma once
// An online session: the API a caller's own motion planner drives.
//
//   ontime::Session session(mdp, allocator);
//   while (session.status() == ontime::Status::running) {
//     const auto decision = session.choose();        // which skeleton, which action
//     // ... spend one step of real planning effort on decision.action ...
//     if (found) session.report_refined(execution_steps);
//     else       session.report_not_yet();
//   }
//   if (session.status() == ontime::Status::success) execute(session.solution());
//
// The session keeps the MDP state, asks the allocator before every step, and reports
// success (with the skeleton to execute) or failure: the deadline passed, or no skeleton can
// still meet it, so that no more effort is wasted. The episode runner (episode_runner.hpp)
// drives the same API against a World.

#include <cstdint>

#include "ontime/allocator.hpp"
#include "ontime/decision_budget.hpp"
#include "ontime/mdp.hpp"

namespace ontime {

struct Decision {
  int skeleton = -1;  // the allocator's choice
  int action = -1;    // the action to refine now, or -1: the step is spent idle
};

class Session {
 public:
  // Calls allocator.begin_episode(seed). The Mdp and the allocator must outlive the session.
  Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed = 0);

  // Asks the allocator for the next step. Throws std::logic_error when the session is over
  // or a decision is still waiting for its report; UsageError when the allocator returns a
  // skeleton index out of range.
  Decision choose();
  // The same within `budget` (an anytime allocator's budget for this decision; unset: its own).
  Decision choose(const DecisionBudget& budget);

  // Reports the outcome of the step just decided. Throws std::logic_error without a
  // pending decision, and UsageError for a refinement reported on an idle step or a negative
  // execution time.
  Status report_not_yet();
  Status report_refined(Steps execution_steps);
  Status report(const Observation& observation);

  Status status() const noexcept { return status_; }
  const State& state() const noexcept { return state_; }
  const Mdp& mdp() const noexcept { return *mdp_; }
  // The skeleton to execute after success, -1 before.
  int solution() const noexcept { return solution_; }
  // Steps of effort spent so far (CT).
  Steps steps_used() const noexcept { return state_.time; }

 private:
  const Mdp* mdp_;
  Allocator* allocator_;
  State state_;
  Status status_ = Status::running;
  int pending_ = -1;
  int solution_ = -1;
};

}  // namespace ontime
