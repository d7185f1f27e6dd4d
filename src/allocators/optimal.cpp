#include "ontime/allocators/optimal.hpp"

#include "ontime/allocators/allocator_registry.hpp"

namespace ontime {

OptimalAllocator::OptimalAllocator(const Mdp& mdp, std::size_t max_states) : mdp_(&mdp) {
  auto solver = std::make_shared<OptimalSolver>(mdp, max_states);
  solver->solve(mdp.start());
  solved_ = std::move(solver);
}

OptimalAllocator::OptimalAllocator(const Mdp& mdp, std::shared_ptr<const OptimalSolver> solved)
    : mdp_(&mdp), solved_(std::move(solved)) {}

int OptimalAllocator::choose(const State& state) {
  if (const auto choice = solved_->best_choice(state)) return *choice;
  if (private_) {
    if (const auto choice = private_->best_choice(state)) return *choice;
  } else {
    private_ = std::make_unique<OptimalSolver>(*mdp_, solved_->max_states());
  }
  private_->solve(state);
  // No choice at all means no skeleton can succeed; any choice is as good as another.
  return private_->best_choice(state).value_or(0);
}

ConcurrentOptimalAllocator::ConcurrentOptimalAllocator(const ConcurrentMdp& mdp,
                                                       std::shared_ptr<const ConcurrentSolver> solved,
                                                       std::size_t max_states)
    : mdp_(&mdp), solved_(std::move(solved)), max_states_(max_states) {}

ConcurrentMdp::Move ConcurrentOptimalAllocator::choose(const ConcurrentState& state) {
  if (mdp_->certain_success(state)) return mdp_->run_complete_plan(state);
  if (const auto move = solved_->best_move(state)) return *move;
  if (!private_) private_ = std::make_unique<ConcurrentSolver>(*mdp_, max_states_);
  if (const auto move = private_->best_move(state)) return *move;
  private_->solve(state);
  // No move at all means no skeleton can finish; any move is as good as another.
  return private_->best_move(state).value_or(ConcurrentMdp::Move{});
}

std::size_t max_states_of(const ParameterValues& values) {
  const AllocatorKind& optimal = allocator_registry().find("optimal");
  for (const Parameter& parameter : optimal.parameters) {
    if (const std::string* value = values.find(parameter.name)) parameter.check(*value);
  }
  return ParameterReader(optimal, values).integer("max-states");
}

AllocatorKind optimal_kind() {
  return {
      .name = "optimal",
      .summary = "exact expectimax over the reachable MDP: the highest success probability any allocator can reach",
      .capabilities = {Capability::stationary, Capability::optimal, Capability::chains},
      .parameters = {Parameter::integer("max-states", OptimalSolver::kDefaultMaxStates, 1, Parameter::kNoLimit,
                                        "cap on the states the exact solver and the exact evaluation may hold")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        auto solver = std::make_shared<OptimalSolver>(mdp, parameters.integer("max-states"));
        solver->solve(mdp.start());
        std::shared_ptr<const OptimalSolver> solved = std::move(solver);
        return [model = &mdp, solved] { return std::make_unique<OptimalAllocator>(*model, solved); };
      },
      .needs = exact_solve_needs(),
      .commit_rule = "the optimum's: starts an action exactly when starting is worth more than planning on",
      .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader& parameters) -> ConcurrentAllocatorFactory {
        const std::size_t max_states = parameters.integer("max-states");
        auto solver = std::make_shared<ConcurrentSolver>(mdp, max_states);
        solver->solve(mdp.start());
        std::shared_ptr<const ConcurrentSolver> solved = std::move(solver);
        return [model = &mdp, solved, max_states] {
          return std::make_unique<ConcurrentOptimalAllocator>(*model, solved, max_states);
        };
      }};
}

AllocatorNeeds exact_solve_needs() {
  return {.memory = {.parameter = "max-states",
                     .bytes =
                         [](const Problem& problem, const ParameterReader& parameters) {
                           const std::size_t max_states = parameters.integer("max-states");
                           return problem.acting() == Acting::concurrent
                                      ? ConcurrentSolver::max_bytes(problem, max_states)
                                      : OptimalSolver::max_bytes(problem, max_states);
                         },
                     .per_allocator = false}};
}

}  // namespace ontime
