#include "ontime/solve/concurrent_value_bounds.hpp"

#include <algorithm>

namespace ontime {

ConcurrentValueBounds::ConcurrentValueBounds(const ConcurrentMdp& mdp)
    : mdp_(&mdp), devoted_(mdp, Aggregation::self, ConcurrentContiguousSuccess::Timing::relax) {
  if (!mdp.is_timed()) clairvoyant_.emplace(mdp);
}

ConcurrentValueBounds::Standing ConcurrentValueBounds::standing(const ConcurrentState& state, int k) const {
  const Problem& problem = mdp_->problem();
  const int length = problem.skeleton_length(k);
  Standing result = Standing::eligible;
  for (int m = 0; m < mdp_->skeleton_count(); ++m) {
    if (m == k || !ConcurrentMdp::is_live(state, m)) continue;
    const int prefix = problem.skeleton_length(m);
    // Actions are the nodes of the prefix tree: one shared action at m's last position means m
    // is a prefix of k (or k itself, spelled again).
    if (prefix > length || problem.action_at(m, prefix - 1) != problem.action_at(k, prefix - 1)) continue;
    if (prefix == length && m < k) return Standing::twin;
    if (prefix < length) result = Standing::below_prefix;
  }
  return result;
}

ConcurrentValueBounds::Interval ConcurrentValueBounds::bounds(const ConcurrentState& state) {
  if (!mdp_->any_live(state)) return {};
  if (mdp_->certain_success(state)) return {1.0, 1.0};
  const Problem& problem = mdp_->problem();
  const bool rewards = problem.has_rewards();
  const bool backtracking = mdp_->has_backtracking();
  // Without rewards, per next unrefined action (a group), the sums of its skeletons' devoted values
  // and give-up chances: groups share no unrefined action, so their events are independent.
  groups_.clear();
  double best = 0.0, sum = 0.0, give_ups = 0.0, cap = 0.0;
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (!ConcurrentMdp::is_live(state, k)) continue;
    const Standing place = standing(state, k);
    // Without backtracking only eligible skeletons count; with it, a give-up on the actions a
    // skeleton below a live prefix adds counts too (the relaxation ends the episode there).
    if (place == Standing::twin || (place == Standing::below_prefix && !backtracking)) continue;
    double devoted = 0.0, give_up = 0.0;
    if (!backtracking) {
      devoted = devoted_.value(state, k);
      best = std::max(best, devoted);
    } else {
      // Above: the relaxation in which the first give-up ends the episode with the largest reward
      // left (R_cap); below: the devoted policy's exact value, give-ups and all.
      const ConcurrentContiguousSuccess::GiveUpRelaxed relaxed = devoted_.give_up_relaxed(state, k);
      give_up = relaxed.give_up;
      if (place == Standing::eligible) {
        devoted = relaxed.reward;
        if (!mdp_->is_timed()) best = std::max(best, devoted_.value(state, k));
      }
    }
    sum += devoted;
    give_ups += give_up;
    if (place == Standing::eligible) {
      const std::int64_t finish = mdp_->earliest_finish(state, k);
      if (finish <= mdp_->deadline())
        cap = std::max(cap, rewards ? problem.reward_at(k, static_cast<Steps>(finish)) : 1.0);
    }
    const int refined = ConcurrentMdp::refined(state, k);
    // A skeleton refined in full is a group of its own (its event is certain or impossible).
    const int next = refined < problem.skeleton_length(k) ? problem.action_at(k, refined) : -1 - k;
    const auto group = std::find_if(groups_.begin(), groups_.end(), [&](const Group& g) { return g.next == next; });
    if (group == groups_.end()) {
      groups_.push_back({next, devoted + give_up});
    } else {
      group->chance += devoted + give_up;
    }
  }
  double upper = std::min(cap, backtracking ? sum + cap * give_ups : sum);
  if (!rewards) {
    double none = 1.0;  // the chance that no group's devoted policy succeeds (or gives up), at least
    for (const Group& group : groups_) none *= 1.0 - std::min(1.0, group.chance);
    upper = std::min(upper, 1.0 - none);
  }
  // With chains or expiry the devoted values are of the relaxed problem (upper bounds only); the
  // lower end is the best start that ends the episode now, or 0.
  if (mdp_->is_timed()) best = ending_start(state);
  if (clairvoyant_) upper = std::min(upper, cap * clairvoyant_->union_probability(state));
  // Rounding aside, upper >= V* >= lower; the max keeps the interval ordered when it rounds.
  return {best, std::max(best, upper)};
}

double ConcurrentValueBounds::ending_start(const ConcurrentState& state) const {
  double best = 0.0;
  for (const int action : mdp_->startable(state)) {
    double value = 0.0;
    bool ends = true;
    mdp_->for_each_start_outcome(state, action, [&](double probability, const ConcurrentMdp::StartOutcome& outcome) {
      ends = ends && outcome.ends;
      value += probability * outcome.reward;
    });
    if (ends) best = std::max(best, value);
  }
  return best;
}

}  // namespace ontime
