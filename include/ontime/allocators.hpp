#pragma once
// Allocators by name, for command lines and experiment scripts.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/allocator.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/allocators/ppo.hpp"
#include "ontime/contiguous_success.hpp"
#include "ontime/mdp.hpp"

namespace ontime {

struct AllocatorOptions {
  Aggregation aggregation = Aggregation::sum;                 // dp-rerun (and its use as mcts rollout)
  std::size_t max_states = OptimalSolver::kDefaultMaxStates;  // optimal
  // mcts
  double exploration = 0.5;
  std::uint64_t iterations = 10'000;        // per decision
  std::optional<double> seconds;            // per decision; with `iterations`, whichever ends first
  std::size_t max_tree_bytes = std::size_t{1} << 30;
  std::string rollout = "random";           // "random" or the name of a stationary allocator
  // ppo: the trained policy (load_ppo_policy); required for "ppo".
  std::shared_ptr<const PpoPolicy> policy;
};

// Names accepted by make_allocator_factory, in the order of the paper's tables (optimal first).
std::vector<std::string> allocator_names();

// A factory of independent allocators of the named kind for `mdp` (which must outlive it).
// Precomputation (Eq. (1) tables, the optimal solve) happens here, once, and is shared.
// Throws UsageError for an unknown name, ResourceLimitError when `optimal` hits its cap.
AllocatorFactory make_allocator_factory(std::string_view name, const Mdp& mdp,
                                        const AllocatorOptions& options = {});

}  // namespace ontime
