#include "ontime/run/simulator.hpp"

#include <memory>

namespace ontime {

HiddenWorld::HiddenWorld(const Problem& problem, std::uint64_t seed)
    : problem_(&problem),
      planning_(static_cast<std::size_t>(problem.action_count())),
      execution_(static_cast<std::size_t>(problem.action_count())) {
  HiddenWorld::begin_episode(seed);
}

void HiddenWorld::begin_episode(std::uint64_t seed) {
  SplitMix64 generator(seed);
  // A fixed draw order (action by action, planning then execution), whatever the allocator
  // later touches, so that every allocator meets the same world for the same seed.
  for (std::size_t a = 0; a < planning_.size(); ++a) {
    const Action& action = problem_->actions()[a];
    planning_[a] = action.planning.sample(generator);
    execution_[a] = action.execution.sample(generator);
  }
}

Observation HiddenWorld::observe(int action, Steps spent) const {
  if (planning_time(action) == spent + 1) return Observation::found(execution_time(action));
  return Observation::not_yet();
}

WorldFactory hidden_worlds(const Problem& problem) {
  return [&problem] { return std::make_unique<HiddenWorld>(problem, 0); };
}

}  // namespace ontime
