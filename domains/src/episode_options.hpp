#pragma once
// The episode runner's options (episode_runner.hpp) from the settings every run of episodes on a
// domain shares (PlannerRunOptions, TampOptions): how many, the seed, threads, ranks, progress
// and stop. Private to the domains library.

#include "ontime/run/episode_runner.hpp"

namespace ontime::domains::detail {

template <class RunOptions>
MonteCarloOptions monte_carlo_options(const RunOptions& options) {
  MonteCarloOptions episodes;
  episodes.episodes = options.episodes;
  episodes.seed = options.seed;
  episodes.threads = options.threads;
  episodes.ranks = options.ranks;
  episodes.progress = options.progress;
  episodes.stop = options.stop;
  return episodes;
}

}  // namespace ontime::domains::detail
