#pragma once
// `averaged`: the chain-averaging baseline (SPEC §9). It plans as a model without exogenous chains
// would: it solves exactly the instance with every chain averaged into static distributions
// (model/chain_averaging.hpp: each chain's mean occupancy from its start over `horizon` steps, by
// default the deadline) and follows that optimum in the real instance, blind to the chains'
// states. Waiting for a chain to change is therefore never worth it to it, though expiry at a
// known step is still seen (the clock is part of the state). Comparing it with `optimal` measures
// what observing the chains is worth.
//
// Guarantees: without chains it is `optimal` (the averaged instance is the instance itself); with
// chains its exact value in the real instance is at most the optimum. It is stationary, so exact
// evaluation applies. Cost: one exact solve of the averaged instance, shared by every allocator a
// factory makes (its states: those of the instance with one state per chain, up to `max-states`);
// a choice is then one hash lookup after copying the state.

#include <cstddef>
#include <cstdint>
#include <memory>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/solve/optimal_solver.hpp"

namespace ontime {

// The averaged instance, its MDP and its optimum from the start, solved once.
struct AveragedPlan {
  // Solves the instance of `real_problem` averaged over `horizon` steps (0: its deadline); throws
  // ResourceLimitError at the cap.
  AveragedPlan(const Problem& real_problem, std::int64_t horizon, std::size_t max_states);
  // (mdp points into problem: the plan stays where it was made.)
  AveragedPlan(const AveragedPlan&) = delete;
  AveragedPlan& operator=(const AveragedPlan&) = delete;
  AveragedPlan(AveragedPlan&&) = delete;
  AveragedPlan& operator=(AveragedPlan&&) = delete;
  ~AveragedPlan() = default;

  Problem problem;
  Mdp mdp;
  std::shared_ptr<const OptimalSolver> solved;
};

class AveragedAllocator final : public Allocator {
 public:
  // Follows the optimum of `plan`, shared with the other allocators of its factory.
  explicit AveragedAllocator(std::shared_ptr<const AveragedPlan> plan);

  std::string_view name() const noexcept override { return "averaged"; }
  // The averaged optimum's choice in `state` seen without its chains (joint state 0).
  int choose(const State& state) override;

 private:
  std::shared_ptr<const AveragedPlan> plan_;
  OptimalAllocator follow_;
  State seen_;  // the state without its chains (reused: no allocation per decision)
};

}  // namespace ontime
