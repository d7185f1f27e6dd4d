#include "ontime/allocators/thompson.hpp"

#include <limits>

#include "ontime/allocators/allocator_registry.hpp"

namespace ontime {
namespace {

constexpr std::int64_t kNeverFinishes = std::numeric_limits<std::int64_t>::max();

}  // namespace

bool ThompsonAllocator::better(int k, std::int64_t finish, int best, std::int64_t best_finish) const {
  if (best < 0) return true;
  const Problem& problem = mdp_->problem();
  if (problem.has_rewards()) {
    // The reward the drawn world gives each (-1: it misses the deadline there), then the sooner.
    const auto worth = [&](int skeleton, std::int64_t at) {
      return at <= mdp_->deadline() ? problem.reward_at(skeleton, static_cast<Steps>(at)) : -1.0;
    };
    const double mine = worth(k, finish);
    const double theirs = worth(best, best_finish);
    if (mine != theirs) return mine > theirs;
  }
  return finish < best_finish;
}

ThompsonAllocator::ThompsonAllocator(const Mdp& mdp)
    : mdp_(&mdp),
      drawn_at_(static_cast<std::size_t>(mdp.problem().action_count()), 0),
      drawn_time_(static_cast<std::size_t>(mdp.problem().action_count()), 0) {}

std::int64_t ThompsonAllocator::drawn_time(int action, Steps spent) {
  const auto slot = static_cast<std::size_t>(action);
  if (drawn_at_[slot] == decision_) return drawn_time_[slot];
  const Action& model = mdp_->problem().action(action);
  // T - spent given T > spent, by inverting the CDF above F(spent).
  const double below = model.planning.cdf(spent);
  const Steps planning = model.planning.quantile(below + uniform01(generator_) * (1.0 - below));
  const Steps execution = model.execution.sample(generator_);
  drawn_at_[slot] = decision_;
  drawn_time_[slot] = planning == kNever || execution == kNever
                          ? kNeverFinishes
                          : std::int64_t{planning} - spent + std::int64_t{execution};
  return drawn_time_[slot];
}

std::int64_t ThompsonAllocator::drawn_finish_with_backtracking(const State& state, int k) {
  const Problem& problem = mdp_->problem();
  const auto slot = static_cast<std::size_t>(k);
  const std::span<const int> actions = problem.skeleton(k);
  const std::int64_t deadline = mdp_->deadline();
  execution_before_.assign(actions.size() + 1, 0);
  // The execution before each refined position: the restore values recorded in the state where
  // there are any (every position some action may blame), else unknown and unneeded.
  for (std::size_t position = 0; position < state.refined[slot]; ++position) {
    const int culprit_slot = problem.culprit_slot(actions[position]);
    if (culprit_slot >= 0) execution_before_[position] = state.restore[static_cast<std::size_t>(culprit_slot)];
  }
  std::int64_t time = state.time;
  std::int64_t execution = state.execution[slot];
  std::size_t position = state.refined[slot];
  Steps spent = state.spent[slot];
  while (position < actions.size()) {
    const Action& action = problem.action(actions[position]);
    // The attempt's end, conditioned on `spent` steps that neither found nor backtracked.
    const AttemptEnd end =
        draw_attempt_end(action, uniform01(generator_), spent, static_cast<Steps>(deadline - time + spent));
    if (end.step == kNever) return kNeverFinishes;
    time += end.step - spent;
    spent = 0;
    if (end.found) {
      const Steps drawn = action.execution.sample(generator_);
      if (drawn == kNever) return kNeverFinishes;
      execution_before_[position] = execution;
      execution += drawn;
      ++position;
    } else {
      position = static_cast<std::size_t>(problem.position(draw_culprit(problem, actions[position], generator_)));
      execution = execution_before_[position];
    }
    if (time >= deadline) return kNeverFinishes;
  }
  return time + execution;
}

ThompsonAllocator::Draw ThompsonAllocator::drawn_plan_with_chains(const State& state, int k) {
  // Skeleton k refined alone in one draw of the model: planning, static executions and the
  // chains' steps as the MDP draws them, until a plan is completed (worth its expected reward
  // over the chains' paths while it executes) or the episode is lost (worth -1).
  scratch_ = state;
  for (;;) {
    const Observation observation = mdp_->sample_observation(scratch_, k, generator_);
    const Status status = mdp_->apply(scratch_, k, observation);
    if (status == Status::success) return {mdp_->success_reward(scratch_, k), scratch_.time};
    if (status == Status::failure) return {-1.0, kNeverFinishes};
  }
}

int ThompsonAllocator::choose_with_chains(const State& state) {
  int best = -1;
  Draw best_draw{-1.0, kNeverFinishes};
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (!mdp_->can_succeed(state, k)) continue;
    const Draw draw = drawn_plan_with_chains(state, k);
    if (best < 0 || draw.worth > best_draw.worth ||
        (draw.worth == best_draw.worth && draw.completed < best_draw.completed)) {
      best = k;
      best_draw = draw;
    }
  }
  return best >= 0 ? best : mdp_->first_with_work_left(state);
}

int ThompsonAllocator::choose(const State& state) {
  ++decision_;
  if (mdp_->is_timed()) return choose_with_chains(state);
  if (mdp_->has_backtracking()) {
    int best = -1;
    std::int64_t best_finish = kNeverFinishes;
    for (int k = 0; k < mdp_->skeleton_count(); ++k) {
      if (!mdp_->can_succeed(state, k)) continue;
      const std::int64_t finish = drawn_finish_with_backtracking(state, k);
      if (better(k, finish, best, best_finish)) {
        best = k;
        best_finish = finish;
      }
    }
    return best >= 0 ? best : mdp_->first_with_work_left(state);
  }
  const Problem& problem = mdp_->problem();
  int best = -1;
  std::int64_t best_finish = kNeverFinishes;
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (!mdp_->can_succeed(state, k)) continue;
    const auto slot = static_cast<std::size_t>(k);
    std::int64_t finish = std::int64_t{state.time} + state.execution[slot];
    const std::span<const int> actions = problem.skeleton(k);
    for (std::size_t position = state.refined[slot]; position < actions.size() && finish != kNeverFinishes;
         ++position) {
      const Steps spent = position == state.refined[slot] ? static_cast<Steps>(state.spent[slot]) : 0;
      const std::int64_t time = drawn_time(actions[position], spent);
      finish = time == kNeverFinishes ? kNeverFinishes : finish + time;
    }
    if (better(k, finish, best, best_finish)) {
      best = k;
      best_finish = finish;
    }
  }
  return best >= 0 ? best : mdp_->first_with_work_left(state);
}

AllocatorKind thompson_kind() {
  return {.name = "thompson",
          .summary = "Thompson-style: one world drawn from the model per step, the skeleton finishing soonest in it",
          .capabilities = {Capability::randomised, Capability::chains},
          .parameters = {},
          .make = [](const Mdp& mdp, const ParameterReader&) -> AllocatorFactory {
            return [model = &mdp] { return std::make_unique<ThompsonAllocator>(*model); };
          },
          .commit_rule = kEagerCommitRule};
}

}  // namespace ontime
