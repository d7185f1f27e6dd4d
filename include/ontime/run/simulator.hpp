#pragma once
// Simulated episodes (SPEC §4): the true planning and execution time of every action is
// drawn at the start of the episode and hidden from the allocator, which sees only the
// states of a Session. All actions are drawn in a fixed order, so the same seed gives every
// allocator the same hidden world (common random numbers). The episode runner
// (episode_runner.hpp) runs allocators in these worlds.

#include <cstdint>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/run/world.hpp"

namespace ontime {

// The hidden outcomes of one episode, redrawn by begin_episode.
class HiddenWorld final : public World {
 public:
  // The world drawn from `seed`.
  HiddenWorld(const Problem& problem, std::uint64_t seed);

  void begin_episode(std::uint64_t seed) override;
  Observation step(int action, Steps spent) override { return observe(action, spent); }

  Steps planning_time(int action) const { return planning_.at(static_cast<std::size_t>(action)); }
  Steps execution_time(int action) const { return execution_.at(static_cast<std::size_t>(action)); }

  // What one more step of effort on `action`, after `spent` steps, reveals.
  Observation observe(int action, Steps spent) const;

 private:
  const Problem* problem_;
  std::vector<Steps> planning_;
  std::vector<Steps> execution_;
};

// One hidden world per thread, for the episode runner. `problem` must outlive the worlds.
WorldFactory hidden_worlds(const Problem& problem);

}  // namespace ontime
