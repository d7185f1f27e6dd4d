#include "ontime/allocators.hpp"

#include "ontime/allocators/dp.hpp"
#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/allocators/greedy.hpp"
#include "ontime/allocators/round_robin.hpp"
#include "ontime/error.hpp"

namespace ontime {

std::vector<std::string> allocator_names() {
  return {"optimal", "dp", "dp-rerun", "round-robin", "greedy"};
}

AllocatorFactory make_allocator_factory(std::string_view name, const Mdp& mdp, const AllocatorOptions& options) {
  const Mdp* model = &mdp;
  if (name == "optimal") {
    auto solver = std::make_shared<OptimalSolver>(mdp, options.max_states);
    solver->solve(mdp.start());
    std::shared_ptr<const OptimalSolver> solved = std::move(solver);
    return [model, solved] { return std::make_unique<OptimalAllocator>(*model, solved); };
  }
  if (name == "dp") {
    const int chosen = DpAllocator(mdp).chosen_skeleton();
    return [chosen] { return std::make_unique<DpAllocator>(chosen); };
  }
  if (name == "dp-rerun") {
    auto table = std::make_shared<const ContiguousSuccessTable>(mdp, options.aggregation);
    return [model, table] { return std::make_unique<DpRerunAllocator>(*model, table); };
  }
  if (name == "greedy") {
    return [model] { return std::make_unique<GreedyAllocator>(*model); };
  }
  if (name == "round-robin") {
    const int count = mdp.skeleton_count();
    return [count] { return std::make_unique<RoundRobinAllocator>(count); };
  }
  std::string known;
  for (const std::string& candidate : allocator_names()) known += (known.empty() ? "" : ", ") + candidate;
  throw UsageError("unknown solver '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace ontime
