#pragma once
// `dp-rerun` (the paper's DP_Rerun, Algorithm 1, SPEC §3).
//
// Before every step, evaluates PS(k, l_k, CT, ET_k) of Eq. (1) for every skeleton with
// actions left, conditioning the current action's planning time on the PT_k steps already
// spent, and spends the step on the largest (ties: lowest index). Aggregation `sum` by
// default (reproduces Table I); `max` and `self` are selectable.
// No optimality guarantee; in the paper's instances it comes close to the optimum.
// Cost: the Eq. (1) tables are built once per problem and shared. A decision reads PS from a
// table for every skeleton with nothing spent on its current action, and computes the dot
// product (at most D - CT - ET_k terms) only for the others whose table bound could beat the
// best so far: O(K) with a few dot products, no allocation (see docs/performance.md). With
// backtracking (SPEC §7) PS is its extension (backtracking_success.hpp), memoised per allocator:
// O(K) hash lookups once the values an episode needs are known.
// With chains or expiry (SPEC §9) PS is the exact expected reward of refining the skeleton alone
// from the state, the chains read now and modelled from there (timed_contiguous_success.hpp):
// Eq. (1) has no form for a chain, and that is the value Eq. (1) stands for with aggregation
// `self`, the only one taken then (the default becomes `self`). Memoised per allocator as well.

#include <memory>
#include <optional>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/solve/backtracking_success.hpp"
#include "ontime/solve/concurrent_contiguous_success.hpp"
#include "ontime/solve/concurrent_devoted_optimum.hpp"
#include "ontime/solve/contiguous_success.hpp"
#include "ontime/solve/timed_contiguous_success.hpp"

namespace ontime {

class DpRerunAllocator final : public Allocator {
 public:
  // No aggregation: `sum`, or `self` with chains or expiry; another with them throws UsageError.
  explicit DpRerunAllocator(const Mdp& mdp, std::optional<Aggregation> aggregation = std::nullopt);
  DpRerunAllocator(const Mdp& mdp, std::shared_ptr<const ContiguousSuccessTable> table);

  // With backtracking (SPEC §7): Eq. (1)'s extension, memoised by this allocator as it decides.
  DpRerunAllocator(const Mdp& mdp, std::unique_ptr<BacktrackingSuccess> backtracking);

  // With chains or expiry (SPEC §9): the value of refining each skeleton alone, memoised by this
  // allocator as it decides.
  DpRerunAllocator(const Mdp& mdp, std::unique_ptr<TimedContiguousSuccess> timed);

  std::string_view name() const noexcept override { return "dp-rerun"; }
  int choose(const State& state) override;

  // Eq. (1)'s tables (problems without backtracking).
  const ContiguousSuccessTable& table() const noexcept { return *table_; }

 private:
  // With backtracking or chains: the largest memoised value over the skeletons with work left.
  int choose_memoised(const State& state);

  const Mdp* mdp_;
  std::shared_ptr<const ContiguousSuccessTable> table_;
  std::unique_ptr<BacktrackingSuccess> backtracking_;
  std::unique_ptr<TimedContiguousSuccess> timed_;
  std::vector<int> worked_on_;  // skeletons with steps spent on their current action (scratch)
};

// `dp-rerun` when the robot acts while planning (SPEC §10), with the eager commit rule. Before
// every move it values each live skeleton by Eq. (1) for acting while planning
// (ConcurrentContiguousSuccess: the robot runs the skeleton's refined actions back to back while the
// rest is planned) and follows the best (ties: lowest index): while the robot is idle and the
// best skeleton's next action to execute is refined, it starts it (committing to the skeletons
// through it); otherwise it spends the step on the best skeleton's next action, or waits when that
// skeleton is refined in full (ConcurrentContiguousSuccess::devoted_move). With backtracking
// (SPEC §7) Eq. (1) has its give-up term. With chains or expiry (SPEC §9), where waiting for a chain
// may pay, a skeleton is worth its devoted optimum from the state (ConcurrentDevotedOptimum: the
// best a policy refining it alone can earn, choosing when the robot starts each action; the chains
// read now and modelled from there), aggregation `self` only, and the move is that optimum's: the
// robot starts an action when starting is worth more than waiting, by that value.
// Stationary: ConcurrentSolver's policy mode values it exactly.
// Cost: per move, one Eq. (1) query per live skeleton: a sum over at most D - CT planning steps of
// memoised values (memoised per allocator, so each thread's allocator has its own memo); with
// chains or expiry a lookup once the devoted states from there are solved.
class ConcurrentDpRerunAllocator final : public ConcurrentAllocator {
 public:
  // The allocator for `mdp`, Eq. (1) combining sharing skeletons by `aggregation` (none: sum,
  // Table I's; with chains or expiry self, the only one taken there: another throws UsageError).
  explicit ConcurrentDpRerunAllocator(const ConcurrentMdp& mdp, std::optional<Aggregation> aggregation = std::nullopt);
  std::string_view name() const noexcept override { return "dp-rerun"; }
  // The move in a state where some skeleton is live: a start or a step, as above.
  ConcurrentMdp::Move choose(const ConcurrentState& state) override;

 private:
  const ConcurrentMdp* mdp_;
  ConcurrentContiguousSuccess values_;
  std::unique_ptr<ConcurrentDevotedOptimum> devoted_;  // with chains or expiry
};

}  // namespace ontime
