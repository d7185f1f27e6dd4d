#include "ontime/allocators.hpp"

#include "ontime/allocators/dp.hpp"
#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/allocators/greedy.hpp"
#include "ontime/allocators/mcts.hpp"
#include "ontime/allocators/round_robin.hpp"
#include "ontime/error.hpp"

namespace ontime {

std::vector<std::string> allocator_names() {
  return {"optimal", "mcts", "dp", "dp-rerun", "ppo", "round-robin", "greedy"};
}

AllocatorFactory make_allocator_factory(std::string_view name, const Mdp& mdp, const AllocatorOptions& options) {
  const Mdp* model = &mdp;
  if (name == "optimal") {
    auto solver = std::make_shared<OptimalSolver>(mdp, options.max_states);
    solver->solve(mdp.start());
    std::shared_ptr<const OptimalSolver> solved = std::move(solver);
    return [model, solved] { return std::make_unique<OptimalAllocator>(*model, solved); };
  }
  if (name == "mcts") {
    MctsOptions mcts;
    mcts.exploration = options.exploration;
    mcts.budget = options.seconds ? DecisionBudget::either(options.iterations, *options.seconds)
                                  : DecisionBudget::iterations(options.iterations);
    mcts.max_tree_bytes = options.max_tree_bytes;
    if (options.rollout != "random") {
      if (options.rollout == "mcts") throw UsageError("mcts cannot be its own rollout policy");
      mcts.rollout = make_allocator_factory(options.rollout, mdp, options);
    }
    // Probe the options once here, so that a bad rollout policy fails before any episode.
    MctsAllocator probe(mdp, mcts);
    return [model, mcts] { return std::make_unique<MctsAllocator>(*model, mcts); };
  }
  if (name == "dp") {
    const int chosen = DpAllocator(mdp).chosen_skeleton();
    return [chosen] { return std::make_unique<DpAllocator>(chosen); };
  }
  if (name == "dp-rerun") {
    auto table = std::make_shared<const ContiguousSuccessTable>(mdp, options.aggregation);
    return [model, table] { return std::make_unique<DpRerunAllocator>(*model, table); };
  }
  if (name == "ppo") {
    if (!options.policy) {
      throw UsageError("ppo needs a trained policy: train one with 'ontime train INSTANCE --solver ppo --out FILE' "
                       "and pass it with --policy FILE");
    }
    PpoAllocator probe(mdp, options.policy);  // fails here when the policy is for another instance
    const std::shared_ptr<const PpoPolicy> policy = options.policy;
    return [model, policy] { return std::make_unique<PpoAllocator>(*model, policy); };
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
