#pragma once
// Evaluation of allocators: Monte Carlo over seeded episodes, and exact success probability.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>

#include "ontime/allocator.hpp"
#include "ontime/mdp.hpp"

namespace ontime {

struct MonteCarloOptions {
  std::uint64_t episodes = 10'000;
  std::uint64_t seed = 1;
  unsigned threads = 0;          // 0: one per hardware thread
  bool time_decisions = true;    // measure each decision (adds ~40 ns of clock reads)
  DecisionBudget decision_budget;  // passed with every decision (unset: the allocators' own)
  // Called now and then with the number of episodes done (from one thread at a time).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

struct LatencySummary {
  std::uint64_t decisions = 0;
  double mean_us = 0, median_us = 0, p99_us = 0, max_us = 0;
};

struct MonteCarloResult {
  std::uint64_t episodes = 0;
  std::uint64_t successes = 0;
  double success_rate = 0;
  double ci95 = 0;             // half-width: 1.96 * sqrt(r (1 - r) / N)  (SPEC §4)
  LatencySummary decision_time;
  LatencySummary episode_decision_time;  // total decision time of each episode (meta-level cost)
  double seconds = 0;          // wall-clock time of the whole run
  Statistics statistics;       // the allocators' counters, merged over threads
};

// Runs `options.episodes` episodes; episode i lives in the hidden world drawn from
// stream_seed(options.seed, i), whichever thread runs it, so the success counts are identical
// for every thread count. Each thread gets its own allocator from `factory`.
MonteCarloResult run_monte_carlo(const Mdp& mdp, const AllocatorFactory& factory,
                                 const MonteCarloOptions& options);

struct ExactEvaluation {
  double success_probability = 0;
  std::size_t states = 0;      // reachable running states under the allocator
};

// The success probability of a stationary allocator (SPEC §4): a finite sum over the states
// reachable under its choices, with no sampling. Throws UsageError when the allocator is not
// stationary, ResourceLimitError past `max_states`.
ExactEvaluation evaluate_exactly(const Mdp& mdp, Allocator& allocator,
                                 std::size_t max_states = 10'000'000);

// The 95% half-width of SPEC §4 for r successes out of n.
double ci95_half_width(double rate, std::uint64_t episodes) noexcept;

}  // namespace ontime
