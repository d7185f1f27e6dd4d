#pragma once
// Evaluation of allocators: Monte Carlo over seeded simulated episodes (the episode runner in
// hidden sampled worlds), and exact success probability.

#include <cstddef>
#include <functional>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/run/episode_runner.hpp"

namespace ontime {

// Runs `options.episodes` episodes in hidden sampled worlds (simulator.hpp): episode i lives in
// the world drawn from stream_seed(options.seed, i), whichever thread runs it, so the success
// counts are identical for every thread count. Each thread gets its own allocator from `factory`.
MonteCarloResult run_monte_carlo(const Mdp& mdp, const AllocatorFactory& factory, const MonteCarloOptions& options);

struct ExactEvaluation {
  double success_probability = 0;
  // The expected reward (SPEC §8): the success probability, to the bit, without rewards. With
  // rewards the same policy is valued twice, once with every reward 1.
  double expected_reward = 0;
  std::size_t states = 0;  // reachable running states under the allocator
};

// The success probability and expected reward of a stationary allocator (SPEC §4, §8): a finite sum over the states
// reachable under its choices, with no sampling. Throws UsageError when the allocator is not
// stationary, ResourceLimitError past `max_states`, Cancelled once `stop` (checked every few
// thousand states) returns true.
ExactEvaluation evaluate_exactly(const Mdp& mdp, Allocator& allocator, std::size_t max_states = 10'000'000,
                                 const std::function<bool()>& stop = {});

// Acting while planning (SPEC §10): Monte Carlo in the same hidden sampled worlds
// (run_concurrent_episodes), and the exact value of a stationary allocator (ConcurrentSolver's
// policy mode: a finite sum over the states its moves reach). Same errors as above.
MonteCarloResult run_monte_carlo(const ConcurrentMdp& mdp, const ConcurrentAllocatorFactory& factory,
                                 const MonteCarloOptions& options);
// The exact success probability and expected reward of a stationary concurrent allocator, as above.
ExactEvaluation evaluate_exactly(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator,
                                 std::size_t max_states = 10'000'000, const std::function<bool()>& stop = {});

}  // namespace ontime
