#include "ontime/allocators/averaged.hpp"

#include <utility>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/chain_averaging.hpp"

namespace ontime {

AveragedPlan::AveragedPlan(const Problem& real_problem, std::int64_t horizon, std::size_t max_states)
    : problem(average_chains(real_problem, horizon)), mdp(problem) {
  auto solver = std::make_shared<OptimalSolver>(mdp, max_states);
  solver->solve(mdp.start());
  solved = std::move(solver);
}

AveragedAllocator::AveragedAllocator(std::shared_ptr<const AveragedPlan> plan)
    : plan_(std::move(plan)), follow_(plan_->mdp, plan_->solved) {}

int AveragedAllocator::choose(const State& state) {
  // Every chain of the averaged instance has one state, so its only joint state is 0; the other
  // fields mean the same in both instances (average_chains keeps actions, skeletons and slots).
  seen_ = state;
  seen_.chains = 0;
  return follow_.choose(seen_);
}

AllocatorKind averaged_kind() {
  return {
      .name = "averaged",
      .summary =
          "baseline with chains: the optimum of the instance with each chain averaged into static "
          "distributions, followed blind to the chains (optimal without chains)",
      .capabilities = {Capability::stationary, Capability::chains},
      .parameters = {Parameter::integer("max-states", OptimalSolver::kDefaultMaxStates, 1, Parameter::kNoLimit,
                                        "cap on the states the exact solver and the exact evaluation may hold"),
                     Parameter::integer("horizon", 0, 0, 1'000'000,
                                        "steps over which each chain's occupancy from its start is averaged (0: the "
                                        "deadline; long: the long-run mix)")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        std::shared_ptr<const AveragedPlan> plan = std::make_shared<AveragedPlan>(
            mdp.problem(), static_cast<std::int64_t>(parameters.integer("horizon")), parameters.integer("max-states"));
        return [plan] { return std::make_unique<AveragedAllocator>(plan); };
      },
      .needs = exact_solve_needs()};
}

}  // namespace ontime
