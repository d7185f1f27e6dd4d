#include "ontime/allocators/greedy.hpp"

#include <limits>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/chain_averaging.hpp"

namespace ontime {
namespace {

int fastest_on_average(const Problem& problem) {
  int best = 0;
  double best_mean = std::numeric_limits<double>::infinity();
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    double mean = 0;
    for (const int action : problem.skeleton(k)) {
      const Action& model = problem.action(action);
      // A chain-dependent execution of an averaged instance has one state: its mixture.
      const Distribution& execution =
          model.execution_chain.empty() ? model.execution : model.execution_by_state.front();
      mean += model.planning.mean_finite() + execution.mean_finite();
    }
    if (mean < best_mean) {
      best_mean = mean;
      best = k;
    }
  }
  return best;
}

}  // namespace

// With chains (SPEC §9) the means are those of the averaged instance (chain_averaging.hpp): a
// chain-dependent execution's mean over the chain's occupancy from its start, and a blocked
// action's blocked share as D + 1 steps. A mean is all greedy reads, and that is the mean a
// static model shows.
GreedyAllocator::GreedyAllocator(const Mdp& mdp)
    : chosen_(fastest_on_average(mdp.problem().has_chains() ? average_chains(mdp.problem()) : mdp.problem())) {}

AllocatorKind greedy_kind() {
  return {.name = "greedy",
          .summary = "baseline: the skeleton with the least mean planning and execution time, refined throughout",
          .capabilities = {Capability::stationary, Capability::chains},
          .parameters = {},
          .make = [](const Mdp& mdp, const ParameterReader&) -> AllocatorFactory {
            return [model = &mdp] { return std::make_unique<GreedyAllocator>(*model); };
          },
          .commit_rule = kEagerCommitRule};
}

}  // namespace ontime
