#include "ontime/allocators/averaged.hpp"

#include <algorithm>
#include <utility>
#include <vector>

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

ConcurrentAveragedPlan::ConcurrentAveragedPlan(const Problem& real_problem, std::int64_t horizon, std::size_t state_cap)
    : problem(average_chains(real_problem, horizon)), mdp(problem), max_states(state_cap) {
  auto solver = std::make_shared<ConcurrentSolver>(mdp, max_states);
  solver->solve(mdp.start());
  solved = std::move(solver);
}

ConcurrentAveragedAllocator::ConcurrentAveragedAllocator(const ConcurrentMdp& mdp,
                                                         std::shared_ptr<const ConcurrentAveragedPlan> plan)
    : mdp_(&mdp), plan_(std::move(plan)), follow_(plan_->mdp, plan_->solved, plan_->max_states) {}

bool ConcurrentAveragedAllocator::allowed(const ConcurrentState& state, const ConcurrentMdp::Move& move) const {
  if (move.is_start()) {
    const std::vector<int> startable = mdp_->startable(state);
    return std::binary_search(startable.begin(), startable.end(), move.start);
  }
  if (ConcurrentMdp::time(state) >= mdp_->deadline()) return false;
  const int k = move.refine;
  return k == ConcurrentMdp::kWait ||
         (ConcurrentMdp::is_live(state, k) && ConcurrentMdp::refined(state, k) < mdp_->problem().skeleton_length(k));
}

double ConcurrentAveragedAllocator::averaged_value(const ConcurrentState& seen) {
  if (const std::optional<double> value = plan_->solved->value(seen)) return *value;
  if (!values_) values_ = std::make_unique<ConcurrentSolver>(plan_->mdp, plan_->max_states);
  return values_->solve(seen);
}

ConcurrentMdp::Move ConcurrentAveragedAllocator::choose(const ConcurrentState& state) {
  // Without chains the averaged instance is the instance: the optimum's move, ties and all.
  if (!mdp_->problem().has_chains()) return follow_.choose(state);
  const ConcurrentMdp& averaged = plan_->mdp;
  // The chains' word (the fourth, SPEC §10's layout) is 0 in the averaged model, whose chains have
  // one state each; the rest means the same there, once canonical in the averaged model (an
  // execution it expects slower may leave a skeleton unable to finish there).
  ConcurrentState seen = state;
  seen[3] = 0;
  seen = averaged.on_clock(seen, {.time = ConcurrentMdp::time(state), .robot_left = ConcurrentMdp::robot_left(state)});
  // The averaged values Q of the moves the real state allows (a start a chain blocks now is not).
  std::vector<std::pair<ConcurrentMdp::Move, double>> values;
  double best = -1.0;
  for (const ConcurrentMdp::Move& candidate : averaged.useful_moves(seen)) {
    if (!allowed(state, candidate)) continue;
    const double q =
        move_value(averaged, seen, candidate, [&](const ConcurrentState& next) { return averaged_value(next); });
    values.emplace_back(candidate, q);
    best = std::max(best, q);
  }
  // Ties: a start first (the lowest action), else the first in ConcurrentSolver's order.
  const ConcurrentMdp::Move* chosen = nullptr;
  for (const auto& [candidate, q] : values) {
    if (q < best - ConcurrentSolver::kTieTolerance) continue;
    if (candidate.is_start()) return candidate;
    if (chosen == nullptr) chosen = &candidate;
  }
  // Nothing allowed: the planner idles (as the optimum does where no move is left).
  return chosen != nullptr ? *chosen : ConcurrentMdp::Move{};
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
      .needs = exact_solve_needs(),
      .commit_rule =
          "the averaged instance's concurrent optimum, blind to the chains: starts an action when starting "
          "is worth at least planning on there; where a chain blocks that start now, waits",
      .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader& parameters) -> ConcurrentAllocatorFactory {
        std::shared_ptr<const ConcurrentAveragedPlan> plan = std::make_shared<ConcurrentAveragedPlan>(
            mdp.problem(), static_cast<std::int64_t>(parameters.integer("horizon")), parameters.integer("max-states"));
        return [model = &mdp, plan] { return std::make_unique<ConcurrentAveragedAllocator>(*model, plan); };
      }};
}

}  // namespace ontime
