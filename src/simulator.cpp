#include "ontime/simulator.hpp"

#include <chrono>

#include "ontime/session.hpp"

namespace ontime {

HiddenWorld::HiddenWorld(const Problem& problem, std::uint64_t seed) {
  SplitMix64 generator(seed);
  const auto count = static_cast<std::size_t>(problem.action_count());
  planning_.resize(count);
  execution_.resize(count);
  // A fixed draw order (action by action, planning then execution), whatever the allocator
  // later touches, so that every allocator meets the same world for the same seed.
  for (std::size_t a = 0; a < count; ++a) {
    const Action& action = problem.actions()[a];
    planning_[a] = action.planning.sample(generator);
    execution_[a] = action.execution.sample(generator);
  }
}

Observation HiddenWorld::observe(int action, Steps spent) const {
  if (planning_time(action) == spent + 1) return Observation::found(execution_time(action));
  return Observation::not_yet();
}

EpisodeResult run_episode(const Mdp& mdp, Allocator& allocator, std::uint64_t seed, DecisionTimer* timer,
                          const DecisionBudget& budget) {
  const HiddenWorld world(mdp.problem(), seed);
  Session session(mdp, allocator, stream_seed(seed, 1));
  EpisodeResult result;
  while (session.status() == Status::running) {
    Decision decision;
    if (timer != nullptr) {
      const auto start = std::chrono::steady_clock::now();
      decision = session.choose(budget);
      const auto stop = std::chrono::steady_clock::now();
      timer->record(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count());
    } else {
      decision = session.choose(budget);
    }
    ++result.decisions;
    if (decision.action < 0) {
      session.report_not_yet();
    } else {
      const Steps spent = session.state().spent[static_cast<std::size_t>(decision.skeleton)];
      session.report(world.observe(decision.action, spent));
    }
  }
  result.status = session.status();
  result.solution = session.solution();
  result.steps_used = session.steps_used();
  return result;
}

}  // namespace ontime
