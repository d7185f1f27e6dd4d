#pragma once
// The world an episode happens in: what one step of refinement effort on an action reveals.
//
// An allocator decides which action gets the next step; a World answers "not yet" or "refined,
// with execution time x". The hidden sampled world of the simulator (simulator.hpp) is one
// World, a domain's real motion planner another (ontime::domains::PlannerWorld); a caller can
// implement its own, e.g. around a planner of its own.
//
// One World object serves one episode at a time and is not thread-safe; it is reused from
// episode to episode (begin_episode), so it may keep resources that are costly to build, such
// as a planner's collision checkers. A WorldFactory makes one World per thread.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {

// A skeleton a task planner running alongside an episode found (World::next_skeleton).
struct FoundSkeleton {
  std::vector<std::string> action_ids;  // in order
  std::vector<Action> new_actions;      // those of its actions no earlier skeleton of the episode had
  // Search time the episode's clock does not see (e.g. a task planner's nominal cost), charged
  // to the deadline as outside time.
  double charged_seconds = 0;
};

class World {
 public:
  virtual ~World() = default;

  // Starts a new episode: its outcomes are drawn from `seed` and nothing else, so that an
  // episode does not depend on which thread ran the episodes before it.
  virtual void begin_episode(std::uint64_t seed) = 0;

  // One step of effort on `action`, which has already had `spent` steps in this attempt: not
  // yet, or refined with its execution time in steps (kNever: the motion cannot be executed), or,
  // with backtracking (SPEC §7), a backtrack blaming one of the action's culprits (whose motion
  // and everything after it are discarded: their next steps are new attempts). The action is one
  // whose parent action, if any, is refined in this episode.
  virtual Observation step(int action, Steps spent) = 0;

  // Adds this world's counters (work done since it was made, e.g. refinements started) to
  // `statistics`; a sampled world has none.
  virtual void collect_statistics(Statistics& statistics) const { (void)statistics; }

  // The clock live episodes of this world run on (session.hpp), or nullptr for the steady
  // clock: a simulated world can keep a manual clock that its steps advance.
  virtual const Clock* clock() const noexcept { return nullptr; }

  // Worlds whose skeletons stream in (streaming episodes, episode_runner.hpp): the task
  // planner's next skeleton of this episode, or nullopt when it has no more. Its actions take
  // the next action indices of the episode's problem, in the order of new_actions. The default:
  // a world of fixed skeletons, which has none to add.
  virtual std::optional<FoundSkeleton> next_skeleton() { return std::nullopt; }
  // Acting while planning (SPEC §10): the robot committed to the executed prefix `executed` (action
  // indices of the episode's problem, in order). A world with a task planner streams only skeletons
  // through it from now on (the executed prefix followed by a path from where it ends). The
  // default: nothing to do.
  virtual void commit(const std::vector<int>& executed) { (void)executed; }
};

using WorldFactory = std::function<std::unique_ptr<World>()>;

}  // namespace ontime
