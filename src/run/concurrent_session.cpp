#include "ontime/run/concurrent_session.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, std::uint64_t seed)
    : ConcurrentSession(mdp, &allocator) {
  allocator.begin_episode(seed);
}

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp) : ConcurrentSession(mdp, nullptr) {}

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator* allocator)
    : mdp_(&mdp),
      allocator_(allocator),
      state_(mdp.start()),
      before_(state_),
      attempts_(static_cast<std::size_t>(mdp.problem().action_count())) {
  if (mdp.is_timed()) {
    throw UsageError(mdp.problem().name() +
                     ": episodes with exogenous chains or expiry (SPEC §9) acting while planning (SPEC §10) are not "
                     "there yet: the session would simulate the chains and draw executions when they start; solve "
                     "the instance exactly instead (ontime solve --act concurrent)");
  }
  end_if_stuck();
}

ConcurrentDecision ConcurrentSession::choose() {
  if (allocator_ == nullptr) throw std::logic_error("this session has no allocator: the caller decides (decide())");
  if (status_ != Status::running) throw std::logic_error("the session is over");
  if (pending_) throw std::logic_error("a step awaits its report");
  return carry_out_move(allocator_->choose(state_));
}

ConcurrentDecision ConcurrentSession::decide(const ConcurrentMdp::Move& move) {
  if (allocator_ != nullptr) throw std::logic_error("this session's allocator decides (choose())");
  if (status_ != Status::running) throw std::logic_error("the session is over");
  if (pending_) throw std::logic_error("a step awaits its report");
  return carry_out_move(move);
}

ConcurrentDecision ConcurrentSession::carry_out_move(const ConcurrentMdp::Move& move) {
  const Problem& problem = mdp_->problem();
  if (move.is_start()) {
    const Steps finish = ConcurrentMdp::time(state_) + mdp_->execution(state_, move.start);
    ConcurrentMdp::StartOutcome outcome = mdp_->start_action(state_, move.start);  // checks the start
    started_.push_back(move.start);
    if (outcome.ends) {
      const int position = problem.position(move.start);
      for (const int k : problem.members(move.start)) {
        if (ConcurrentMdp::is_live(state_, k) && problem.skeleton_length(k) == position + 1) {
          solution_ = k;
          break;
        }
      }
      finish_ = finish;
      const bool in_time = finish <= mdp_->deadline();
      status_ = in_time ? Status::success : Status::failure;
      reward_ = in_time ? outcome.reward : 0.0;
      if (!in_time) solution_ = -1;
    } else {
      state_ = std::move(outcome.next);
      end_if_stuck();
    }
    return {.start = move.start};
  }
  const int choice = move.refine;
  if (choice != ConcurrentMdp::kWait &&
      (choice < 0 || choice >= mdp_->skeleton_count() || !ConcurrentMdp::is_live(state_, choice) ||
       ConcurrentMdp::refined(state_, choice) >= problem.skeleton_length(choice))) {
    throw UsageError("skeleton " + std::to_string(choice) +
                     " cannot be refined now: it is dropped (not through what the robot executed, or unable to "
                     "finish by the deadline) or has nothing left to refine");
  }
  if (ConcurrentMdp::time(state_) >= mdp_->deadline()) {
    // No step is left at the deadline: only a start could still have finished.
    status_ = Status::failure;
    return {.skeleton = choice};
  }
  pending_ = true;
  pending_skeleton_ = choice;
  pending_action_ =
      choice == ConcurrentMdp::kWait ? -1 : problem.action_at(choice, ConcurrentMdp::refined(state_, choice));
  return {.skeleton = choice, .action = pending_action_};
}

Status ConcurrentSession::carry_out(World& world) {
  if (!pending_) throw std::logic_error("no step awaits its report");
  if (pending_action_ < 0) return report_not_yet();
  return report(world.step(pending_action_, mdp_->spent(state_, pending_skeleton_)));
}

Status ConcurrentSession::report_not_yet() { return report(Observation::not_yet()); }

Status ConcurrentSession::report_refined(Steps execution_steps) { return report(Observation::found(execution_steps)); }

Status ConcurrentSession::report(const Observation& observation) {
  if (!pending_) throw std::logic_error("no step awaits its report");
  if (observation.refined && observation.execution < 0) {
    throw UsageError("an execution time is at least 0 steps (got " + std::to_string(observation.execution) + ")");
  }
  before_ = state_;
  state_ = mdp_->step(before_, pending_skeleton_, observation);  // checks what the step cannot reveal
  pending_ = false;
  if (pending_action_ >= 0) {
    ActionAttempt& attempt = attempts_[static_cast<std::size_t>(pending_action_)];
    ++attempt.effort;
    attempt.found = observation.refined;
  }
  if (allocator_ != nullptr) allocator_->observe(before_, pending_skeleton_, state_);
  end_if_stuck();
  return status_;
}

Status ConcurrentSession::report_execution_finished(int action) {
  if (status_ != Status::running) throw std::logic_error("the session is over");
  if (pending_) throw std::logic_error("a step awaits its report: report the execution after it");
  if (std::find(started_.begin(), started_.end(), action) == started_.end()) {
    throw UsageError("report_execution_finished: action " + std::to_string(action) +
                     " was never started: the robot reports only the executions the session started (SPEC §10)");
  }
  if (action == started_.back()) {
    state_ = mdp_->execution_finished(state_);
    end_if_stuck();
  }
  return status_;
}

void ConcurrentSession::end_if_stuck() {
  if (status_ == Status::running && !mdp_->any_live(state_)) status_ = Status::failure;
}

}  // namespace ontime
