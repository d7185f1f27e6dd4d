#include "ontime/allocators/concurrent_allocator.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"

namespace ontime {

void plan_first_view(const ConcurrentMdp& mdp, const ConcurrentState& state, State& view) {
  const Problem& problem = mdp.problem();
  const std::int64_t too_late = std::int64_t{mdp.deadline()} + 1;
  const bool timed = mdp.is_timed();
  view.time = static_cast<std::uint16_t>(ConcurrentMdp::time(state));
  if (timed) {
    view.chains = ConcurrentMdp::chains(state);
    // The timed slots follow the culprit slots (Problem::timed_slot).
    const auto first = static_cast<std::size_t>(problem.culprit_slot_count());
    const std::size_t end = first + static_cast<std::size_t>(problem.timed_slot_count());
    for (std::size_t slot = first; slot < end; ++slot) view.restore[slot] = 0;
  }
  // What a refined action after E adds to the robot's backlog in the view: its execution; with
  // chains or expiry a chain-dependent one adds nothing, as the plan-first Mdp counts it (drawn
  // when it starts, SPEC §9).
  const auto backlog_of = [&](int action) -> std::int64_t {
    const std::uint16_t word = mdp.execution(state, action);
    return word == ConcurrentMdp::kDrawnAtStart ? 0 : std::int64_t{word};
  };
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    const auto slot = static_cast<std::size_t>(k);
    if (!ConcurrentMdp::is_live(state, k)) {
      view.refined[slot] = static_cast<std::uint8_t>(problem.skeleton_length(k));
      view.spent[slot] = 0;
      view.execution[slot] = static_cast<std::uint16_t>(too_late);
      continue;
    }
    view.refined[slot] = static_cast<std::uint8_t>(ConcurrentMdp::refined(state, k));
    view.spent[slot] = static_cast<std::uint16_t>(mdp.spent(state, k));
    std::int64_t robot_needs = mdp.robot_free(state, k) - ConcurrentMdp::time(state);
    if (timed) {
      // The timed plan-first view: ET_k the static backlog, and each refined timed action after E
      // restored to the static backlog before it (the plan-first Mdp's restore value).
      robot_needs = ConcurrentMdp::robot_left(state);
      for (int j = mdp.executed_depth(state); j < ConcurrentMdp::refined(state, k); ++j) {
        const int action = problem.action_at(k, j);
        if (const int timed_slot = problem.timed_slot(action); timed_slot >= 0) {
          view.restore[static_cast<std::size_t>(timed_slot)] =
              static_cast<std::uint16_t>(std::min(robot_needs, too_late));
        }
        robot_needs += backlog_of(action);
      }
    }
    view.execution[slot] = static_cast<std::uint16_t>(std::min(robot_needs, too_late));
  }
  if (!mdp.has_backtracking()) return;
  // SPEC §7's restore value B_c of a culprit refined after E: the robot's backlog before it, so
  // that a backtrack the plan-first allocator foresees restores what acting would.
  for (int slot = 0; slot < problem.culprit_slot_count(); ++slot) view.restore[static_cast<std::size_t>(slot)] = 0;
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    if (!ConcurrentMdp::is_live(state, k)) continue;
    std::int64_t backlog = ConcurrentMdp::robot_left(state);
    for (int j = mdp.executed_depth(state); j < ConcurrentMdp::refined(state, k); ++j) {
      const int action = problem.action_at(k, j);
      if (const int culprit_slot = problem.culprit_slot(action); culprit_slot >= 0) {
        view.restore[static_cast<std::size_t>(culprit_slot)] = static_cast<std::uint16_t>(std::min(backlog, too_late));
      }
      backlog += timed ? backlog_of(action) : mdp.execution(state, action);
    }
  }
}

EagerCommitAllocator::EagerCommitAllocator(const ConcurrentMdp& mdp, std::unique_ptr<Allocator> plan_first)
    : mdp_(&mdp),
      plan_first_(std::move(plan_first)),
      view_(mdp.plan_first_mdp().start()),
      view_after_(mdp.plan_first_mdp().start()) {
  if (!plan_first_) throw UsageError("the eager commit rule needs a plan-first allocator");
}

void EagerCommitAllocator::begin_episode(std::uint64_t seed) {
  plan_first_->begin_episode(seed);
  kept_choice_ = -1;
  kept_time_ = -1;
}

int EagerCommitAllocator::skeleton_to_follow(const ConcurrentState& state) {
  const Problem& problem = mdp_->problem();
  const auto has_work = [&](int k) {
    return k >= 0 && k < mdp_->skeleton_count() && ConcurrentMdp::is_live(state, k) &&
           ConcurrentMdp::refined(state, k) < problem.skeleton_length(k);
  };
  const int time = ConcurrentMdp::time(state);
  int choice = -1;
  if (!plan_first_->is_stationary() && kept_time_ == time && has_work(kept_choice_)) {
    choice = kept_choice_;
  } else {
    plan_first_view(*mdp_, state, view_);
    choice = plan_first_->choose(view_);
  }
  if (!has_work(choice)) choice = soonest_skeleton(*mdp_, state, true);
  kept_choice_ = choice;
  kept_time_ = time;
  return choice;
}

ConcurrentMdp::Move EagerCommitAllocator::choose(const ConcurrentState& state) {
  if (mdp_->complete_plan(state) >= 0) return mdp_->run_complete_plan(state);
  const int k = skeleton_to_follow(state);
  if (k < 0) return {};  // no live skeleton has work left (none is complete either): nothing helps
  const int depth = mdp_->executed_depth(state);
  if (ConcurrentMdp::robot_left(state) == 0 && ConcurrentMdp::refined(state, k) > depth) {
    const int next = mdp_->problem().action_at(k, depth);
    // With expiry (SPEC §9) it starts as soon as it may: until then the planner refines k.
    if (!mdp_->is_timed()) return {next, ConcurrentMdp::kWait};
    const std::vector<int> startable = mdp_->startable(state);
    if (std::binary_search(startable.begin(), startable.end(), next)) return {next, ConcurrentMdp::kWait};
  }
  return {-1, k};
}

void EagerCommitAllocator::observe(const ConcurrentState& before, int choice, const ConcurrentState& after) {
  if (plan_first_->is_stationary() || choice < 0) return;
  plan_first_view(*mdp_, before, view_);
  plan_first_view(*mdp_, after, view_after_);
  plan_first_->observe(view_, choice, view_after_, Status::running);
}

int soonest_skeleton(const ConcurrentMdp& mdp, const ConcurrentState& state, bool with_work_left) {
  int soonest = -1;
  std::int64_t least = 0;
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    if (!ConcurrentMdp::is_live(state, k)) continue;
    if (with_work_left && ConcurrentMdp::refined(state, k) >= mdp.problem().skeleton_length(k)) continue;
    const std::int64_t finish = mdp.earliest_finish(state, k);
    if (soonest < 0 || finish < least) {
      soonest = k;
      least = finish;
    }
  }
  return soonest;
}

ConcurrentAllocatorFactory eager_commit_factory(const ConcurrentMdp& mdp, AllocatorFactory plan_first) {
  return
      [&mdp, plan_first = std::move(plan_first)] { return std::make_unique<EagerCommitAllocator>(mdp, plan_first()); };
}

namespace {

// An allocator deciding on a belief's model, shown the world's states as that model holds them.
class BelievingAllocator final : public ConcurrentAllocator {
 public:
  BelievingAllocator(const ConcurrentMdp& belief, std::unique_ptr<ConcurrentAllocator> inner)
      : belief_(&belief), inner_(std::move(inner)) {}

  std::string_view name() const noexcept override { return inner_->name(); }
  void begin_episode(std::uint64_t seed) override { inner_->begin_episode(seed); }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override {
    seen_ = belief_->canonical(state);
    if (!belief_->any_live(seen_)) return {};  // hopeless by its model: the planner idles
    return inner_->choose(seen_);
  }
  void observe(const ConcurrentState& before, int choice, const ConcurrentState& after) override {
    inner_->observe(belief_->canonical(before), choice, belief_->canonical(after));
  }
  bool is_stationary() const noexcept override { return inner_->is_stationary(); }
  void collect_statistics(Statistics& statistics) const override { inner_->collect_statistics(statistics); }

 private:
  const ConcurrentMdp* belief_;
  std::unique_ptr<ConcurrentAllocator> inner_;
  ConcurrentState seen_;  // scratch
};

}  // namespace

ConcurrentAllocatorFactory seen_by_belief(const ConcurrentMdp& belief, ConcurrentAllocatorFactory allocators) {
  return [&belief, allocators = std::move(allocators)] {
    return std::make_unique<BelievingAllocator>(belief, allocators());
  };
}

}  // namespace ontime
