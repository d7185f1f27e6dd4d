#pragma once
// `thompson`: Thompson-sampling-style allocation.
//
// Before every step, draws one possible world from the model: for every action still ahead
// of a skeleton that can still succeed, a planning time (the current action's conditioned on
// the PT_k steps already spent on it: T - PT_k given T > PT_k) and an execution time; an
// action shared by several skeletons is drawn once. In that world skeleton k would finish at
// CT + ET_k + the drawn planning and execution times of its remaining actions; the step goes
// to the skeleton that would finish soonest (ties: lowest index; a draw of "never" is later
// than any finite time). If no skeleton can still succeed, the lowest-index skeleton with
// work left (any choice is as good).
//
// It is randomised (one draw per decision from the episode's seed), so its success is
// sampled, not computed exactly. It spends effort where a plausible world says the deadline
// is met soonest, which explores a skeleton in proportion to the chance that it is the
// fastest, instead of committing to one estimate (dp-rerun) or searching (mcts).
// With rewards (SPEC §8) the step goes to the skeleton whose drawn finish earns the most
// (one that misses the deadline in the draw earns nothing), the soonest among equals; with
// every reward 1 that is the soonest, as above.
// No optimality guarantee.
// Cost per decision: one inverse-CDF draw (a binary search over D + 1 steps) per remaining
// action of the live skeletons, O(sum of remaining actions * log D); no allocation (the
// per-action draws live in arrays sized once).
//
// With backtracking (SPEC §7) a world is drawn skeleton by skeleton as its refinement would go:
// each attempt's outcome (a motion at t with its execution, or a backtrack at t to a culprit,
// after which the refinement goes on from the culprit with the execution before it restored),
// until the skeleton is refined or the deadline passes; the step goes to the skeleton finishing
// soonest in its draw. O(D) draws per skeleton at most.
//
// With chains or expiry (SPEC §9) a skeleton's draw is its refinement alone as the MDP draws it
// (planning, static executions and the chains' steps, Mdp::sample_observation), until it completes
// a plan or the episode is lost. The chains' path while the plan executes is not drawn: the plan
// is worth its expected reward over those paths (Mdp::success_reward), and a lost draw ranks
// below any completed plan. The step goes to the skeleton whose draw is worth the most, the
// soonest completed among equals.
// Every skeleton is drawn on its own (an action two skeletons share is drawn for each), and no
// draw waits for the chains. O(D) draws per skeleton at most.

#include <cstdint>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/util/random.hpp"

namespace ontime {

class ThompsonAllocator final : public Allocator {
 public:
  // The Mdp must outlive the allocator.
  explicit ThompsonAllocator(const Mdp& mdp);

  std::string_view name() const noexcept override { return "thompson"; }
  void begin_episode(std::uint64_t seed) override { generator_ = SplitMix64(seed); }
  int choose(const State& state) override;
  bool is_stationary() const noexcept override { return false; }

 private:
  // Planning plus execution steps of `action` in this decision's draw (kNever: never), the
  // planning time conditioned on `spent` steps already spent on it.
  std::int64_t drawn_time(int action, Steps spent);
  // With backtracking: when skeleton k would finish in one draw of its refinement (kNever-like
  // maximum when past the deadline).
  std::int64_t drawn_finish_with_backtracking(const State& state, int k);
  // With chains or expiry: one draw of skeleton k refined alone, and the choice from such draws.
  struct Draw {
    double worth;            // the plan's expected reward, -1 when the draw loses the episode
    std::int64_t completed;  // the step its refinement completed (kNever-like maximum when lost)
  };
  Draw drawn_plan_with_chains(const State& state, int k);
  int choose_with_chains(const State& state);
  // Whether skeleton k, finishing at `finish` in the drawn world, beats `best` finishing at
  // `best_finish` (best < 0: there is none yet).
  bool better(int k, std::int64_t finish, int best, std::int64_t best_finish) const;

  const Mdp* mdp_;
  SplitMix64 generator_{0};
  std::uint64_t decision_ = 0;                  // numbers the draws: an action is drawn once per decision
  std::vector<std::uint64_t> drawn_at_;         // per action: the decision of its last draw
  std::vector<std::int64_t> drawn_time_;        // per action: its draw in that decision
  std::vector<std::int64_t> execution_before_;  // backtracking: ET before each position (scratch)
  State scratch_;                               // chains: the state of one skeleton's draw
};

}  // namespace ontime
