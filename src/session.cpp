#include "ontime/session.hpp"

#include <stdexcept>
#include <string>

#include "ontime/error.hpp"

namespace ontime {

Session::Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed)
    : mdp_(&mdp), allocator_(&allocator), state_(mdp.start()) {
  allocator_->begin_episode(seed);
}

Decision Session::choose() { return choose(DecisionBudget{}); }

Decision Session::choose(const DecisionBudget& budget) {
  if (status_ != Status::running) throw std::logic_error("the session is over; nothing more to choose");
  if (pending_ >= 0) throw std::logic_error("the last decision has not been reported yet");
  const int choice = allocator_->choose(state_, budget);
  if (choice < 0 || choice >= mdp_->skeleton_count()) {
    throw UsageError("allocator '" + std::string(allocator_->name()) + "' chose skeleton " + std::to_string(choice) +
                     ", outside [0, " + std::to_string(mdp_->skeleton_count()) + ")");
  }
  pending_ = choice;
  return Decision{choice, mdp_->next_action(state_, choice)};
}

Status Session::report_not_yet() { return report(Observation::not_yet()); }

Status Session::report_refined(Steps execution_steps) { return report(Observation::found(execution_steps)); }

Status Session::report(const Observation& observation) {
  if (pending_ < 0) throw std::logic_error("report without a decision: call choose() first");
  const int choice = pending_;
  const State before = state_;
  status_ = mdp_->apply(state_, choice, observation);
  pending_ = -1;
  if (status_ == Status::success) solution_ = mdp_->completed_skeleton(state_, choice);
  allocator_->observe(before, choice, state_, status_);
  return status_;
}

}  // namespace ontime
