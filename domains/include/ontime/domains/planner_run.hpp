#pragma once
// Episodes in which an allocator drives a domain's real motion planner step by step (`ontime
// run`, ontime.domains.run): the allocator decides with a fitted instance as its model, the
// planner's refinements (several interleaved) answer (planner_world.hpp), and the success rate
// measures how well the model predicts the domain; optionally against the exact success the
// allocator expects from the instance. Live episodes (always with wall-clock effort) charge the
// allocator's thinking and the planner's overruns against the deadline in seconds.
//
// Seeded as every run (episode_runner.hpp): in the collision-checks unit the same seed gives
// the same counts for any thread count. Cost: the episodes' planning (at most the instance's
// deadline of effort each), and with `exact` the exact evaluation of the allocator.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/domains/domain.hpp"
#include "ontime/domains/effort.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/memory.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime::domains {

struct PlannerRunOptions {
  std::string solver;
  ParameterValues parameters;
  std::uint64_t episodes = 200;
  std::uint64_t seed = 1;  // episode e uses stream e of it
  unsigned threads = 0;    // 0: one per hardware thread
  EffortSettings effort;
  // Every action after the first starts at a fresh pose in its room, not where the refinement
  // before it ended (PlannerWorldOptions::independent_starts).
  bool independent_starts = false;
  // The allocator's distributions (with_distributions_of(instance, *belief)), while the instance
  // keeps the episodes' structure (skeletons, culprits): e.g. a backtracking-ignorant fit of the
  // same log deciding in a world that backtracks (docs/spec.md §7). Null: the instance's own.
  const Problem* belief = nullptr;
  std::string belief_source;    // for reports
  bool exact = false;           // also the exact success of the allocator with the instance as the truth
  bool live = false;            // live episodes (also whenever the effort is wall-clock time)
  double decision_share = 0.5;  // live: the share of a step an anytime allocator thinks per decision
  const Ranks* ranks = nullptr;
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  std::function<bool()> stop;  // thread-safe; once true the run ends by throwing Cancelled
};

// Whether the run's episodes are live: asked for, or wall-clock effort.
bool is_live(const PlannerRunOptions& options) noexcept;

struct PlannerRun {
  MonteCarloResult summary;
  double refinements_started = 0;  // per episode
  double backtracks = 0;           // per episode
  std::optional<ExactEvaluation> exact;
  std::vector<EpisodeResult> episodes;  // live runs: every episode with its timeline
};

// Refuses, before any work, what the allocator would need beyond this machine's memory (its
// declared need for each thread of the run) and, for an exact evaluation or an optimal
// allocator, an instance too large for exact work (`source` names it); UsageError with the
// parameters named as `spelling` writes them.
void check_planner_run_request(const Problem& problem, const std::string& source, const PlannerRunOptions& options,
                               const ParameterSpelling& spelling = nullptr);

// Refuses, before any episode, an instance with an action the domain's world does not have
// (InputError "source: actions.ID: ...", read from Domain::action_features); a domain without
// features cannot say, and is not checked.
void check_domain_actions(const Domain& domain, const Problem& problem, const std::string& source);

// The episodes (and the exact value). The instance's action ids must be actions of the domain. An
// instance acting while planning (SPEC §10) runs the allocator by its commit rule, on the model's
// steps or live, with a belief too (the allocator decides on the belief's model).
PlannerRun run_planner_episodes(const Domain& domain, const Problem& problem, const PlannerRunOptions& options);

}  // namespace ontime::domains
