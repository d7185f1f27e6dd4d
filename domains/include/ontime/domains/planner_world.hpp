#pragma once
// A domain's real motion planner as the World of episodes (ontime/world.hpp): the episode
// runner's allocator decides, step by step, which action of the domain gets the next step of
// effort, and the domain's refinements — resumed slice by slice, several of them interleaved —
// answer. The instance supplies the allocator's model (fitted from the domain's log); the
// outcomes come from the planner itself, so the success rate measures how well the model
// predicts the domain.
//
// Within an episode an action is refined once: its refinement starts, the first time the
// allocator picks it, where the refinement of the action before it ended (a first action at
// the domain's initial configuration), and every later pick continues it by one step.
// The episode with seed s draws the refinement of the a-th action of the instance from
// stream_seed(s, 2a) (and a fallback start from stream 2a + 1): same seed, same episodes,
// whatever the thread count (in the collision-checks effort unit).

#include <cstdint>
#include <memory>
#include <vector>

#include "ontime/domains/domain.hpp"
#include "ontime/problem.hpp"
#include "ontime/world.hpp"

namespace ontime::domains {

struct PlannerWorldOptions {
  EffortSettings effort;
  // Diagnostic: an action after the first starts from the domain's fallback start (drawn from
  // the episode's seed) instead of where the refinement before it ended, which removes the
  // dependence between consecutive refinements that the MDP does not model.
  bool independent_starts = false;
};

// The clock of live episodes in the collision-checks unit: the steady clock, except that each
// planner call counts as the nominal seconds of its collision checks instead of the real time
// it took. The allocator's thinking and the caller's time stay real, so a live episode on it
// charges them against a planner as slow as the model says.
class NominalPlanningClock final : public Clock {
 public:
  double now() const override { return steady_.now() + offset_; }
  // A planner call took `real_seconds` and counts as `nominal_seconds`.
  void count_call(double real_seconds, double nominal_seconds) noexcept { offset_ += nominal_seconds - real_seconds; }

 private:
  SteadyClock steady_;
  double offset_ = 0;
};

// Counters: "refinements_started" (interleaved ones included) and "refinements_found" (those
// that found a motion), summed over the episodes since the world was made.
class PlannerWorld final : public World {
 public:
  // The domain and the problem must outlive the world. The problem's action ids must be
  // actions of the domain: step throws std::invalid_argument for one that is not.
  PlannerWorld(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options);

  void begin_episode(std::uint64_t seed) override;
  Observation step(int action, Steps spent) override;
  void collect_statistics(Statistics& statistics) const override;
  // Live episodes: the nominal planning clock in the collision-checks unit; the steady clock
  // (nullptr) in the wall-clock unit, where planner calls take the time they take.
  const Clock* clock() const noexcept override;

 private:
  const Domain* domain_;
  const Problem* problem_;
  PlannerWorldOptions options_;
  std::uint64_t seed_ = 0;
  std::vector<std::unique_ptr<Refinement>> refinements_;  // by action, in this episode
  std::uint64_t started_ = 0;
  std::uint64_t found_ = 0;
  NominalPlanningClock nominal_clock_;
};

// One planner world per thread, for the episode runner; the arguments must outlive the worlds.
WorldFactory planner_worlds(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options);

}  // namespace ontime::domains
