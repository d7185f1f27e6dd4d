// The live half of Session (include/ontime/run/session.hpp): a session on a Clock, charged in
// seconds. The ledger (live_ledger.hpp, shared with the live ConcurrentSession): every decision's (the allocator's, or
// the caller's: decide()), planner call's, observation's and outside time, on a timeline of one entry per step and in
// totals; CT is ceil(elapsed / step_seconds), an unsuccessful call that overran adds the whole slices it took to PT,
// and success needs the completed skeleton's execution seconds to fit in the seconds left (a tolerance of 1e-9 slices
// against rounding). An anytime allocator without a budget of its own gets decision_share of a slice, at most the
// seconds left; on a modelled clock, time budgets are the iterations that fit in them, and the search's iterations are
// charged. Beside the clock, the model's step clock judges the same planner calls (model_status).
//
// Cost: a few clock reads and one timeline entry per step (reserved when the session starts).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "ontime/run/session.hpp"
#include "ontime/util/error.hpp"

namespace ontime {

void Session::start_live(const Clock& clock, LiveOptions options) {
  live_.start(clock, options, mdp_->problem().step_seconds(), mdp_->deadline());
  // Execution seconds per action: the plan's seconds at success (owning sessions have them already).
  action_execution_steps_.resize(static_cast<std::size_t>(mdp_->problem().action_count()), -1);
  action_execution_seconds_.resize(static_cast<std::size_t>(mdp_->problem().action_count()), -1.0);
  model_state_ = state_;
}

double Session::elapsed_seconds() const {
  if (!live_.is_live()) throw std::logic_error("elapsed_seconds() needs a live session (one with a clock)");
  return live_.elapsed();
}

LiveTotals Session::totals() const { return live_.totals(); }

void Session::charge_outside(double seconds) {
  if (!live_.is_live()) throw std::logic_error("charge_outside() needs a live session (one with a clock)");
  live_.charge_outside(seconds);
}

void Session::end_if_out_of_time() {
  const double elapsed = elapsed_seconds();
  state_.time = static_cast<std::uint16_t>(std::max<Steps>(state_.time, live_.steps_at(elapsed)));
  if (simulated_chains_) state_.chains = simulated_chains_at(state_.time);
  if (state_.time >= mdp_->deadline() || out_of_skeletons()) {
    status_ = Status::failure;
    live_.end_at(elapsed);
  }
}

Decision Session::choose_live(const DecisionBudget& budget) {
  const double begin = live_.now();
  const Steps steps_before = state_.time;
  end_if_out_of_time();
  if (status_ != Status::running) return Decision{};
  const DecisionBudget own_budget = live_.budget(budget);
  const bool modelled = live_.clock().thinking_model() != nullptr;
  const std::uint64_t searched_before = modelled ? search_iterations_of(*allocator_) : 0;
  const int choice = allocator_->choose(state_, own_budget);
  if (modelled) live_.charge_thinking(search_iterations_of(*allocator_) - searched_before);
  if (choice < 0 || choice >= mdp_->skeleton_count()) {
    throw UsageError("allocator '" + std::string(allocator_->name()) + "' chose skeleton " + std::to_string(choice) +
                     ", outside [0, " + std::to_string(mdp_->skeleton_count()) + ")");
  }
  return record_live_decision(choice, begin, steps_before);
}

Decision Session::decide_live(int skeleton) {
  const double begin = live_.now();
  const Steps steps_before = state_.time;
  end_if_out_of_time();
  if (status_ != Status::running) return Decision{};
  return record_live_decision(skeleton, begin, steps_before);
}

Decision Session::record_live_decision(int choice, double begin, Steps steps_before) {
  pending_ = choice;
  pending_action_ = mdp_->next_action(state_, choice);
  live_.record_decision(choice, pending_action_, begin, state_.time - steps_before);
  return Decision{choice, pending_action_};
}

void Session::record_plan_execution(int skeleton, double elapsed) {
  double at = elapsed;
  for (const int part : mdp_->problem().skeleton(skeleton)) {
    const double seconds = std::max(0.0, action_execution_seconds_[static_cast<std::size_t>(part)]);
    live_.record_execution(part, at, at + seconds);
    at += seconds;
  }
}

Status Session::report_refined_seconds(double execution_seconds) {
  return report(Observation::found(live_.whole_steps(execution_seconds)), execution_seconds);
}

Status Session::report_refined_seconds(double execution_seconds, std::uint16_t chains) {
  return report(Observation::found(live_.whole_steps(execution_seconds)).with_chains(chains), execution_seconds);
}

Status Session::report_live(int choice, int action, const Observation& observation, double execution_seconds) {
  if (model_status_ == Status::running) {
    model_status_ = mdp_->apply(model_state_, choice, observation);
    if (model_status_ == Status::failure && more_expected_ && model_state_.time < mdp_->deadline()) {
      model_status_ = Status::running;
    }
  }
  const double reported = live_.now();
  const double planning = live_.record_call(reported, action < 0);
  const double elapsed = live_.elapsed_at(reported);
  // The model counted one step; the clock may say more (an overrun) or less (an early answer).
  const Steps effort = live_.effort_of(planning);
  if (action >= 0) {
    ActionAttempt& attempt = attempts_[static_cast<std::size_t>(action)];
    attempt.effort = std::min<Steps>(attempt.effort + effort, Distribution::kMaxStep);
    attempt.found = observation.refined;
    if (observation.is_backtrack()) end_attempts_below(observation.culprit, action);
  }
  if (action >= 0 && !observation.refined && !observation.is_backtrack() && effort > 1) {
    for (const int member : mdp_->problem().members(action)) {
      std::uint16_t& spent = state_.spent[static_cast<std::size_t>(member)];
      spent = static_cast<std::uint16_t>(std::min<Steps>(spent + effort - 1, mdp_->deadline() + 1));
    }
  }
  state_.time = static_cast<std::uint16_t>(std::max<Steps>(before_.time, live_.steps_at(elapsed)));
  if (simulated_chains_) state_.chains = simulated_chains_at(state_.time);  // (carried out in a world)

  LiveStep& step = live_.last_step();
  step.steps_charged += state_.time - before_.time;
  step.refined = observation.refined && action >= 0;

  status_ = Status::running;
  if (step.refined) {
    step.execution_seconds = execution_seconds;
    const Problem& problem = mdp_->problem();
    for (const int member : problem.members(action)) {
      if (!problem.completes_a_skeleton(action) || problem.skeleton_length(member) != problem.position(action) + 1) {
        continue;
      }
      // The plan to execute: every action of the completed skeleton, in seconds. With chains or
      // expiry (SPEC §9) its static part: an execution that depends on a chain is drawn when it
      // starts, and the plan is worth its expected reward from the state now (chains as reported).
      double total = 0;
      for (const int part : problem.skeleton(member)) {
        if (mdp_->is_timed() && problem.execution_chain(part) >= 0) continue;
        total += action_execution_seconds_[static_cast<std::size_t>(part)];
      }
      if (live_.fits(elapsed + total)) {
        solution_ = member;
        status_ = Status::success;
        live_.end_at(elapsed);
        finish_seconds_ = elapsed + total;
        record_plan_execution(member, elapsed);
        if (mdp_->is_timed()) {
          const auto slot = static_cast<std::size_t>(member);
          timed_reward_ =
              mdp_->execution_value(member, state_.time, state_.chains, state_.restore.data(), state_.execution[slot]);
        }
      }
      break;
    }
  }
  if (status_ == Status::running && (state_.time >= mdp_->deadline() || out_of_skeletons())) {
    status_ = Status::failure;
    live_.end_at(elapsed);
  }
  if (allocator_ != nullptr) allocator_->observe(before_, choice, state_, status_);
  // What the allocator did with the observation (a search moving its tree) is its thinking too.
  live_.record_observing(reported);
  return status_;
}

}  // namespace ontime
