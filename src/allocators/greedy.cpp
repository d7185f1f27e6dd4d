#include "ontime/allocators/greedy.hpp"

#include <limits>

#include "ontime/allocators/allocator_registry.hpp"

namespace ontime {
namespace {

int fastest_on_average(const Problem& problem) {
  int best = 0;
  double best_mean = std::numeric_limits<double>::infinity();
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    double mean = 0;
    for (const int action : problem.skeleton(k)) {
      mean += problem.action(action).planning.mean_finite() + problem.action(action).execution.mean_finite();
    }
    if (mean < best_mean) {
      best_mean = mean;
      best = k;
    }
  }
  return best;
}

}  // namespace

GreedyAllocator::GreedyAllocator(const Mdp& mdp) : chosen_(fastest_on_average(mdp.problem())) {}

AllocatorKind greedy_kind() {
  return {.name = "greedy",
          .summary = "baseline: the skeleton with the least mean planning and execution time, refined throughout",
          .capabilities = {Capability::stationary},
          .parameters = {},
          .make = [](const Mdp& mdp, const ParameterReader&) -> AllocatorFactory {
            return [model = &mdp] { return std::make_unique<GreedyAllocator>(*model); };
          }};
}

}  // namespace ontime
