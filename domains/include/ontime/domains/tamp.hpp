#pragma once
// The whole deadline-aware TAMP loop on the clock (`ontime tamp`, ontime.domains.tamp): in each
// episode the domain's task planner (Domain::task_planners) streams skeletons into a live session,
// each charged its search time as it is found; the allocator decides which action the domain's
// real motion planner refines next; the distributions it decides with come from a library of
// fitted actions (a problem whose actions are the domain's, e.g. every doorway move collected
// once). Episodes are seeded as every run (episode_runner.hpp) and, on the modelled clock
// (`thinking` set, collision-checks effort), the same seed gives the same episodes on any machine
// for any thread count.
//
// Cost: the episodes' planning (at most the deadline of effort each, refinements interleaved),
// plus the drawn episode run once more on its own.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/domains/domain.hpp"
#include "ontime/domains/drawing.hpp"
#include "ontime/domains/effort.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/util/memory.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime::domains {

// Repeated episodes in the world with the online update (online_belief.hpp): `sequences`
// independent sequences of TampOptions::episodes episodes each; in a sequence, each episode's
// allocator plans with the library's planning distributions updated by every attempt the robot
// made in the sequence's episodes before it (found after t steps, or still unrefined after c when
// the episode ended), the library as the prior worth `strength` attempts.
struct TampAdaptation {
  double strength = 10;
  std::uint64_t sequences = 1;
};

struct TampOptions {
  std::string solver;
  ParameterValues parameters;
  double deadline = 0;  // seconds; whole steps of the library's step_seconds count
  EffortSettings effort;
  std::uint64_t episodes = 100;  // with `adaptation`: per sequence
  std::uint64_t seed = 1;        // episode e uses stream e of it (episode e of sequence r: r * episodes + e)
  std::optional<TampAdaptation> adaptation;
  // Concurrent: the robot acts while planning (SPEC §10): each episode a live ConcurrentSession that
  // owns its skeletons, the allocator by its commit rule. After each start the skeletons not through
  // what the robot executed retire and the task planner streams only paths through it (the executed
  // prefix followed by a path from the room where it ends). Not with `adaptation`.
  Acting acting = Acting::plan_first;
  unsigned threads = 0;         // 0: one per hardware thread
  double task_seconds = 0.5;    // search seconds charged for each skeleton found
  int arrival_period = 2;       // steps between two skeletons (sooner when none found can still succeed)
  int max_skeletons = 16;       // skeletons the task planner finds at most
  double decision_share = 0.5;  // of a slice, for an anytime allocator without its own budget
  // The modelled clock: thinking charged by this model, nothing real on the clock. Unset: the
  // real clock (a robot's view).
  std::optional<ThinkingModel> thinking;
  bool keep_episodes = false;                    // every episode's result and timeline
  std::optional<std::uint64_t> picture_episode;  // the episode drawn (on the root rank)
  std::string world_name;                        // the world file's name: in the episodes' name and the picture's title
  std::string library_source;                    // where the library came from, as given (its errors name it)
  const Ranks* ranks = nullptr;
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  std::function<bool()> stop;  // thread-safe; once true the run ends by throwing Cancelled
};

// One episode drawn: its result (timeline kept) and its map.
struct TampPicture {
  std::uint64_t episode = 0;
  EpisodeResult result;
  EpisodeDrawing drawing;
};

struct TampResult {
  Steps deadline_steps = 0;
  double step_seconds = 0;
  MonteCarloResult summary;
  double mean_skeletons_found = 0;      // per episode
  double refinements_started = 0;       // per episode
  double backtracks = 0;                // per episode
  std::vector<EpisodeResult> episodes;  // with keep_episodes (sequence by sequence with adaptation)
  // With adaptation: per episode index of a sequence, how many of the sequences succeeded there.
  std::vector<std::uint64_t> successes_by_episode;
  // With picture_episode, on the root rank, unless the task planner found no skeleton then.
  std::optional<TampPicture> picture;
};

// The deadline in whole steps of the library's step_seconds.
Steps tamp_deadline_steps(const Problem& library, double deadline);

// Refuses, before any work: the modelled clock with wall-clock effort, a picture episode past
// the run, an adaptation without sequences or with a strength that is not positive and finite, a deadline of less than
// one or more than Problem::kMaxDeadline steps (UsageError, parameters named as `spelling` writes them), and a library
// without an action that a skeleton of the task planner needs (InputError naming the library).
void check_tamp_request(const Domain& domain, const Problem& library, const TampOptions& options,
                        const ParameterSpelling& spelling = nullptr);

// check_tamp_request, then the episodes. The domain and the library must outlive the call.
TampResult run_tamp(const Domain& domain, const Problem& library, const TampOptions& options,
                    const ParameterSpelling& spelling = nullptr);

}  // namespace ontime::domains
