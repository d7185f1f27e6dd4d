#include "ontime/run/session.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>

#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
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

Session::Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed)
    : mdp_(&mdp), allocator_(&allocator), state_(mdp.start()), before_(state_), seed_(seed) {
  allocator_->begin_episode(seed);
}

Session::Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed, const Clock& clock, LiveOptions options)
    : Session(mdp, allocator, seed) {
  start_live(clock, options);
}

Session::Session(Problem problem, AllocatorMaker make_allocator, std::uint64_t seed, const Clock* clock,
                 LiveOptions options)
    : mdp_(nullptr),
      allocator_(nullptr),
      owned_problem_(std::make_unique<Problem>(std::move(problem))),
      owned_mdp_(std::make_unique<Mdp>(*owned_problem_)),
      make_allocator_(std::move(make_allocator)),
      seed_(seed) {
  if (!make_allocator_) throw UsageError("a session that owns its problem needs a function making its allocator");
  owned_allocator_ = make_allocator_(*owned_mdp_);
  if (!owned_allocator_) throw UsageError("the allocator maker returned no allocator");
  mdp_ = owned_mdp_.get();
  allocator_ = owned_allocator_.get();
  state_ = mdp_->start();
  before_ = state_;
  action_execution_steps_.assign(static_cast<std::size_t>(owned_problem_->action_count()), -1);
  action_execution_seconds_.assign(static_cast<std::size_t>(owned_problem_->action_count()), -1.0);
  allocator_->begin_episode(seed);
  if (clock != nullptr) start_live(*clock, options);
}

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
  return static_cast<std::uint64_t>(statistics.find("iterations").value_or(0.0));
}

double Session::step_seconds() const noexcept { return mdp_->problem().step_seconds(); }
double Session::deadline_seconds() const noexcept { return mdp_->deadline() * step_seconds(); }

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
  if (state_.time >= mdp_->deadline() || out_of_skeletons()) {
    status_ = Status::failure;
    ended_at_ = elapsed;
  }
}

bool Session::out_of_skeletons() const { return !more_expected_ && !mdp_->any_can_succeed(state_); }

void Session::expect_more_skeletons(bool expected) {
  if (owned_problem_ == nullptr) {
    throw std::logic_error(
        "expect_more_skeletons needs a session that owns its problem (made with an allocator maker)");
  }
  more_expected_ = expected;
  if (clock_ != nullptr && model_status_ == Status::running && !expected && !mdp_->any_can_succeed(model_state_)) {
    model_status_ = Status::failure;
  }
  if (status_ == Status::running && pending_ < 0 && out_of_skeletons()) {
    status_ = Status::failure;
    if (clock_ != nullptr) ended_at_ = elapsed_seconds();
  }
}

Decision Session::choose() { return choose(DecisionBudget{}); }

Decision Session::choose(const DecisionBudget& budget) {
  if (status_ != Status::running) throw std::logic_error("the session is over; nothing more to choose");
  if (pending_ >= 0) throw std::logic_error("the last decision has not been reported yet");
  if (clock_ == nullptr) {
    const int choice = allocator_->choose(state_, budget);
    if (choice < 0 || choice >= mdp_->skeleton_count()) {
      throw UsageError("allocator '" + std::string(allocator_->name()) + "' chose skeleton " + std::to_string(choice) +
                       ", outside [0, " + std::to_string(mdp_->skeleton_count()) + ")");
    }
    pending_ = choice;
    return Decision{choice, mdp_->next_action(state_, choice)};
  }

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
  decided_at_ = clock_->now();
  pending_ = choice;
  LiveStep step;
  step.skeleton = choice;
  step.action = mdp_->next_action(state_, choice);
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

Status Session::report_not_yet() { return report(Observation::not_yet()); }

Status Session::report_refined(Steps execution_steps) { return report(Observation::found(execution_steps)); }

Status Session::report(const Observation& observation) {
  if (clock_ == nullptr || !observation.refined) {
    return report(observation, std::numeric_limits<double>::quiet_NaN());
  }
  if (observation.execution < 0) return report(observation, -1.0);  // rejected below with the steps
  const double seconds =
      observation.execution == kNever ? std::numeric_limits<double>::infinity() : observation.execution * step_seconds_;
  return report(observation, seconds);
}

Status Session::report_refined_seconds(double execution_seconds) {
  check_seconds(execution_seconds, "execution time");
  const double slices = std::ceil(execution_seconds / step_seconds() - kSliceTolerance);
  const Steps steps = std::isinf(execution_seconds) || slices >= static_cast<double>(kNever)
                          ? kNever
                          : static_cast<Steps>(std::max(0.0, slices));
  return report(Observation::found(steps), execution_seconds);
}

Status Session::report(const Observation& observation, double execution_seconds) {
  if (pending_ < 0) throw std::logic_error("report without a decision: call choose() first");
  const int choice = pending_;
  before_ = state_;
  const Status model_status = mdp_->apply(state_, choice, observation);
  pending_ = -1;
  const int action = mdp_->next_action(before_, choice);
  // Only live and owning sessions keep what each action revealed; a plain session (an episode of
  // a Monte Carlo run) does no work for it.
  if (action >= 0 && observation.refined && !action_execution_steps_.empty()) {
    const auto slot = static_cast<std::size_t>(action);
    action_execution_steps_[slot] =
        observation.execution == kNever ? mdp_->deadline() + 1 : std::min(observation.execution, mdp_->deadline() + 1);
    action_execution_seconds_[slot] = !std::isnan(execution_seconds)    ? execution_seconds
                                      : observation.execution == kNever ? std::numeric_limits<double>::infinity()
                                                                        : observation.execution * step_seconds();
  }
  if (clock_ == nullptr) {
    status_ = model_status;
    // Skeletons still to come keep a session going that its present ones cannot save.
    if (status_ == Status::failure && more_expected_ && state_.time < mdp_->deadline()) status_ = Status::running;
    if (status_ == Status::success) solution_ = mdp_->completed_skeleton(state_, choice);
    allocator_->observe(before_, choice, state_, status_);
    return status_;
  }

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
  if (action >= 0 && !observation.refined && effort > 1) {
    for (const int member : mdp_->problem().members(action)) {
      std::uint16_t& spent = state_.spent[static_cast<std::size_t>(member)];
      spent = static_cast<std::uint16_t>(std::min<Steps>(spent + effort - 1, mdp_->deadline() + 1));
    }
  }
  state_.time = static_cast<std::uint16_t>(std::max<Steps>(before_.time, steps_at(elapsed)));

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
      // The plan to execute: every action of the completed skeleton, in seconds.
      double total = 0;
      for (const int part : problem.skeleton(member))
        total += action_execution_seconds_[static_cast<std::size_t>(part)];
      if (elapsed + total <= deadline_seconds() + kSliceTolerance * step_seconds_) {
        solution_ = member;
        status_ = Status::success;
        ended_at_ = elapsed;
      }
      break;
    }
  }
  if (status_ == Status::running && (state_.time >= mdp_->deadline() || out_of_skeletons())) {
    status_ = Status::failure;
    ended_at_ = elapsed;
  }
  allocator_->observe(before_, choice, state_, status_);
  // What the allocator did with the observation (a search moving its tree) is its thinking too.
  last_report_ = clock_->now();
  const double observing = last_report_ - reported;
  timeline_.back().observe_seconds = observing;
  totals_.decision += observing;
  return status_;
}

State Session::carried_over(const State& old, const Problem& next) const {
  // Effort spent on the actions in progress, read off the old skeletons sharing them.
  std::vector<std::uint16_t> spent(static_cast<std::size_t>(next.action_count()), 0);
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    const int action = mdp_->next_action(old, k);
    if (action >= 0) spent[static_cast<std::size_t>(action)] = old.spent[static_cast<std::size_t>(k)];
  }
  const std::int64_t saturated = std::int64_t{next.deadline()} + 1;
  State out(static_cast<std::size_t>(next.skeleton_count()));
  out.time = old.time;
  for (int k = 0; k < next.skeleton_count(); ++k) {
    const std::span<const int> path = next.skeleton(k);
    std::size_t refined = 0;
    std::int64_t execution = 0;
    while (refined < path.size()) {
      const auto action = static_cast<std::size_t>(path[refined]);
      if (action >= action_execution_steps_.size() || action_execution_steps_[action] < 0) break;
      execution = std::min(saturated, execution + action_execution_steps_[action]);
      ++refined;
    }
    const auto slot = static_cast<std::size_t>(k);
    out.refined[slot] = static_cast<std::uint8_t>(refined);
    out.execution[slot] = static_cast<std::uint16_t>(execution);
    out.spent[slot] = refined < path.size() ? spent[static_cast<std::size_t>(path[refined])] : std::uint16_t{0};
  }
  return out;
}

void Session::change_skeletons(std::vector<Action> actions, std::vector<std::vector<int>> skeletons) {
  const Problem& current = mdp_->problem();
  // Everything that can fail comes first, so that a failure leaves the session as it was.
  auto problem = std::make_unique<Problem>(current.name(), current.deadline(), current.step_seconds(),
                                           std::move(actions), std::move(skeletons), current.description());
  auto mdp = std::make_unique<Mdp>(*problem);
  std::unique_ptr<Allocator> allocator = make_allocator_(*mdp);
  if (!allocator) throw UsageError("the allocator maker returned no allocator");
  State state = carried_over(state_, *problem);
  State model = clock_ != nullptr ? carried_over(model_state_, *problem) : State{};

  owned_problem_ = std::move(problem);
  owned_mdp_ = std::move(mdp);
  owned_allocator_ = std::move(allocator);
  mdp_ = owned_mdp_.get();
  allocator_ = owned_allocator_.get();
  state_ = std::move(state);
  before_ = state_;
  action_execution_steps_.resize(static_cast<std::size_t>(owned_problem_->action_count()), -1);
  action_execution_seconds_.resize(static_cast<std::size_t>(owned_problem_->action_count()), -1.0);
  allocator_->begin_episode(stream_seed(seed_, ++changes_));
  if (clock_ != nullptr) {
    model_state_ = std::move(model);
    if (model_status_ == Status::running && !more_expected_ && !mdp_->any_can_succeed(model_state_)) {
      model_status_ = Status::failure;
    }
  }
  if (out_of_skeletons()) {
    status_ = Status::failure;
    if (clock_ != nullptr) ended_at_ = elapsed_seconds();
  }
}

namespace {

void check_changeable(bool owns_problem, int pending, Status status, const char* what) {
  if (!owns_problem) {
    throw std::logic_error(std::string(what) + " needs a session that owns its problem (made with an allocator maker)");
  }
  if (pending >= 0) throw std::logic_error(std::string(what) + " while a decision awaits its report");
  if (status != Status::running) throw std::logic_error(std::string(what) + " after the session ended");
}

}  // namespace

int Session::add_skeleton(const std::vector<std::string>& action_ids, std::vector<Action> new_actions) {
  check_changeable(owned_problem_ != nullptr, pending_, status_, "add_skeleton");
  const Problem& current = mdp_->problem();
  std::vector<Action> actions(current.actions().begin(), current.actions().end());
  const auto known = static_cast<int>(actions.size());
  for (Action& action : new_actions) actions.push_back(std::move(action));
  std::vector<int> path;
  for (const std::string& id : action_ids) {
    int index = current.find_action(id);
    for (int a = known; index < 0 && a < static_cast<int>(actions.size()); ++a) {
      if (actions[static_cast<std::size_t>(a)].id == id) index = a;
    }
    if (index < 0) {
      throw UsageError("add_skeleton: action '" + id + "' is neither known nor among the new actions");
    }
    path.push_back(index);
  }
  std::vector<std::vector<int>> skeletons;
  skeletons.reserve(static_cast<std::size_t>(current.skeleton_count()) + 1);
  for (int k = 0; k < current.skeleton_count(); ++k)
    skeletons.emplace_back(current.skeleton(k).begin(), current.skeleton(k).end());
  skeletons.push_back(std::move(path));
  const int added = current.skeleton_count();
  change_skeletons(std::move(actions), std::move(skeletons));
  return added;
}

void Session::retire_skeleton(int k) {
  check_changeable(owned_problem_ != nullptr, pending_, status_, "retire_skeleton");
  const Problem& current = mdp_->problem();
  if (k < 0 || k >= current.skeleton_count()) {
    throw UsageError("retire_skeleton: skeleton " + std::to_string(k) + " out of range [0, " +
                     std::to_string(current.skeleton_count()) + ")");
  }
  if (current.skeleton_count() == 1) {
    status_ = Status::failure;  // nothing left to refine
    if (clock_ != nullptr) ended_at_ = elapsed_seconds();
    return;
  }
  std::vector<std::vector<int>> skeletons;
  for (int other = 0; other < current.skeleton_count(); ++other) {
    if (other != k) skeletons.emplace_back(current.skeleton(other).begin(), current.skeleton(other).end());
  }
  change_skeletons(std::vector<Action>(current.actions().begin(), current.actions().end()), std::move(skeletons));
}

}  // namespace ontime
