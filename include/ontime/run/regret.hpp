#pragma once
// The regret of an allocator, V*(s0) - V^pi(s0), estimated along its own episodes with far less
// variance than the difference of two success rates.
//
// What it computes. For any allocator, stationary or not, and episodes drawn from the model,
//   V*(s0) - V^pi(s0) = E[ sum over the decisions t of (V*(s_t) - Q*(s_t, a_t)) ]
// (the performance-difference identity: the terms telescope, since V^pi's episodes move by the
// model's outcome probabilities). Each term is a decision's exact loss, 0 wherever the allocator
// chose optimally, so an allocator that is optimal at nearly every state has an estimate near 0
// with a narrow interval, where its sampled success rate would need millions of episodes to be
// told apart from the optimum. `with_regret` wraps an allocator: after each decision, in
// observe() and so outside the decision's timing, it adds the decision's loss, computed by the
// exact search (search_solver.hpp) whose table is kept across the episodes of its thread. Each
// episode's sum, and its square, go into the statistics (kRegretSum, kRegretSquares,
// kRegretEpisodes) in fixed point, whole multiples of kRegretUnit held exactly in a double, so
// that the runner's merge over threads sums them exactly and the totals do not depend on the
// thread count; with V*(s0) (kRegretOptimum, solved first by each thread's meter),
// `regret_estimate` turns them into a mean and a 95% interval.
//
// Guarantees: the mean is unbiased for episodes drawn from the Mdp given (a hidden sampled world
// of the same instance; an allocator planning with another belief is judged under this Mdp);
// each loss is exact to the solver's rounding. Cost: per decision, the exact values of the state
// and the chosen successors (a search from each, fast once the table holds them); memory: the
// search's table per thread, capped by `max_states` (ResourceLimitError past it).

#include <cstdint>
#include <optional>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {

inline constexpr const char* kRegretSum = "regret_units";
inline constexpr const char* kRegretSquares = "regret_square_units";
inline constexpr const char* kRegretEpisodes = "regret_episodes";
inline constexpr const char* kRegretOptimum = "regret_optimum";
// The fixed point's unit (statistics.hpp's, 2^-32): an episode's sum is rounded to it. Totals
// stay exact up to 2^53 units (2^21 in all).
inline constexpr double kRegretUnit = kSumUnit;

// Allocators of `allocators`, each measuring its losses against `mdp`'s optimum (see above). Each
// solves V*(s0) when made: ResourceLimitError when that needs more than `max_states` states.
AllocatorFactory with_regret(const Mdp& mdp, AllocatorFactory allocators, std::uint64_t max_states);

// The same acting while planning (SPEC §10): allocators of `allocators` measuring their losses
// against `mdp`'s optimum, with the same counters. Every move, a start or a step, is a decision;
// its loss is V*(s) - Q*(s, move) by ConcurrentSolver's exact values (memoised per thread, capped by
// `max_states`, 0: no cap; ResourceLimitError past it), added outside the decision's timing (a start's state
// is copied when it is chosen, its loss added after it). The identity above holds move by move, so
// the estimate means the same: V*(s0) - V^pi(s0) of the concurrent optimum and the allocator's
// concurrent policy. Each solves V*(s0) when made.
ConcurrentAllocatorFactory with_regret(const ConcurrentMdp& mdp, ConcurrentAllocatorFactory allocators,
                                       std::uint64_t max_states);

struct RegretEstimate {
  double optimum = 0;  // V*(s0)
  double mean = 0;     // estimated V*(s0) - V^pi(s0)
  double ci95 = 0;     // half-width: 1.96 times the standard error over the episodes
  std::uint64_t episodes = 0;
};

// The estimate from a run's merged statistics; nullopt when they hold no regret counters.
std::optional<RegretEstimate> regret_estimate(const Statistics& statistics);

}  // namespace ontime
