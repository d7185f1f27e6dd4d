#include "ontime/run/simulator.hpp"

#include <algorithm>
#include <memory>

#include "ontime/util/random.hpp"

namespace ontime {

HiddenWorld::HiddenWorld(const Problem& problem, std::uint64_t seed)
    : problem_(&problem),
      planning_(static_cast<std::size_t>(problem.action_count())),
      execution_(static_cast<std::size_t>(problem.action_count())) {
  HiddenWorld::begin_episode(seed);
}

void HiddenWorld::begin_episode(std::uint64_t seed) {
  if (problem_->has_backtracking()) {
    seed_ = seed;
    attempt_.assign(planning_.size(), 0);
    culprit_.assign(planning_.size(), -1);
    for (std::size_t a = 0; a < planning_.size(); ++a) draw_attempt(a);
    return;
  }
  SplitMix64 generator(seed);
  // A fixed draw order (action by action, planning then execution), whatever the allocator
  // later touches, so that every allocator meets the same world for the same seed.
  for (std::size_t a = 0; a < planning_.size(); ++a) {
    const Action& action = problem_->actions()[a];
    planning_[a] = action.planning.sample(generator);
    execution_[a] = action.execution.sample(generator);
  }
}

void HiddenWorld::draw_attempt(std::size_t a) {
  const Action& action = problem_->actions()[a];
  SplitMix64 generator(stream_seed(stream_seed(seed_, a), attempt_[a]));
  const AttemptEnd end = draw_attempt_end(action, uniform01(generator));
  planning_[a] = end.step;
  execution_[a] = 0;
  culprit_[a] = -1;
  if (end.step == kNever) return;
  if (end.found) {
    execution_[a] = action.execution.sample(generator);
  } else {
    culprit_[a] = draw_culprit(*problem_, static_cast<int>(a), generator);
  }
}

Observation HiddenWorld::observe(int action, Steps spent) const {
  if (planning_time(action) != spent + 1) return Observation::not_yet();
  if (!culprit_.empty() && culprit_[static_cast<std::size_t>(action)] >= 0) {
    return Observation::backtracked(culprit_[static_cast<std::size_t>(action)]);
  }
  return Observation::found(execution_time(action));
}

Observation HiddenWorld::step(int action, Steps spent) {
  const Observation seen = observe(action, spent);
  if (seen.is_backtrack()) {
    // The culprit and every action below it start new attempts.
    for (int a = 0; a < problem_->action_count(); ++a) {
      bool below = a == seen.culprit;
      for (int up = problem_->parent(a); up >= 0 && !below; up = problem_->parent(up)) below = up == seen.culprit;
      if (!below) continue;
      ++attempt_[static_cast<std::size_t>(a)];
      draw_attempt(static_cast<std::size_t>(a));
    }
  }
  return seen;
}

WorldFactory hidden_worlds(const Problem& problem) {
  return [&problem] { return std::make_unique<HiddenWorld>(problem, 0); };
}

}  // namespace ontime
