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
//
// With backtracking (SPEC §7) an action may be attempted several times in an episode: attempt i
// of action a ends at a step drawn, with its kind (a motion, or a backtrack and its culprit) and
// the motion's execution, from stream i of stream a of the episode's seed; a backtrack to c
// starts new attempts of c and of every action below it. So the world an allocator meets still
// depends on the seed alone, and an attempt's outcome on no other draw.
class HiddenWorld final : public World {
 public:
  // The world drawn from `seed`.
  HiddenWorld(const Problem& problem, std::uint64_t seed);

  void begin_episode(std::uint64_t seed) override;
  // observe(), and after a backtrack the new attempts it starts.
  Observation step(int action, Steps spent) override;

  // The current attempt of `action`: the step at which it ends (kNever: it never does), and, for
  // one that ends with a motion, its execution time.
  Steps planning_time(int action) const { return planning_.at(static_cast<std::size_t>(action)); }
  Steps execution_time(int action) const { return execution_.at(static_cast<std::size_t>(action)); }

  // What one more step of effort on `action`, after `spent` steps of its current attempt, reveals.
  Observation observe(int action, Steps spent) const;

 private:
  // Backtracking: draws attempt attempt_[a] of action a.
  void draw_attempt(std::size_t a);

  const Problem* problem_;
  std::vector<Steps> planning_;
  std::vector<Steps> execution_;
  // Backtracking only: per action, the current attempt's number and its culprit (-1: it ends with
  // a motion, or never); and the episode's seed.
  std::vector<std::uint32_t> attempt_;
  std::vector<int> culprit_;
  std::uint64_t seed_ = 0;
};

// One hidden world per thread, for the episode runner. `problem` must outlive the worlds.
WorldFactory hidden_worlds(const Problem& problem);

}  // namespace ontime
