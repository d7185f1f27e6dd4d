#pragma once
// Chain averaging: the instance a model without exogenous chains would plan with (SPEC §9). Each
// chain is replaced by one state, its mean occupancy over a horizon H: an execution that depends
// on a chain is drawn, when it starts, from the mixture of its per-state distributions weighted by
// how often the chain is in each state over steps 0..H from its start (H = D: the episode's
// horizon; a long H: the long-run mix, what a log of past waits gives); an action blocked in some
// states of a chain becomes one whose execution never meets the deadline (D + 1 steps) with the
// weight of those states. Expiry by step (`start_by`) is kept: a known time is not a process.
//
// What it is for: the chain-averaging baseline (the `averaged` allocator plans in this instance
// and acts in the real one), so that a comparison with chain-aware allocation isolates what
// observing the chains and the clock is worth. Executions are drawn when they start in both, as
// a queue's wait is seen only on arrival.
//
// Guarantees: the result has the same actions, skeletons, rewards, timed actions and restore
// layout as the input (only chains and distributions differ), so that a state of the input's MDP
// is a state of the result's once its chains' joint state is set to 0. A problem without chains
// is returned unchanged. Where two different chains meet in one action (its execution depends on
// one, another blocks it), they are taken as independent. Cost O(D * n^2) per chain of n states
// plus the actions' distributions (O(H * n^2) with a horizon H).

#include <cstdint>
#include <vector>

#include "ontime/model/exogenous_chain.hpp"
#include "ontime/model/problem.hpp"

namespace ontime {

// The mean of the chain's state distribution over steps 0..steps from state `from`:
// (1 / (steps + 1)) * sum_{t=0}^{steps} P(state at t = s | state at 0 = from), summed in a fixed
// order (the same bits on every machine). Throws UsageError as chain_distribution does.
std::vector<double> mean_occupancy(const ExogenousChain& chain, int from, std::int64_t steps);

// The name of the one state each chain keeps in average_chains.
inline constexpr const char* kAveragedChainState = "average";

// The problem with every chain averaged as above over steps 0..horizon (0: the deadline). Throws
// UsageError for a negative horizon, or if the result breaks a rule (it does not for a valid problem).
Problem average_chains(const Problem& problem, std::int64_t horizon = 0);

}  // namespace ontime
