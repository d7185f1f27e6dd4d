#include "ontime/run/concurrent_session.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "run/detail/exogenous_stream.hpp"

namespace ontime {

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, std::uint64_t seed)
    : ConcurrentSession(mdp, &allocator, seed) {
  allocator.begin_episode(seed);
}

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp, std::uint64_t seed)
    : ConcurrentSession(mdp, nullptr, seed) {}

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, std::uint64_t seed,
                                     const Clock& clock, LiveOptions options)
    : ConcurrentSession(mdp, &allocator, seed) {
  live_.start(clock, options, mdp.problem().step_seconds(), mdp.deadline());
  execution_seconds_.assign(static_cast<std::size_t>(mdp.problem().action_count()), -1.0);
  allocator.begin_episode(seed);
}

ConcurrentSession::ConcurrentSession(const Problem& problem, AllocatorMaker make_allocator, std::uint64_t seed,
                                     const Clock* clock, LiveOptions options)
    : mdp_(nullptr),
      allocator_(nullptr),
      seed_(seed),
      exogenous_(detail::exogenous_stream(seed)),
      owned_mdp_(std::make_unique<ConcurrentMdp>(problem)),
      owned_allocator_(made_allocator(make_allocator, *owned_mdp_)),  // before the maker moves below
      make_allocator_(std::move(make_allocator)) {
  // The members before the owned ones point into them.
  mdp_ = owned_mdp_.get();
  allocator_ = owned_allocator_.get();
  before_ = state_ = mdp_->start();
  chain_path_.assign(1, ConcurrentMdp::chains(state_));
  const auto actions = static_cast<std::size_t>(problem.action_count());
  attempts_.assign(actions, ActionAttempt{});
  execution_steps_.assign(actions, -1);
  if (clock != nullptr) {
    live_.start(*clock, options, problem.step_seconds(), mdp_->deadline());
    execution_seconds_.assign(actions, -1.0);
  }
  if (allocator_ != nullptr) allocator_->begin_episode(seed);
  end_if_stuck();
}

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp, const Clock& clock, LiveOptions options)
    : ConcurrentSession(mdp, nullptr, 0) {
  live_.start(clock, options, mdp.problem().step_seconds(), mdp.deadline());
  execution_seconds_.assign(static_cast<std::size_t>(mdp.problem().action_count()), -1.0);
}

ConcurrentSession::ConcurrentSession(const ConcurrentMdp& mdp, ConcurrentAllocator* allocator, std::uint64_t seed)
    : mdp_(&mdp),
      allocator_(allocator),
      state_(mdp.start()),
      before_(state_),
      attempts_(static_cast<std::size_t>(mdp.problem().action_count())),
      seed_(seed),
      exogenous_(detail::exogenous_stream(seed)),
      chain_path_(1, ConcurrentMdp::chains(state_)) {
  end_if_stuck();
}

ConcurrentDecision ConcurrentSession::choose() {
  if (allocator_ == nullptr) throw std::logic_error("this session has no allocator: the caller decides (decide())");
  if (status_ != Status::running) throw std::logic_error("the session is over");
  if (pending_) throw std::logic_error("a step awaits its report");
  if (!live_.is_live()) return carry_out_move(allocator_->choose(state_));
  const double begin = live_.now();
  const Steps steps_before = ConcurrentMdp::time(state_);
  if (!catch_up()) return {};
  const bool modelled = live_.clock().thinking_model() != nullptr;
  const std::uint64_t searched_before = modelled ? search_iterations_of(*allocator_) : 0;
  const ConcurrentMdp::Move move = allocator_->choose(state_);
  if (modelled) live_.charge_thinking(search_iterations_of(*allocator_) - searched_before);
  return carry_out_move(move, begin, steps_before);
}

ConcurrentDecision ConcurrentSession::decide(const ConcurrentMdp::Move& move) {
  if (allocator_ != nullptr) throw std::logic_error("this session's allocator decides (choose())");
  if (status_ != Status::running) throw std::logic_error("the session is over");
  if (pending_) throw std::logic_error("a step awaits its report");
  if (!live_.is_live()) return carry_out_move(move);
  const double begin = live_.now();
  const Steps steps_before = ConcurrentMdp::time(state_);
  if (!catch_up()) return {};
  return carry_out_move(move, begin, steps_before);
}

ConcurrentDecision ConcurrentSession::carry_out_move(const ConcurrentMdp::Move& move, double begin,
                                                     Steps steps_before) {
  const Problem& problem = mdp_->problem();
  if (move.is_start()) {
    const ConcurrentDecision decision = start(move.start);
    if (live_.is_live()) {
      live_.record_decision(-1, -1, begin, ConcurrentMdp::time(state_) - steps_before, move.start);
    }
    return decision;
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
    live_.end();
    return {.skeleton = choice};
  }
  pending_ = true;
  pending_skeleton_ = choice;
  pending_action_ =
      choice == ConcurrentMdp::kWait ? -1 : problem.action_at(choice, ConcurrentMdp::refined(state_, choice));
  if (live_.is_live()) {
    live_.record_decision(choice, pending_action_, begin, ConcurrentMdp::time(state_) - steps_before);
  }
  return {.skeleton = choice, .action = pending_action_};
}

ConcurrentDecision ConcurrentSession::start(int action) {
  const Problem& problem = mdp_->problem();
  const bool live = live_.is_live();
  const double elapsed = live ? live_.elapsed() : 0.0;
  // An execution drawn from a chain's state when it starts (SPEC §9): the world's draw, now.
  const std::vector<int> startable = mdp_->startable(state_);
  const bool may_start = std::binary_search(startable.begin(), startable.end(), action);
  const Steps drawn = may_start ? mdp_->sample_start_execution(state_, action, exogenous_) : -1;
  const Steps steps = drawn >= 0 ? drawn : Steps{mdp_->execution(state_, action)};
  Steps finish = steps == kNever ? kNever : ConcurrentMdp::time(state_) + steps;
  ConcurrentMdp::StartOutcome outcome = mdp_->start_action(state_, action, drawn);  // checks the start
  started_.push_back(action);
  double end = 0;
  if (live) {
    // The robot begins the motion once it is free: now, or when the motion before it ends. An
    // execution drawn from a chain when it starts (SPEC §9) lasts the steps drawn, whatever was
    // reported with its motion.
    const double begins = std::max(elapsed, robot_free_);
    const double seconds = drawn < 0         ? execution_seconds_[static_cast<std::size_t>(action)]
                           : drawn == kNever ? std::numeric_limits<double>::infinity()
                                             : static_cast<double>(drawn) * live_.step_seconds();
    end = begins + seconds;
    robot_free_ = end;
    live_.record_execution(action, begins, end);
    finish = std::isinf(end) ? kNever : live_.whole_steps(end);
  }
  if (outcome.ends) {
    const int position = problem.position(action);
    for (const int k : problem.members(action)) {
      if (ConcurrentMdp::is_live(state_, k) && problem.skeleton_length(k) == position + 1) {
        solution_ = k;
        break;
      }
    }
    finish_ = finish;
    const bool in_time = live ? live_.fits(end) : finish <= mdp_->deadline();
    status_ = in_time ? Status::success : Status::failure;
    if (live) {
      finish_seconds_ = in_time ? end : -1.0;
      live_.end_at(elapsed);
      outcome.reward = solution_ >= 0 ? std::max(0.0, problem.reward(solution_).at(end / live_.step_seconds())) : 0.0;
    }
    reward_ = in_time ? outcome.reward : 0.0;
    if (!in_time) solution_ = -1;
  } else {
    state_ = std::move(outcome.next);
    if (live) {
      const Steps time = ConcurrentMdp::time(state_);
      state_ = mdp_->on_clock(state_, clock_reading(time));
    }
    end_if_stuck();
  }
  return {.start = action};
}

Steps ConcurrentSession::robot_left_at(Steps time) const {
  if (std::isinf(robot_free_)) return mdp_->deadline() + 1;
  return std::clamp<Steps>(live_.whole_steps(robot_free_) - time, 0, mdp_->deadline() + 1);
}

ConcurrentMdp::ClockReading ConcurrentSession::clock_reading(Steps time) {
  return {.time = time, .robot_left = robot_left_at(time), .extra_effort = 0, .chains = chains_at(time)};
}

std::uint16_t ConcurrentSession::chains_at(Steps time) {
  if (!mdp_->plan_first_mdp().has_chains()) return 0;
  // One draw of their joint transition per step, from the path's end: as far as `time` needs.
  while (chain_path_.size() <= static_cast<std::size_t>(time)) {
    chain_path_.push_back(mdp_->plan_first_mdp().sample_chain_step(chain_path_.back(), exogenous_));
  }
  return chain_path_[static_cast<std::size_t>(time)];
}

bool ConcurrentSession::catch_up() {
  const double elapsed = live_.elapsed();
  const Steps time = std::max<Steps>(ConcurrentMdp::time(state_), live_.steps_at(elapsed));
  state_ = mdp_->on_clock(state_, clock_reading(time));
  end_if_stuck();
  return status_ == Status::running;
}

void ConcurrentSession::require_live(const char* what) const {
  if (!live_.is_live()) throw std::logic_error(std::string(what) + " needs a live session (one with a clock)");
}

double ConcurrentSession::elapsed_seconds() const {
  require_live("elapsed_seconds()");
  return live_.elapsed();
}

void ConcurrentSession::charge_outside(double seconds) {
  require_live("charge_outside()");
  live_.charge_outside(seconds);
}

Status ConcurrentSession::carry_out(World& world) {
  if (!pending_) throw std::logic_error("no step awaits its report");
  if (pending_action_ < 0) return report_not_yet();
  return report(world.step(pending_action_, mdp_->spent(state_, pending_skeleton_)));
}

Status ConcurrentSession::report_not_yet() { return report(Observation::not_yet()); }

Status ConcurrentSession::report_refined(Steps execution_steps) { return report(Observation::found(execution_steps)); }

Status ConcurrentSession::report(const Observation& observation) {
  if (!live_.is_live() || !observation.refined || observation.execution < 0) {
    return report_with_seconds(observation, std::numeric_limits<double>::quiet_NaN());
  }
  return report_with_seconds(observation, observation.execution == kNever
                                              ? std::numeric_limits<double>::infinity()
                                              : static_cast<double>(observation.execution) * live_.step_seconds());
}

Status ConcurrentSession::report_refined_seconds(double execution_seconds) {
  require_live("report_refined_seconds");
  return report_with_seconds(Observation::found(live_.whole_steps(execution_seconds)), execution_seconds);
}

Status ConcurrentSession::report_with_seconds(const Observation& observation, double execution_seconds) {
  if (!pending_) throw std::logic_error("no step awaits its report");
  if (observation.refined && observation.execution < 0) {
    throw UsageError("an execution time is at least 0 steps (got " + std::to_string(observation.execution) + ")");
  }
  if (live_.is_live()) return report_on_clock(observation, execution_seconds);
  before_ = state_;
  // The simulated chains (SPEC §9) move one step of their joint transition, whatever the step.
  const Observation seen = observation.with_chains(chains_at(ConcurrentMdp::time(before_) + 1));
  state_ = mdp_->step(before_, pending_skeleton_, seen);  // checks what the step cannot reveal
  pending_ = false;
  if (pending_action_ >= 0) {
    ActionAttempt& attempt = attempts_[static_cast<std::size_t>(pending_action_)];
    ++attempt.effort;
    attempt.found = observation.refined;
    remember_execution(observation);
  }
  if (allocator_ != nullptr) allocator_->observe(before_, pending_skeleton_, state_);
  end_if_stuck();
  return status_;
}

Status ConcurrentSession::report_on_clock(const Observation& observation, double execution_seconds) {
  const double reported = live_.now();
  const double planning = live_.record_call(reported, pending_action_ < 0);
  const double elapsed = live_.elapsed_at(reported);
  // The model counts one step; the clock may say more (an overrun) or less (an early answer).
  const Steps effort = live_.effort_of(planning);
  const Steps time = std::max<Steps>(ConcurrentMdp::time(state_), live_.steps_at(elapsed));
  before_ = state_;
  // The simulated chains (SPEC §9) follow the clock: one step of their path per step of CT,
  // however many steps the call took.
  state_ = mdp_->step(
      before_, pending_skeleton_, observation.with_chains(chains_at(time)),
      {.time = time, .robot_left = robot_left_at(time), .extra_effort = observation.refined ? 0 : effort - 1});
  pending_ = false;
  LiveStep& step = live_.last_step();
  step.steps_charged += time - ConcurrentMdp::time(before_);
  if (pending_action_ >= 0) {
    const auto slot = static_cast<std::size_t>(pending_action_);
    ActionAttempt& attempt = attempts_[slot];
    attempt.effort = std::min<Steps>(attempt.effort + effort, Distribution::kMaxStep);
    attempt.found = observation.refined;
    remember_execution(observation);
    if (observation.refined) {
      execution_seconds_[slot] = execution_seconds;
      step.refined = true;
      step.execution_seconds = execution_seconds;
    }
  }
  if (allocator_ != nullptr) allocator_->observe(before_, pending_skeleton_, state_);
  end_if_stuck();
  live_.record_observing(reported);
  return status_;
}

namespace {

void check_reported_execution(const std::vector<int>& started, int action, const char* what) {
  if (std::find(started.begin(), started.end(), action) == started.end()) {
    throw UsageError(std::string(what) + ": action " + std::to_string(action) +
                     " was never started: the robot reports only the executions the session started (SPEC §10)");
  }
}

}  // namespace

Status ConcurrentSession::report_execution_finished(int action) {
  if (status_ != Status::running) throw std::logic_error("the session is over");
  if (pending_) throw std::logic_error("a step awaits its report: report the execution after it");
  check_reported_execution(started_, action, "report_execution_finished");
  if (action == started_.back()) {
    if (live_.is_live()) return report_execution_left(action, 0.0);
    state_ = mdp_->execution_finished(state_);
    end_if_stuck();
  }
  return status_;
}

Status ConcurrentSession::report_execution_left(int action, double seconds) {
  require_live("report_execution_left");
  if (status_ != Status::running) throw std::logic_error("the session is over");
  if (pending_) throw std::logic_error("a step awaits its report: report the execution after it");
  check_reported_execution(started_, action, "report_execution_left");
  if (action != started_.back()) {
    throw UsageError("report_execution_left: action " + std::to_string(action) +
                     " is not the one the robot executes now (SPEC §10: one execution at a time)");
  }
  if (!(seconds >= 0) || std::isinf(seconds)) {
    throw UsageError("report_execution_left: the seconds left must be finite and >= 0 (got " + std::to_string(seconds) +
                     ")");
  }
  const double elapsed = live_.elapsed();
  robot_free_ = elapsed + seconds;
  live_.move_last_execution_end(robot_free_);
  const Steps time = std::max<Steps>(ConcurrentMdp::time(state_), live_.steps_at(elapsed));
  state_ = mdp_->on_clock(state_, clock_reading(time));
  end_if_stuck();
  return status_;
}

void ConcurrentSession::remember_execution(const Observation& observation) {
  if (observation.refined && !execution_steps_.empty()) {
    execution_steps_[static_cast<std::size_t>(pending_action_)] =
        std::min<Steps>(observation.execution, mdp_->deadline() + 1);
  }
}

void ConcurrentSession::check_changeable(const char* what) const {
  if (owned_mdp_ == nullptr) {
    throw std::logic_error(std::string(what) + " needs a session that owns its problem (made from a Problem)");
  }
  if (pending_) throw std::logic_error(std::string(what) + " while a step awaits its report");
  if (status_ != Status::running) throw std::logic_error(std::string(what) + " after the session ended");
}

int ConcurrentSession::add_skeleton(const std::vector<std::string>& action_ids, std::vector<Action> new_actions) {
  check_changeable("add_skeleton");
  const int added = mdp_->skeleton_count();
  change_skeletons(with_added_skeleton(mdp_->problem(), action_ids, std::move(new_actions)));
  return added;
}

int ConcurrentSession::retire_dropped() {
  check_changeable("retire_dropped");
  const Problem& current = mdp_->problem();
  std::vector<std::vector<int>> skeletons;
  std::vector<SkeletonReward> rewards;
  for (int k = 0; k < current.skeleton_count(); ++k) {
    if (!ConcurrentMdp::is_live(state_, k)) continue;
    skeletons.emplace_back(current.skeleton(k).begin(), current.skeleton(k).end());
    rewards.push_back(current.reward(k));
  }
  const int retired = current.skeleton_count() - static_cast<int>(skeletons.size());
  if (retired == 0 || skeletons.empty()) return 0;
  change_skeletons(with_skeletons(current, std::vector<Action>(current.actions().begin(), current.actions().end()),
                                  std::move(skeletons), std::move(rewards)));
  return retired;
}

void ConcurrentSession::expect_more_skeletons(bool expected) {
  if (owned_mdp_ == nullptr) {
    throw std::logic_error("expect_more_skeletons needs a session that owns its problem (made from a Problem)");
  }
  more_expected_ = expected;
  if (!pending_) end_if_stuck();
}

void ConcurrentSession::change_skeletons(const Problem& next) {
  // Everything that can fail comes first, so that a failure leaves the session as it was.
  auto mdp = std::make_unique<ConcurrentMdp>(next);
  std::unique_ptr<ConcurrentAllocator> allocator = made_allocator(make_allocator_, *mdp);
  const auto actions = static_cast<std::size_t>(next.action_count());
  std::vector<Steps> execution = execution_steps_;
  execution.resize(actions, -1);
  std::vector<Steps> effort(actions, 0);
  for (std::size_t a = 0; a < attempts_.size() && a < actions; ++a) effort[a] = attempts_[a].effort;
  // The chains carry over in their order (the problem keeps them): the same joint state.
  ConcurrentState state =
      mdp->state_of(ConcurrentMdp::time(state_), ConcurrentMdp::robot_left(state_), ConcurrentMdp::executed(state_),
                    execution, effort, ConcurrentMdp::chains(state_));

  // Nothing below throws.
  mdp_ = mdp.get();
  allocator_ = allocator.get();
  owned_mdp_ = std::move(mdp);
  owned_allocator_ = std::move(allocator);
  before_ = state_ = std::move(state);
  execution_steps_ = std::move(execution);
  attempts_.resize(actions);
  if (live_.is_live()) execution_seconds_.resize(actions, -1.0);
  if (allocator_ != nullptr) allocator_->begin_episode(stream_seed(seed_, ++changes_));
  end_if_stuck();
}

void ConcurrentSession::end_if_stuck() {
  // Skeletons still to come keep a session going that its present ones cannot save, while a step
  // is left.
  if (more_expected_ && ConcurrentMdp::time(state_) < mdp_->deadline()) return;
  if (status_ == Status::running && !mdp_->any_live(state_)) {
    status_ = Status::failure;
    live_.end();
  }
}

}  // namespace ontime
