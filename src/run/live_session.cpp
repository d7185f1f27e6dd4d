// The live half of Session (include/ontime/run/session.hpp): a session on a Clock, charged in
// seconds. The ledger: every decision's (the allocator's, or the caller's: decide()), planner
// call's, observation's and outside time, on a timeline of one entry per step and in totals; CT is
// ceil(elapsed / step_seconds), an unsuccessful call that overran adds the whole slices it took to
// PT, and success needs the completed skeleton's execution seconds to fit in the seconds left (a
// tolerance of 1e-9 slices against rounding). An anytime allocator without a budget of its own gets
// decision_share of a slice, at most the seconds left; on a modelled clock, time budgets are the
// iterations that fit in them, and the search's iterations are charged. Beside the clock, the
// model's step clock judges the same planner calls (model_status).
//
// Cost: a few clock reads and one timeline entry per step (reserved when the session starts).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/session.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {
namespace {

// Slices closer than this to a whole number count as that number: sums of step_seconds on a
// clock are not exact multiples of it.
constexpr double kSliceTolerance = 1e-9;

void check_seconds(double seconds, const char* what) {
  if (!(seconds >= 0) || std::isnan(seconds)) {
    throw UsageError(std::string(what) + " must be a time >= 0 seconds (got " + std::to_string(seconds) + ")");
  }
}

}  // namespace

void Session::start_live(const Clock& clock, LiveOptions options) {
  if (!(options.decision_share > 0 && options.decision_share <= 1e6)) {
    throw UsageError("decision_share must be in (0, 1e6] slices (got " + std::to_string(options.decision_share) + ")");
  }
  clock_ = &clock;
  live_ = options;
  // Execution seconds per action: the plan's seconds at success (owning sessions have them already).
  action_execution_steps_.resize(static_cast<std::size_t>(mdp_->problem().action_count()), -1);
  action_execution_seconds_.resize(static_cast<std::size_t>(mdp_->problem().action_count()), -1.0);
  step_seconds_ = mdp_->problem().step_seconds();
  model_state_ = state_;
  timeline_.reserve(static_cast<std::size_t>(mdp_->deadline()));
  started_ = clock_->now();
  last_report_ = started_;
}

std::uint64_t Session::search_iterations() const {
  Statistics statistics;
  allocator_->collect_statistics(statistics);
  return static_cast<std::uint64_t>(statistics.find(kIterationsCounter).value_or(0.0));
}

double Session::elapsed_seconds() const {
  if (clock_ == nullptr) throw std::logic_error("elapsed_seconds() needs a live session (one with a clock)");
  if (ended_at_ >= 0) return ended_at_;
  return clock_->now() - started_ + charged_outside_;
}

LiveTotals Session::totals() const {
  LiveTotals totals = totals_;
  totals.elapsed = elapsed_seconds();
  return totals;
}

Steps Session::steps_at(double seconds) const noexcept {
  const double slices = std::ceil(seconds / step_seconds_ - kSliceTolerance);
  return slices <= 0 ? 0 : slices >= mdp_->deadline() ? mdp_->deadline() : static_cast<Steps>(slices);
}

void Session::charge_outside(double seconds) {
  if (clock_ == nullptr) throw std::logic_error("charge_outside() needs a live session (one with a clock)");
  check_seconds(seconds, "outside time");
  if (std::isinf(seconds)) throw UsageError("outside time must be finite");
  charged_outside_ += seconds;
  totals_.outside += seconds;
}

void Session::end_if_out_of_time() {
  const double elapsed = elapsed_seconds();
  state_.time = static_cast<std::uint16_t>(std::max<Steps>(state_.time, steps_at(elapsed)));
  if (simulated_chains_) state_.chains = simulated_chains_at(state_.time);
  if (state_.time >= mdp_->deadline() || out_of_skeletons()) {
    status_ = Status::failure;
    ended_at_ = elapsed;
  }
}

Decision Session::choose_live(const DecisionBudget& budget) {
  const double begin = clock_->now();
  const Steps steps_before = state_.time;
  end_if_out_of_time();
  if (status_ != Status::running) return Decision{};
  DecisionBudget own_budget;
  const ThinkingModel* model = clock_->thinking_model();
  if (!budget.is_set()) {
    const double left = deadline_seconds() - elapsed_seconds();
    const double seconds = std::max(1e-9, std::min(live_.decision_share * step_seconds_, left));
    own_budget = model != nullptr ? DecisionBudget::iterations(model->iterations_within(seconds))
                                  : DecisionBudget::seconds(seconds);
  } else if (model != nullptr && budget.max_seconds()) {
    // On a modelled clock a time budget is the iterations that fit in it: real time would make
    // the search, and so the report, depend on the machine.
    const std::uint64_t fit = model->iterations_within(*budget.max_seconds());
    own_budget = DecisionBudget::iterations(budget.max_iterations() ? std::min(*budget.max_iterations(), fit) : fit);
  }
  const std::uint64_t searched_before = model != nullptr ? search_iterations() : 0;
  const int choice = allocator_->choose(state_, own_budget.is_set() ? own_budget : budget);
  if (model != nullptr) clock_->charge_thinking(search_iterations() - searched_before);
  if (choice < 0 || choice >= mdp_->skeleton_count()) {
    throw UsageError("allocator '" + std::string(allocator_->name()) + "' chose skeleton " + std::to_string(choice) +
                     ", outside [0, " + std::to_string(mdp_->skeleton_count()) + ")");
  }
  return record_live_decision(choice, begin, steps_before);
}

Decision Session::decide_live(int skeleton) {
  const double begin = clock_->now();
  const Steps steps_before = state_.time;
  end_if_out_of_time();
  if (status_ != Status::running) return Decision{};
  return record_live_decision(skeleton, begin, steps_before);
}

Decision Session::record_live_decision(int choice, double begin, Steps steps_before) {
  decided_at_ = clock_->now();
  pending_ = choice;
  LiveStep step;
  step.skeleton = choice;
  step.action = mdp_->next_action(state_, choice);
  pending_action_ = step.action;
  step.start = begin - started_ + charged_outside_;
  step.outside_seconds = begin - last_report_;
  step.decision_seconds = decided_at_ - begin;
  // Steps the clock already moved on while the caller was away are counted with this step.
  step.steps_charged = state_.time - steps_before;
  totals_.outside += step.outside_seconds;
  totals_.decision += step.decision_seconds;
  timeline_.push_back(step);
  return Decision{choice, step.action};
}

Status Session::report_refined_seconds(double execution_seconds) {
  return report(Observation::found(execution_steps(execution_seconds)), execution_seconds);
}

Status Session::report_refined_seconds(double execution_seconds, std::uint16_t chains) {
  return report(Observation::found(execution_steps(execution_seconds)).with_chains(chains), execution_seconds);
}

Steps Session::execution_steps(double execution_seconds) const {
  check_seconds(execution_seconds, "execution time");
  const double slices = std::ceil(execution_seconds / step_seconds() - kSliceTolerance);
  return std::isinf(execution_seconds) || slices >= static_cast<double>(kNever)
             ? kNever
             : static_cast<Steps>(std::max(0.0, slices));
}

Status Session::report_live(int choice, int action, const Observation& observation, double execution_seconds) {
  if (model_status_ == Status::running) {
    model_status_ = mdp_->apply(model_state_, choice, observation);
    if (model_status_ == Status::failure && more_expected_ && model_state_.time < mdp_->deadline()) {
      model_status_ = Status::running;
    }
  }
  const double reported = clock_->now();
  double planning = reported - decided_at_;
  if (action < 0 && planning < step_seconds_) {
    // An idle step (a skeleton with nothing left to refine) holds its whole slice, as in the
    // model; otherwise a session whose allocator idles would never see time pass.
    charged_outside_ += step_seconds_ - planning;
    planning = step_seconds_;
  }
  const double elapsed = reported - started_ + charged_outside_;
  // The model counted one step; the clock may say more (an overrun) or less (an early answer).
  const auto effort = static_cast<Steps>(std::max(1.0, std::floor(planning / step_seconds_ + kSliceTolerance)));
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
  state_.time = static_cast<std::uint16_t>(std::max<Steps>(before_.time, steps_at(elapsed)));
  if (simulated_chains_) state_.chains = simulated_chains_at(state_.time);  // (carried out in a world)

  LiveStep& step = timeline_.back();
  step.planning_seconds = planning;
  step.overrun_seconds = std::max(0.0, planning - step_seconds_);
  step.steps_charged += state_.time - before_.time;
  step.refined = observation.refined && action >= 0;
  totals_.planning += planning;
  totals_.overrun += step.overrun_seconds;

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
      if (elapsed + total <= deadline_seconds() + kSliceTolerance * step_seconds_) {
        solution_ = member;
        status_ = Status::success;
        ended_at_ = elapsed;
        finish_seconds_ = elapsed + total;
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
    ended_at_ = elapsed;
  }
  if (allocator_ != nullptr) allocator_->observe(before_, choice, state_, status_);
  // What the allocator did with the observation (a search moving its tree) is its thinking too.
  last_report_ = clock_->now();
  const double observing = last_report_ - reported;
  timeline_.back().observe_seconds = observing;
  totals_.decision += observing;
  return status_;
}

}  // namespace ontime
