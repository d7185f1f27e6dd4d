#pragma once
// Allocators driving the real planner: episodes in which an ontime::Session decides, step by
// step, which action of a domain gets the next step of effort, and the domain's refinements —
// resumed slice by slice, several of them interleaved — answer. The instance supplies the
// allocator's model (fitted from the domain's log); the outcomes come from the planner itself,
// so the success rate measures how well the model predicts the domain.
//
// Within an episode an action is refined once: its refinement starts, the first time the
// allocator picks it, where the refinement of the action before it ended (a first action at
// the domain's initial configuration), and every later pick continues it by one step.
// Episode e draws the refinement of the a-th action of the instance from
// stream_seed(stream_seed(seed, e), 2a) (and a fallback start from stream 2a + 1): same seed,
// same episodes, whatever the thread count (in the collision-checks effort unit).

#include <cstdint>
#include <vector>

#include "ontime/allocator.hpp"
#include "ontime/domains/domain.hpp"
#include "ontime/mdp.hpp"

namespace ontime::domains {

struct OnlineEpisode {
  Status status = Status::failure;
  int solution = -1;          // the skeleton executed on success
  Steps steps_used = 0;       // steps of planning effort
  int actions_refined = 0;    // refinements that found a motion
  int actions_started = 0;    // refinements started (interleaved ones included)
};

struct OnlineOptions {
  EffortSettings effort;
  // Diagnostic: an action after the first starts from the domain's fallback start (drawn from
  // the episode's seed) instead of where the refinement before it ended, which removes the
  // dependence between consecutive refinements that the MDP does not model.
  bool independent_starts = false;
};

// One episode. The instance's action ids must be actions of the domain. Throws
// std::invalid_argument when they are not.
OnlineEpisode run_online_episode(const Domain& domain, const Mdp& mdp, Allocator& allocator, std::uint64_t seed,
                                 const OnlineOptions& options);

struct OnlineSummary {
  std::uint64_t episodes = 0, successes = 0;
  double success_rate = 0, ci95 = 0;
  double mean_actions_started = 0;  // refinements started per episode
  double seconds = 0;               // wall-clock time
};

// `episodes` episodes on `threads` threads (0: all cores), episode e from stream_seed(seed, e).
OnlineSummary run_online(const Domain& domain, const Mdp& mdp, const AllocatorFactory& factory,
                         std::uint64_t episodes, std::uint64_t seed, unsigned threads, const OnlineOptions& options);

}  // namespace ontime::domains
