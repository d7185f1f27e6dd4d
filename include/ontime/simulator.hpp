#pragma once
// Simulated episodes (SPEC §4): the true planning and execution time of every action is
// drawn at the start of the episode and hidden from the allocator, which sees only the
// states of a Session. All actions are drawn in a fixed order, so the same seed and episode
// index give every allocator the same hidden world (common random numbers).

#include <cstdint>
#include <vector>

#include "ontime/allocator.hpp"
#include "ontime/mdp.hpp"
#include "ontime/random.hpp"

namespace ontime {

// The hidden outcomes of one episode.
class HiddenWorld {
 public:
  HiddenWorld(const Problem& problem, std::uint64_t seed);

  Steps planning_time(int action) const { return planning_.at(static_cast<std::size_t>(action)); }
  Steps execution_time(int action) const { return execution_.at(static_cast<std::size_t>(action)); }

  // What one more step of effort on `action`, after `spent` steps, reveals.
  Observation observe(int action, Steps spent) const;

 private:
  std::vector<Steps> planning_;
  std::vector<Steps> execution_;
};

// Receives the duration of each decision of an episode, in nanoseconds.
class DecisionTimer {
 public:
  virtual ~DecisionTimer() = default;
  virtual void record(std::int64_t nanoseconds) = 0;
};

struct EpisodeResult {
  Status status = Status::failure;
  int solution = -1;      // skeleton executed on success
  Steps steps_used = 0;   // steps of effort spent
  int decisions = 0;
};

// Runs one episode of `allocator` in the hidden world drawn from `seed`; the allocator's own
// randomness is seeded from another stream of the same seed.
EpisodeResult run_episode(const Mdp& mdp, Allocator& allocator, std::uint64_t seed,
                          DecisionTimer* timer = nullptr, const DecisionBudget& budget = {});

}  // namespace ontime
