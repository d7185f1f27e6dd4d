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
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/solve/concurrent_solver.hpp"
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

// Acting while planning (SPEC §10): the averaged instance, its ConcurrentMdp and its concurrent
// optimum from the start, solved once.
struct ConcurrentAveragedPlan {
  // Solves the instance of `real_problem` averaged over `horizon` steps (0: its deadline), acting
  // while planning, holding at most `state_cap` states; throws ResourceLimitError past them.
  ConcurrentAveragedPlan(const Problem& real_problem, std::int64_t horizon, std::size_t state_cap);
  // (mdp points into problem: the plan stays where it was made.)
  ConcurrentAveragedPlan(const ConcurrentAveragedPlan&) = delete;
  ConcurrentAveragedPlan& operator=(const ConcurrentAveragedPlan&) = delete;
  ConcurrentAveragedPlan(ConcurrentAveragedPlan&&) = delete;
  ConcurrentAveragedPlan& operator=(ConcurrentAveragedPlan&&) = delete;
  ~ConcurrentAveragedPlan() = default;

  Problem problem;
  ConcurrentMdp mdp;
  std::size_t max_states;
  std::shared_ptr<const ConcurrentSolver> solved;
};

// `averaged` acting while planning (its commit rule): the concurrent optimum of the averaged
// instance, followed blind to the chains. A state of the real ConcurrentMdp is read as the
// averaged one's with the chains' word set to 0 (the averaged chains have one state) and brought
// to the averaged model's canonical form (ConcurrentMdp::on_clock): CT, r, E, the refined actions,
// PT and every known execution mean the same in both (average_chains keeps the actions, skeletons
// and slots). An action whose execution a chain draws when it starts is drawn when it starts in
// the averaged instance too, from its averaged distribution (average_chains keeps its chain, with
// one state): refined and not started it is kDrawnAtStart in both states, and once started its
// draw is in r in both. So the averaged optimum plans with the averaged distribution of every
// execution it has not seen start, and with each one it has seen. An action a chain may block
// (and whose execution no chain draws) has its execution revealed with its motion in both; the
// real one is never the averaged model's "too slow" of a block, so once such a motion is found
// the averaged model counts on it, and the block is met only when the start is refused.
//
// The move is the best one the real state allows by the averaged model's values Q (V* of the
// averaged model at the successors). What the real state may refuse is a start that a chain's
// state blocks now (the averaged instance sees a block as an execution too slow, with the block's
// weight; expiry by step it sees as the real one does): then the robot waits, the planner refining
// what the averaged optimum values most meanwhile. Ties go to a start (the lowest action), else
// to the first move in ConcurrentSolver's order: where the averaged model sees nothing to gain by
// waiting the robot starts at once, as a planner blind to the chains would (the solver's order,
// starting only when starting is worth more, would put off every start that costs nothing to put
// off in the averaged model, up to the last step, and give the chains that long to block it).
//
// Guarantees: without chains it is the `optimal` allocator (ConcurrentOptimalAllocator), ties and
// all (the averaged instance is the instance itself); it is stationary, so its exact value
// (evaluate_exactly) is at most the concurrent optimum. Cost: one exact solve of the averaged
// instance shared by the allocators of a factory; with chains a move then costs the successors'
// values of every useful move of the averaged model (hash lookups into the shared solve, else a
// private one kept across the episodes, capped by max_states).
class ConcurrentAveragedAllocator final : public ConcurrentAllocator {
 public:
  // Acts in `mdp` (the real instance's; it must outlive this object) following `plan`'s optimum.
  ConcurrentAveragedAllocator(const ConcurrentMdp& mdp, std::shared_ptr<const ConcurrentAveragedPlan> plan);

  std::string_view name() const noexcept override { return "averaged"; }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override;

 private:
  // Whether the real state allows `move`.
  bool allowed(const ConcurrentState& state, const ConcurrentMdp::Move& move) const;
  // V* of a state of the averaged model.
  double averaged_value(const ConcurrentState& seen);

  const ConcurrentMdp* mdp_;
  std::shared_ptr<const ConcurrentAveragedPlan> plan_;
  ConcurrentOptimalAllocator follow_;         // without chains
  std::unique_ptr<ConcurrentSolver> values_;  // the averaged values the shared solve lacks
};

}  // namespace ontime
