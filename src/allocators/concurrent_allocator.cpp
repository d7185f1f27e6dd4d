#include "ontime/allocators/concurrent_allocator.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include "ontime/util/error.hpp"

namespace ontime {

void plan_first_view(const ConcurrentMdp& mdp, const ConcurrentState& state, State& view) {
  const Problem& problem = mdp.problem();
  const std::int64_t too_late = std::int64_t{mdp.deadline()} + 1;
  view.time = static_cast<std::uint16_t>(ConcurrentMdp::time(state));
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
    const std::int64_t robot_needs = mdp.robot_free(state, k) - ConcurrentMdp::time(state);
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
      backlog += mdp.execution(state, action);
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
  if (!has_work(choice)) {
    choice = -1;
    std::int64_t best = 0;
    for (int k = 0; k < mdp_->skeleton_count(); ++k) {
      if (!has_work(k)) continue;
      const std::int64_t finish = mdp_->earliest_finish(state, k);
      if (choice < 0 || finish < best) {
        choice = k;
        best = finish;
      }
    }
  }
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
    return {mdp_->problem().action_at(k, depth), ConcurrentMdp::kWait};
  }
  return {-1, k};
}

void EagerCommitAllocator::observe(const ConcurrentState& before, int choice, const ConcurrentState& after) {
  if (plan_first_->is_stationary() || choice < 0) return;
  plan_first_view(*mdp_, before, view_);
  plan_first_view(*mdp_, after, view_after_);
  plan_first_->observe(view_, choice, view_after_, Status::running);
}

ConcurrentAllocatorFactory eager_commit_factory(const ConcurrentMdp& mdp, AllocatorFactory plan_first) {
  refuse_chains(mdp, "the eager commit rule", "its plan-first view has no chains' state nor expiry");
  return
      [&mdp, plan_first = std::move(plan_first)] { return std::make_unique<EagerCommitAllocator>(mdp, plan_first()); };
}

void refuse_chains(const ConcurrentMdp& mdp, std::string_view rule, std::string_view why) {
  if (!mdp.is_timed()) return;
  throw UsageError(mdp.problem().name() + ": " + std::string(rule) +
                   " acting while planning (SPEC §10) does not take exogenous chains or expiry (SPEC §9) yet (" +
                   std::string(why) + "): only the optimal allocator takes chains so far");
}

}  // namespace ontime
