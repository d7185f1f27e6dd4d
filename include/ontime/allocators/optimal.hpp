#pragma once
// `optimal`: the allocator that follows the exact solver's choice (solve/optimal_solver.hpp),
// the highest success probability any allocator can reach.
//
// Guarantees: those of OptimalSolver. Cost: one solve from the start state, shared by every
// allocator a factory makes (time and memory linear in the reachable states, up to the
// `max-states` cap); a choice afterwards is one hash lookup.

#include <cstddef>
#include <memory>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/solve/optimal_solver.hpp"

namespace ontime {

class ParameterValues;

// The state cap `max-states` (the optimal kind's parameter, also the cap of exact evaluation)
// given in `values`, or its default. Throws UsageError for a bad value.
std::size_t max_states_of(const ParameterValues& values);

struct AllocatorNeeds;
// What a kind that solves its instance exactly once, under its `max-states` parameter, needs: the
// memory of OptimalSolver::max_bytes, shared by its allocators (the optimal and averaged kinds).
AllocatorNeeds exact_solve_needs();

// Follows the optimal policy. The solve from the start state is done once and shared by all
// allocators a factory makes; a state outside it (a session resumed elsewhere) is solved on
// demand by a private solver.
class OptimalAllocator final : public Allocator {
 public:
  // Solves from the start state; throws ResourceLimitError at the cap.
  OptimalAllocator(const Mdp& mdp, std::size_t max_states = OptimalSolver::kDefaultMaxStates);
  OptimalAllocator(const Mdp& mdp, std::shared_ptr<const OptimalSolver> solved);

  std::string_view name() const noexcept override { return "optimal"; }
  int choose(const State& state) override;

 private:
  const Mdp* mdp_;
  std::shared_ptr<const OptimalSolver> solved_;
  std::unique_ptr<OptimalSolver> private_;
};

// `optimal` acting while planning (SPEC §10): follows ConcurrentSolver's best move, and at a
// certain success (ConcurrentMdp::certain_success, where the solver stops) runs the complete plan
// at once (ConcurrentMdp::run_complete_plan). With rewards, chains or expiry a complete plan is
// not a certain success and the solver's move is followed there too. Its commit rule is the
// optimum's: the robot starts an action exactly when starting is worth more than planning on
// while it waits. The solve from the start is shared by the allocators of one factory; a state
// outside it (a session driven elsewhere by its caller) is solved on demand by a private solver
// under the same cap. Cost: one hash lookup per move.
class ConcurrentOptimalAllocator final : public ConcurrentAllocator {
 public:
  // Follows `solved` (which has solved mdp.start()); `max_states` caps a private solve.
  ConcurrentOptimalAllocator(const ConcurrentMdp& mdp, std::shared_ptr<const ConcurrentSolver> solved,
                             std::size_t max_states);
  std::string_view name() const noexcept override { return "optimal"; }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override;

 private:
  const ConcurrentMdp* mdp_;
  std::shared_ptr<const ConcurrentSolver> solved_;
  std::size_t max_states_;
  std::unique_ptr<ConcurrentSolver> private_;
};

}  // namespace ontime
