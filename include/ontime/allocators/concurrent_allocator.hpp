#pragma once
// Allocators that act while planning (SPEC §10): one move at a time, a start or a step.
//
// A ConcurrentAllocator is asked before every move of ConcurrentMdp: while the robot is idle it
// may start a refined action just after what the robot executed (a move that takes no time, after
// which it is asked again), or the planner spends the next step on one skeleton's next action (or
// idles) while the robot executes. It sees the state of SPEC §10 and nothing else. Like Allocator
// (allocator.hpp), it keeps what state it likes between moves, `begin_episode` resets it with the
// episode's seed, and one object serves one episode at a time.
//
// Every kind of the registry that acts while planning has a commit rule: when the robot starts an
// action, and so drops the skeletons not through it (allocator_registry.hpp, AllocatorKind). The
// kinds that choose a skeleton plan-first follow the eager rule of EagerCommitAllocator below.

#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>

#include "ontime/allocators/allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {

class ConcurrentAllocator {
 public:
  virtual ~ConcurrentAllocator() = default;

  // The kind's name, as the registry spells it.
  virtual std::string_view name() const noexcept = 0;
  // Starts a new episode; `seed` seeds any randomness of the episode.
  virtual void begin_episode(std::uint64_t seed) { (void)seed; }
  // The move in a running state (some skeleton live): a start the state allows
  // (ConcurrentMdp::startable) or a step on a live skeleton with work left, or kWait.
  virtual ConcurrentMdp::Move choose(const ConcurrentState& state) = 0;
  // The step that followed the last step chosen (starts are not reported: they reveal nothing).
  virtual void observe(const ConcurrentState& before, int choice, const ConcurrentState& after) {
    (void)before, (void)choice, (void)after;
  }
  // True when `choose` is a function of the state alone, so that ConcurrentSolver's policy mode
  // values it exactly.
  virtual bool is_stationary() const noexcept { return true; }
  // Adds this allocator's counters to `statistics`; most have none.
  virtual void collect_statistics(Statistics& statistics) const { (void)statistics; }
};

using ConcurrentAllocatorFactory = std::function<std::unique_ptr<ConcurrentAllocator>()>;

// The eager commit rule around a plan-first allocator (round-robin, greedy, first-found, thompson,
// dp, ...): what a planner does that acts as soon as it can. Before each step the plan-first
// allocator chooses a skeleton k from the state seen plan-first (plan_first_view); then, while
// the robot is idle and k's next action to execute is refined, the robot starts it; otherwise the
// planner refines k's next action. Once a live skeleton is refined in full, the robot runs it as
// soon as it can and the planner idles (ConcurrentMdp::run_complete_plan). A choice of a skeleton
// that is dropped or has nothing left to refine goes to the live skeleton with work left whose
// earliest finish is least (ties: lowest index).
// With exogenous chains or expiry (SPEC §9) the rule is the same, "as soon as it can" meaning as
// soon as the action may start (ConcurrentMdp::startable): while k's next action to execute is
// blocked the planner refines k, and while a complete plan's next action is blocked the planner
// idles; the plan-first allocator sees the timed plan-first view (plan_first_view).
// A stationary plan-first allocator is asked anew before every move (so the rule is stationary
// too); any other is asked once per step, its choice kept across the starts within the step, and
// observes each step plan-first.
// Cost: the plan-first allocator's decision plus O(K * A_max) to build its view.
class EagerCommitAllocator final : public ConcurrentAllocator {
 public:
  // Wraps `plan_first`, an allocator for mdp.plan_first_mdp(); `mdp` must outlive this object.
  EagerCommitAllocator(const ConcurrentMdp& mdp, std::unique_ptr<Allocator> plan_first);

  std::string_view name() const noexcept override { return plan_first_->name(); }
  void begin_episode(std::uint64_t seed) override;
  ConcurrentMdp::Move choose(const ConcurrentState& state) override;
  void observe(const ConcurrentState& before, int choice, const ConcurrentState& after) override;
  bool is_stationary() const noexcept override { return plan_first_->is_stationary(); }
  void collect_statistics(Statistics& statistics) const override { plan_first_->collect_statistics(statistics); }

 private:
  int skeleton_to_follow(const ConcurrentState& state);
  const ConcurrentMdp* mdp_;
  std::unique_ptr<Allocator> plan_first_;
  State view_, view_after_;  // scratch
  int kept_choice_ = -1;     // a non-stationary allocator's choice for the step at kept_time_
  int kept_time_ = -1;
};

// The live skeleton whose earliest finish (ConcurrentMdp::earliest_finish) is least, ties to the
// lowest index, among those with an action left to refine when `with_work_left`; -1 when there is
// none. Where the eager rule goes when its choice cannot be followed, and dp's devoted follower once
// its skeleton is dropped. O(K * A_max).
int soonest_skeleton(const ConcurrentMdp& mdp, const ConcurrentState& state, bool with_work_left);

// A factory of EagerCommitAllocator around the allocators `plan_first` makes (for
// mdp.plan_first_mdp()), chains and expiry (SPEC §9) included.
ConcurrentAllocatorFactory eager_commit_factory(const ConcurrentMdp& mdp, AllocatorFactory plan_first);

// Allocators that decide with a belief (other distributions for the same skeletons, SPEC §10
// "Beliefs"): each allocator `allocators` makes decides on `belief` (the ConcurrentMdp of the
// belief's problem) and is shown every state of the world's model as `belief` holds it
// (ConcurrentMdp::canonical), so that the skeletons it counts as hopeless are the ones its own
// distributions say are; the world's model should keep hopeless skeletons
// (HopelessSkeletons::kept), or its states would tell what only the world's distributions imply.
// Where `belief` counts every skeleton hopeless, the planner idles (ConcurrentMdp::kWait): no move
// is worth anything there by the allocator's model. With the world's own distributions as the
// belief, the moves are those of the allocators on the world's own model, state by state. `belief`
// must outlive the factory and what it makes. Cost: one copy and canonicalisation of the state per
// move, O(K * A_max + A), on top of the allocator's.
ConcurrentAllocatorFactory seen_by_belief(const ConcurrentMdp& belief, ConcurrentAllocatorFactory allocators);

// The state of SPEC §10 seen plan-first (SPEC §2), for a plan-first allocator: CT; per live
// skeleton its l_k and PT_k, and as ET_k the steps the robot still needs for its refined actions
// (ConcurrentMdp::robot_free less CT, at most D + 1), so that plan-first success from the view
// (CT' + ET <= D) implies success acting while planning; a dropped skeleton appears refined in full
// with ET_k = D + 1, which no plan-first rule chooses or counts as able to succeed.
// With chains or expiry (SPEC §9) it is the timed plan-first state: the chains' joint state, ET_k
// the static backlog (r and the refined executions after E; one drawn from a chain when it starts
// counts 0, as the plan-first Mdp counts it) and each refined timed action after E restored to the
// static backlog before it. A plan-first state has no executed prefix: a timed action the robot
// already started reads as starting now (restore 0) to a rule that values plans in the chains
// (round-robin and greedy read none of it). Writes into `view` (sized for the problem's
// skeletons and slots) without allocating.
void plan_first_view(const ConcurrentMdp& mdp, const ConcurrentState& state, State& view);

}  // namespace ontime
