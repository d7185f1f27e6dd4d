#include "ontime/solve/concurrent_value_bounds.hpp"

#include <algorithm>
#include <utility>

#include "ontime/util/error.hpp"

namespace ontime {

ConcurrentValueBounds::ConcurrentValueBounds(const ConcurrentMdp& mdp)
    : mdp_(&mdp),
      devoted_((refuse_backtracking(mdp), mdp), Aggregation::self,  // refused first
               ConcurrentContiguousSuccess::Timing::relax) {
  if (!mdp.is_timed()) clairvoyant_.emplace(mdp);
}

void ConcurrentValueBounds::refuse_backtracking(const ConcurrentMdp& mdp) {
  if (!mdp.has_backtracking()) return;
  throw UsageError(mdp.problem().name() +
                   ": the bounds on the optimum acting while planning (SPEC §10), which the search and the bound "
                   "leaves of mcts and branch-and-bound use, do not value backtracking (SPEC §7) yet: a give-up may "
                   "discard motions, which their proofs leave out (--method memoised and the optimal allocator "
                   "take it)");
}

bool ConcurrentValueBounds::eligible(const ConcurrentState& state, int k) const {
  const Problem& problem = mdp_->problem();
  const int length = problem.skeleton_length(k);
  for (int m = 0; m < mdp_->skeleton_count(); ++m) {
    if (m == k || !ConcurrentMdp::is_live(state, m)) continue;
    const int prefix = problem.skeleton_length(m);
    // Actions are the nodes of the prefix tree: one shared action at m's last position means m
    // is a prefix of k (or k itself, spelled again).
    if (prefix > length || problem.action_at(m, prefix - 1) != problem.action_at(k, prefix - 1)) continue;
    if (prefix < length || m < k) return false;
  }
  return true;
}

ConcurrentValueBounds::Interval ConcurrentValueBounds::bounds(const ConcurrentState& state) {
  if (!mdp_->any_live(state)) return {};
  if (mdp_->certain_success(state)) return {1.0, 1.0};
  const Problem& problem = mdp_->problem();
  const bool rewards = problem.has_rewards();
  // Without rewards, per next unrefined action (a group), the sum of its skeletons' devoted
  // values: groups share no unrefined action, so their events are independent.
  groups_.clear();
  double best = 0.0, sum = 0.0, cap = 0.0;
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (!ConcurrentMdp::is_live(state, k) || !eligible(state, k)) continue;
    const double devoted = devoted_.value(state, k);
    best = std::max(best, devoted);
    sum += devoted;
    const std::int64_t finish = mdp_->earliest_finish(state, k);
    if (finish <= mdp_->deadline())
      cap = std::max(cap, rewards ? problem.reward_at(k, static_cast<Steps>(finish)) : 1.0);
    const int refined = ConcurrentMdp::refined(state, k);
    // A skeleton refined in full is a group of its own (its event is certain or impossible).
    const int next = refined < problem.skeleton_length(k) ? problem.action_at(k, refined) : -1 - k;
    const auto group = std::find_if(groups_.begin(), groups_.end(), [&](const auto& g) { return g.first == next; });
    if (group == groups_.end()) {
      groups_.emplace_back(next, devoted);
    } else {
      group->second += devoted;
    }
  }
  double upper = std::min(cap, sum);
  if (!rewards) {
    double none = 1.0;  // the chance that no group's devoted policy succeeds, at least
    for (const auto& group : groups_) none *= 1.0 - std::min(1.0, group.second);
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
