// Session (include/ontime/run/session.hpp): the MDP state, the allocator asked (or the caller's
// choice taken) before every step, the step carried out against a World, the end of the episode,
// and the skeletons that arrive and leave in a session that owns its problem. A live session's
// clock, seconds and timeline are in live_session.cpp: where a step differs on the clock (choosing
// within the seconds left, a report charged in seconds), the member here hands over to its live
// counterpart.

#include "ontime/run/session.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "run/detail/exogenous_stream.hpp"

namespace ontime {

Session::Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed)
    : mdp_(&mdp),
      allocator_(&allocator),
      state_(mdp.start()),
      before_(state_),
      attempts_(static_cast<std::size_t>(mdp.problem().action_count())),
      seed_(seed) {
  allocator_->begin_episode(seed);
}

Session::Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed, const Clock& clock, LiveOptions options)
    : Session(mdp, allocator, seed) {
  start_live(clock, options);
}

// before_ stays empty until a transition needs it (a live report): a caller-decided session that
// is not live never copies its state.
Session::Session(const Mdp& mdp, std::uint64_t seed)
    : mdp_(&mdp),
      allocator_(nullptr),
      state_(mdp.start()),
      attempts_(static_cast<std::size_t>(mdp.problem().action_count())),
      seed_(seed) {}

Session::Session(const Mdp& mdp, const Clock& clock, LiveOptions options) : Session(mdp) { start_live(clock, options); }

Session::Session(Problem problem, AllocatorMaker make_allocator, std::uint64_t seed, const Clock* clock,
                 LiveOptions options)
    : mdp_(nullptr),
      allocator_(nullptr),
      owned_problem_(std::make_unique<Problem>(std::move(problem))),
      owned_mdp_(std::make_unique<Mdp>(*owned_problem_)),
      make_allocator_(std::move(make_allocator)),
      seed_(seed) {
  owned_allocator_ = made_allocator(make_allocator_, *owned_mdp_);
  mdp_ = owned_mdp_.get();
  allocator_ = owned_allocator_.get();
  before_ = state_ = mdp_->start();
  attempts_.assign(static_cast<std::size_t>(owned_problem_->action_count()), ActionAttempt{});
  action_execution_steps_.assign(static_cast<std::size_t>(owned_problem_->action_count()), -1);
  action_execution_seconds_.assign(static_cast<std::size_t>(owned_problem_->action_count()), -1.0);
  if (allocator_ != nullptr) allocator_->begin_episode(seed);
  if (clock != nullptr) start_live(*clock, options);
}

double Session::step_seconds() const noexcept { return mdp_->problem().step_seconds(); }
double Session::deadline_seconds() const noexcept { return mdp_->deadline() * step_seconds(); }

bool Session::out_of_skeletons() const { return !more_expected_ && !mdp_->any_can_succeed(state_); }

void Session::expect_more_skeletons(bool expected) {
  if (owned_problem_ == nullptr) {
    throw std::logic_error("expect_more_skeletons needs a session that owns its problem (made from a Problem)");
  }
  more_expected_ = expected;
  if (live_.is_live() && model_status_ == Status::running && !expected && !mdp_->any_can_succeed(model_state_)) {
    model_status_ = Status::failure;
  }
  if (status_ == Status::running && pending_ < 0 && out_of_skeletons()) {
    status_ = Status::failure;
    live_.end();
  }
}

Decision Session::choose() { return choose(DecisionBudget{}); }

namespace {

// What choose() and decide() check before a decision.
void check_decidable(Status status, int pending) {
  if (status != Status::running) throw std::logic_error("the session is over; nothing more to choose");
  if (pending >= 0) throw std::logic_error("the last decision has not been reported yet");
}

}  // namespace

Decision Session::choose(const DecisionBudget& budget) {
  check_decidable(status_, pending_);
  if (allocator_ == nullptr) {
    throw std::logic_error("choose() needs a session with an allocator; in this one the caller decides (decide())");
  }
  if (!live_.is_live()) {
    const int choice = allocator_->choose(state_, budget);
    if (choice < 0 || choice >= mdp_->skeleton_count()) {
      throw UsageError("allocator '" + std::string(allocator_->name()) + "' chose skeleton " + std::to_string(choice) +
                       ", outside [0, " + std::to_string(mdp_->skeleton_count()) + ")");
    }
    pending_ = choice;
    pending_action_ = mdp_->next_action(state_, choice);
    return Decision{choice, pending_action_};
  }
  return choose_live(budget);
}

Decision Session::decide(int skeleton) {
  check_decidable(status_, pending_);
  if (allocator_ != nullptr) {
    throw std::logic_error("decide() needs a session without an allocator; in this one allocator '" +
                           std::string(allocator_->name()) + "' decides (choose())");
  }
  if (skeleton < 0 || skeleton >= mdp_->skeleton_count()) {
    throw UsageError("skeleton " + std::to_string(skeleton) + " is outside [0, " +
                     std::to_string(mdp_->skeleton_count()) + ")");
  }
  if (!live_.is_live()) {
    pending_ = skeleton;
    pending_action_ = mdp_->next_action(state_, skeleton);
    return Decision{skeleton, pending_action_};
  }
  return decide_live(skeleton);
}

void Session::throw_without_decision() {
  throw std::logic_error("carry_out without a decision: call choose() or decide() first");
}

Status Session::report_not_yet() { return report(Observation::not_yet()); }

Status Session::report_refined(Steps execution_steps) { return report(Observation::found(execution_steps)); }

Status Session::report(const Observation& observation) {
  if (!live_.is_live() || !observation.refined) {
    return report(observation, std::numeric_limits<double>::quiet_NaN());
  }
  if (observation.execution < 0) return report(observation, -1.0);  // rejected below with the steps
  const double seconds = observation.execution == kNever ? std::numeric_limits<double>::infinity()
                                                         : observation.execution * live_.step_seconds();
  return report(observation, seconds);
}

Status Session::report(const Observation& observation, double execution_seconds) {
  if (pending_ < 0) throw std::logic_error("report without a decision: call choose() or decide() first");
  const int choice = pending_;
  const int action = pending_action_;
  if (allocator_ != nullptr || live_.is_live()) before_ = state_;
  const Status model_status = mdp_->apply(state_, choice, observation);
  pending_ = -1;
  if (action >= 0 && !live_.is_live()) {
    // One step of effort (a live session counts the slices its report charges: report_live).
    ActionAttempt& attempt = attempts_[static_cast<std::size_t>(action)];
    ++attempt.effort;
    attempt.found = observation.refined;
    if (observation.is_backtrack()) end_attempts_below(observation.culprit, action);
  }
  // Only live and owning sessions keep what each action revealed; a plain session (an episode of
  // a Monte Carlo run) does no work for it.
  if (observation.is_backtrack() && !action_execution_steps_.empty()) {
    // The culprit's motion and every motion after it on its paths are discarded.
    const Problem& problem = mdp_->problem();
    for (int a = 0; a < problem.action_count(); ++a) {
      bool below = a == observation.culprit;
      for (int up = problem.parent(a); up >= 0 && !below; up = problem.parent(up)) below = up == observation.culprit;
      if (!below) continue;
      action_execution_steps_[static_cast<std::size_t>(a)] = -1;
      action_execution_seconds_[static_cast<std::size_t>(a)] = -1.0;
    }
  }
  if (action >= 0 && observation.refined && !action_execution_steps_.empty()) {
    const auto slot = static_cast<std::size_t>(action);
    action_execution_steps_[slot] =
        observation.execution == kNever ? mdp_->deadline() + 1 : std::min(observation.execution, mdp_->deadline() + 1);
    action_execution_seconds_[slot] = !std::isnan(execution_seconds)    ? execution_seconds
                                      : observation.execution == kNever ? std::numeric_limits<double>::infinity()
                                                                        : observation.execution * step_seconds();
  }
  if (!live_.is_live()) {
    status_ = model_status;
    // Skeletons still to come keep a session going that its present ones cannot save.
    if (status_ == Status::failure && more_expected_ && state_.time < mdp_->deadline()) status_ = Status::running;
    if (status_ == Status::success) {
      solution_ = mdp_->completed_skeleton(state_, choice);
      if (mdp_->is_timed()) timed_reward_ = mdp_->success_reward(state_, choice);
    }
    if (allocator_ != nullptr) allocator_->observe(before_, choice, state_, status_);
    return status_;
  }
  return report_live(choice, action, observation, execution_seconds);
}

void Session::end_attempts_below(int culprit, int backtracking) {
  const Problem& problem = mdp_->problem();
  for (int a = 0; a < problem.action_count(); ++a) {
    ActionAttempt& attempt = attempts_[static_cast<std::size_t>(a)];
    if (attempt.effort <= 0) continue;
    bool below = a == culprit;
    for (int up = problem.parent(a); up >= 0 && !below; up = problem.parent(up)) below = up == culprit;
    if (!below) continue;
    attempt.ended.push_back(EndedAttempt{attempt.effort, attempt.found, a == backtracking});
    attempt.effort = 0;
    attempt.found = false;
  }
}

Status Session::carry_out_timed(World& world) {
  if (!exogenous_seeded_) {
    // A stream of its own: the allocator's draws stay those of the same seed without chains.
    exogenous_ = detail::exogenous_stream(seed_);
    exogenous_seeded_ = true;
  }
  if (live_.is_live() && !simulated_chains_) {
    // A live session in a world: the chains follow the clock (report_live, end_if_out_of_time),
    // one step of their path per step of CT, however many steps a report charges.
    simulated_chains_ = true;
    chain_path_.assign(1, mdp_->start().chains);
    state_.chains = simulated_chains_at(state_.time);
  }
  Observation observation = pending_action_ < 0
                                ? Observation::not_yet()
                                : world.step(pending_action_, state_.spent[static_cast<std::size_t>(pending_)]);
  if (mdp_->has_chains()) {
    observation = observation.with_chains(simulated_chains_ ? simulated_chains_at(state_.time + 1)
                                                            : mdp_->sample_chain_step(state_.chains, exogenous_));
  }
  if (report(observation) != Status::success) return status_;
  // The completed plan is executed in the simulated chains.
  const auto slot = static_cast<std::size_t>(solution_);
  const Steps finish = mdp_->sample_execution(solution_, state_.time, state_.chains, state_.restore.data(),
                                              state_.execution[slot], exogenous_);
  if (finish == kNever) {
    status_ = Status::failure;
    solution_ = -1;
    timed_reward_ = 0;
  } else {
    timed_reward_ = problem().reward_at(solution_, finish);
  }
  return status_;
}

std::uint16_t Session::simulated_chains_at(Steps t) {
  if (!mdp_->has_chains()) return 0;
  while (chain_path_.size() <= static_cast<std::size_t>(t)) {
    chain_path_.push_back(mdp_->sample_chain_step(chain_path_.back(), exogenous_));
  }
  return chain_path_[static_cast<std::size_t>(t)];
}

double Session::reward() const {
  if (status_ != Status::success || solution_ < 0) return 0.0;
  if (mdp_->is_timed()) return timed_reward_;
  const SkeletonReward& reward = problem().reward(solution_);
  if (live_.is_live()) return std::max(0.0, reward.at(finish_seconds_ / step_seconds()));  // (within a slice)
  return reward.at(static_cast<double>(state_.time + state_.execution[static_cast<std::size_t>(solution_)]));
}

State Session::carried_over(const State& old, const Problem& next) const {
  // Effort spent on the actions in progress, read off the old skeletons sharing them.
  std::vector<std::uint16_t> spent(static_cast<std::size_t>(next.action_count()), 0);
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    const int action = mdp_->next_action(old, k);
    if (action >= 0) spent[static_cast<std::size_t>(action)] = old.spent[static_cast<std::size_t>(k)];
  }
  const std::int64_t saturated = std::int64_t{next.deadline()} + 1;
  // What a refined action adds to ET: its execution, or nothing when that depends on a chain and
  // is drawn when it starts (SPEC §9).
  const auto static_steps = [&](int action) -> std::int64_t {
    if (next.is_timed() && next.execution_chain(action) >= 0) return 0;
    return std::max<Steps>(0, action_execution_steps_[static_cast<std::size_t>(action)]);
  };
  State out(static_cast<std::size_t>(next.skeleton_count()),
            static_cast<std::size_t>(next.culprit_slot_count() + next.timed_slot_count()));
  out.time = old.time;
  out.chains = old.chains;  // the chains are carried over in their order: the same joint state
  // Backtracking (SPEC §7): B_c of every refined culprit, the execution before it on its path;
  // chains or expiry (SPEC §9): the same of every refined timed action (an action may have both).
  for (int c = 0; c < next.action_count(); ++c) {
    const auto index = static_cast<std::size_t>(c);
    if (next.culprit_slot(c) < 0 && next.timed_slot(c) < 0) continue;
    if (index >= action_execution_steps_.size() || action_execution_steps_[index] < 0) continue;
    std::int64_t before = 0;
    for (int up = next.parent(c); up >= 0; up = next.parent(up))
      before = std::min(saturated, before + static_steps(up));
    for (const int slot : {next.culprit_slot(c), next.timed_slot(c)}) {
      if (slot >= 0) out.restore[static_cast<std::size_t>(slot)] = static_cast<std::uint16_t>(before);
    }
  }
  for (int k = 0; k < next.skeleton_count(); ++k) {
    const std::span<const int> path = next.skeleton(k);
    std::size_t refined = 0;
    std::int64_t execution = 0;
    while (refined < path.size()) {
      const auto action = static_cast<std::size_t>(path[refined]);
      if (action >= action_execution_steps_.size() || action_execution_steps_[action] < 0) break;
      execution = std::min(saturated, execution + static_steps(path[refined]));
      ++refined;
    }
    const auto slot = static_cast<std::size_t>(k);
    out.refined[slot] = static_cast<std::uint8_t>(refined);
    out.execution[slot] = static_cast<std::uint16_t>(execution);
    out.spent[slot] = refined < path.size() ? spent[static_cast<std::size_t>(path[refined])] : std::uint16_t{0};
  }
  return out;
}

void Session::change_skeletons(Problem next) {
  // Everything that can fail comes first, so that a failure leaves the session as it was.
  auto problem = std::make_unique<Problem>(std::move(next));
  auto mdp = std::make_unique<Mdp>(*problem);
  std::unique_ptr<Allocator> allocator = made_allocator(make_allocator_, *mdp);
  State state = carried_over(state_, *problem);
  State model = live_.is_live() ? carried_over(model_state_, *problem) : State{};

  owned_problem_ = std::move(problem);
  owned_mdp_ = std::move(mdp);
  owned_allocator_ = std::move(allocator);
  mdp_ = owned_mdp_.get();
  allocator_ = owned_allocator_.get();
  state_ = std::move(state);
  before_ = state_;
  attempts_.resize(static_cast<std::size_t>(owned_problem_->action_count()));
  action_execution_steps_.resize(static_cast<std::size_t>(owned_problem_->action_count()), -1);
  action_execution_seconds_.resize(static_cast<std::size_t>(owned_problem_->action_count()), -1.0);
  ++changes_;
  if (allocator_ != nullptr) allocator_->begin_episode(stream_seed(seed_, changes_));
  if (live_.is_live()) {
    model_state_ = std::move(model);
    if (model_status_ == Status::running && !more_expected_ && !mdp_->any_can_succeed(model_state_)) {
      model_status_ = Status::failure;
    }
  }
  if (out_of_skeletons()) {
    status_ = Status::failure;
    live_.end();
  }
}

namespace {

void check_changeable(bool owns_problem, int pending, Status status, const char* what) {
  if (!owns_problem) {
    throw std::logic_error(std::string(what) + " needs a session that owns its problem (made from a Problem)");
  }
  if (pending >= 0) throw std::logic_error(std::string(what) + " while a decision awaits its report");
  if (status != Status::running) throw std::logic_error(std::string(what) + " after the session ended");
}

}  // namespace

Problem with_added_skeleton(const Problem& current, const std::vector<std::string>& action_ids,
                            std::vector<Action> new_actions, SkeletonReward reward) {
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
  std::vector<std::vector<int>> skeletons = current.skeleton_lists();
  skeletons.push_back(std::move(path));
  std::vector<SkeletonReward> rewards(current.rewards().begin(), current.rewards().end());
  rewards.push_back(reward);
  return with_skeletons(current, std::move(actions), std::move(skeletons), std::move(rewards));
}

std::optional<Problem> without_skeleton(const Problem& current, int k) {
  if (k < 0 || k >= current.skeleton_count()) {
    throw UsageError("retire_skeleton: skeleton " + std::to_string(k) + " out of range [0, " +
                     std::to_string(current.skeleton_count()) + ")");
  }
  if (current.skeleton_count() == 1) return std::nullopt;
  std::vector<std::vector<int>> skeletons;
  std::vector<SkeletonReward> rewards;
  for (int other = 0; other < current.skeleton_count(); ++other) {
    if (other == k) continue;
    skeletons.emplace_back(current.skeleton(other).begin(), current.skeleton(other).end());
    rewards.push_back(current.reward(other));
  }
  return with_skeletons(current, std::vector<Action>(current.actions().begin(), current.actions().end()),
                        std::move(skeletons), std::move(rewards));
}

Problem with_skeletons(const Problem& current, std::vector<Action> actions, std::vector<std::vector<int>> skeletons,
                       std::vector<SkeletonReward> rewards) {
  return Problem(current.name(), current.deadline(), current.step_seconds(), std::move(actions), std::move(skeletons),
                 current.description(), std::move(rewards),
                 std::vector<ExogenousChain>(current.chains().begin(), current.chains().end()));
}

int Session::add_skeleton(const std::vector<std::string>& action_ids, std::vector<Action> new_actions,
                          SkeletonReward reward) {
  check_changeable(owned_problem_ != nullptr, pending_, status_, "add_skeleton");
  const int added = mdp_->problem().skeleton_count();
  change_skeletons(with_added_skeleton(mdp_->problem(), action_ids, std::move(new_actions), reward));
  return added;
}

void Session::revise_distributions(const Problem& beliefs) {
  check_changeable(owned_problem_ != nullptr, pending_, status_, "revise_distributions");
  change_skeletons(with_distributions_of(mdp_->problem(), beliefs));
}

void Session::retire_skeleton(int k) {
  check_changeable(owned_problem_ != nullptr, pending_, status_, "retire_skeleton");
  std::optional<Problem> next = without_skeleton(mdp_->problem(), k);  // checks k
  if (!next) {
    status_ = Status::failure;  // nothing left to refine
    live_.end();
    return;
  }
  change_skeletons(std::move(*next));
}

}  // namespace ontime
