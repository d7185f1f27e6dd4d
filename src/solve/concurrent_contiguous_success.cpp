#include "ontime/solve/concurrent_contiguous_success.hpp"

#include <algorithm>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {

ConcurrentContiguousSuccess::ConcurrentContiguousSuccess(const ConcurrentMdp& mdp, Aggregation aggregation)
    : mdp_(&mdp), aggregation_(aggregation), deadline_(mdp.deadline()) {
  check_supported(mdp);
}

void ConcurrentContiguousSuccess::check_supported(const ConcurrentMdp& mdp) {
  if (mdp.is_timed()) {
    throw UsageError(mdp.problem().name() +
                     ": dp and dp-rerun acting while planning (SPEC §10) do not value exogenous chains or expiry "
                     "(SPEC §9) yet (the optimal allocator and the eager kinds take them)");
  }
  if (mdp.has_backtracking()) {
    throw UsageError(mdp.problem().name() +
                     ": dp and dp-rerun acting while planning (SPEC §10) do not value backtracking (SPEC §7) yet: "
                     "Eq. (1) acting while planning has no give-up term (the optimal allocator and the eager "
                     "kinds take it)");
  }
}

// value, fresh and after_found recurse one level per action of the skeleton (at most
// Problem::kMaxSkeletonLength deep, whatever the deadline), each level memoised by fresh.
// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentContiguousSuccess::value(int k, int l, Steps spent, Steps time, std::int64_t backlog) {
  if (time + backlog > deadline_) return 0.0;
  const Problem& problem = mdp_->problem();
  const Distribution& planning = problem.action(problem.action_at(k, l)).planning;
  const double survival = planning.survival(spent);
  if (survival <= 0.0) return 0.0;
  double total = 0.0;
  for (Steps t = 1; time + t <= deadline_; ++t) {
    const double found = planning.pmf(spent + t);
    if (found > 0.0) total += found * after_found(k, l, time + t, std::max<std::int64_t>(backlog - t, 0));
  }
  return total / survival;
}

double ConcurrentContiguousSuccess::value(const ConcurrentState& state, int k) {
  const Problem& problem = mdp_->problem();
  const std::int64_t free = mdp_->robot_free(state, k);
  const Steps now = ConcurrentMdp::time(state);
  const int refined = ConcurrentMdp::refined(state, k);
  if (refined == problem.skeleton_length(k)) {
    if (free > deadline_) return 0.0;
    return problem.has_rewards() ? problem.reward_at(k, static_cast<Steps>(free)) : 1.0;
  }
  return value(k, refined, mdp_->spent(state, k), now, free - now);
}

// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentContiguousSuccess::fresh(int k, int l, Steps time, std::int64_t backlog) {
  if (time + backlog > deadline_) return 0.0;
  const std::uint64_t key = (static_cast<std::uint64_t>(k) << 40U) | (static_cast<std::uint64_t>(l) << 32U) |
                            (static_cast<std::uint64_t>(time) << 16U) | static_cast<std::uint64_t>(backlog);
  if (const auto found = fresh_.find(key); found != fresh_.end()) return found->second;
  const double computed = value(k, l, 0, time, backlog);
  fresh_.emplace(key, computed);
  return computed;
}

// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentContiguousSuccess::after_found(int k, int l, Steps time, std::int64_t backlog) {
  const Problem& problem = mdp_->problem();
  const int action = problem.action_at(k, l);
  // A skeleton that ends with this action is worth its reward at the end of its backlog.
  const auto ending = [&](int m, std::int64_t finish) {
    if (finish > deadline_) return 0.0;
    return problem.has_rewards() ? problem.reward_at(m, static_cast<Steps>(finish)) : 1.0;
  };
  double total = 0.0;
  for (const Mdp::ExecutionOutcome& outcome : mdp_->plan_first_mdp().execution_outcomes(action)) {
    const std::int64_t after = backlog + outcome.steps;
    if (time + after > deadline_) continue;
    const auto worth = [&](int m) {  // NOLINT(misc-no-recursion)
      return problem.skeleton_length(m) == l + 1 ? ending(m, time + after) : fresh(m, l + 1, time, after);
    };
    double combined = 0.0;
    if (aggregation_ == Aggregation::self) {
      combined = worth(k);
    } else {
      for (const int m : problem.members(action)) {
        combined = aggregation_ == Aggregation::sum ? combined + worth(m) : std::max(combined, worth(m));
      }
    }
    total += outcome.probability * combined;
  }
  return total;
}

}  // namespace ontime
