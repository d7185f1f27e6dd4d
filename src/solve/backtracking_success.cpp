#include "ontime/solve/backtracking_success.hpp"

#include <algorithm>

#include "ontime/util/error.hpp"

namespace ontime {

BacktrackingSuccess::BacktrackingSuccess(const Mdp& mdp, Aggregation aggregation)
    : mdp_(&mdp), aggregation_(aggregation), deadline_(mdp.deadline()) {
  if (!mdp.has_backtracking()) {
    throw UsageError(
        "BacktrackingSuccess is for an instance with backtracking; ContiguousSuccessTable serves the others");
  }
}

double BacktrackingSuccess::need(const Key& key, bool& ready) {
  if (key.time >= deadline_ || key.execution > deadline_) return 0.0;
  if (const auto known = memo_.find(key); known != memo_.end()) return known->second;
  pending_.push_back(key);
  ready = false;
  return 0.0;
}

double BacktrackingSuccess::attempt(const Key& key, Steps spent, bool& ready) {
  const Problem& problem = mdp_->problem();
  const int k = key.skeleton;
  const int l = key.position;
  const int action_index = problem.action_at(k, l);
  const Action& action = problem.action(action_index);
  const bool last = l + 1 == problem.skeleton_length(k);
  const Distribution& execution = action.execution;
  // The restore list the next position sees: this action's execution before it when some action
  // may blame it.
  const std::uint32_t next_restores =
      last ? 0
           : restores_.append(key.restores, problem.culprit_slot(action_index) >= 0
                                                ? static_cast<std::uint16_t>(std::min<std::int64_t>(
                                                      key.execution, std::int64_t{deadline_} + 1))
                                                : std::uint16_t{0});
  double total = 0;
  for (std::int64_t t = 1; key.time + t <= deadline_; ++t) {
    const auto ct = static_cast<std::int32_t>(key.time + t);
    const double found = action.planning.pmf(static_cast<Steps>(spent + t));
    if (found > 0) {
      // A motion: execution x, then the next position (Eq. (1)'s aggregation over the
      // skeletons sharing this action; one that ends with it is complete and succeeds).
      const std::int64_t left = std::int64_t{deadline_} - ct - key.execution;
      double continuation = 0;
      if (left >= 0 && last && problem.has_rewards()) {
        // With rewards (SPEC §8): the expected reward of the finish, not the chance it fits.
        for (std::int64_t x = 0; x <= left; ++x) {
          continuation += execution.pmf(static_cast<Steps>(x)) *
                          problem.reward_at(k, static_cast<Steps>(std::int64_t{ct} + key.execution + x));
        }
      } else if (left >= 0 && last) {
        continuation = execution.cdf(static_cast<Steps>(left));
      } else if (left >= 0) {
        const auto next_value = [&](int member, std::int64_t x) {
          return problem.skeleton_length(member) == l + 1
                     ? problem.reward_at(member, static_cast<Steps>(std::int64_t{ct} + key.execution + x))
                     : need(Key{member, l + 1, ct, static_cast<std::int32_t>(key.execution + x), next_restores}, ready);
        };
        for (std::int64_t x = 0; x <= left; ++x) {
          const double mass = execution.pmf(static_cast<Steps>(x));
          if (mass <= 0) continue;
          double combined = 0;
          switch (aggregation_) {
            case Aggregation::self:
              combined = next_value(k, x);
              break;
            case Aggregation::sum:
              for (const int member : problem.members(action_index)) combined += next_value(member, x);
              break;
            case Aggregation::max:
              for (const int member : problem.members(action_index))
                combined = std::max(combined, next_value(member, x));
              break;
          }
          continuation += mass * combined;
        }
      }
      total += found * continuation;
    }
    const double back = action.backtrack.pmf(static_cast<Steps>(spent + t));
    if (back > 0) {
      // A backtrack: the skeleton itself from its culprit, with the culprit's execution before it
      // restored and the time kept.
      double continuation = 0;
      for (const Problem::CulpritIndex& culprit : problem.culprits(action_index)) {
        const int position = problem.position(culprit.action);
        continuation += culprit.probability * need(Key{k, position, ct, restores_.at(key.restores, l, position),
                                                       restores_.prefix(key.restores, l, position)},
                                                   ready);
      }
      total += back * continuation;
    }
  }
  return total;
}

void BacktrackingSuccess::settle() {
  while (!pending_.empty()) {
    const Key key = pending_.back();
    if (memo_.contains(key)) {
      pending_.pop_back();
      continue;
    }
    bool ready = true;
    const double value = attempt(key, 0, ready);
    // Not ready: what it needs is now above it on the stack, and it is summed again after.
    if (ready) {
      memo_.emplace(key, value);
      pending_.pop_back();
    }
  }
}

double BacktrackingSuccess::fresh(const Key& key) {
  bool ready = true;
  const double value = need(key, ready);
  if (ready) return value;
  settle();
  return memo_.at(key);
}

double BacktrackingSuccess::success_probability(const State& state, int k) {
  const Problem& problem = mdp_->problem();
  const auto slot = static_cast<std::size_t>(k);
  const int l = state.refined[slot];
  if (l >= problem.skeleton_length(k)) return 0.0;
  std::uint32_t restores = 0;
  for (int position = 0; position < l; ++position) {
    const int culprit_slot = problem.culprit_slot(problem.action_at(k, position));
    restores = restores_.append(
        restores, culprit_slot >= 0 ? state.restore[static_cast<std::size_t>(culprit_slot)] : std::uint16_t{0});
  }
  const Key key{k, l, static_cast<std::int32_t>(state.time), static_cast<std::int32_t>(state.execution[slot]),
                restores};
  const Steps spent = state.spent[slot];
  if (spent == 0) return fresh(key);
  // The attempt conditioned on `spent` steps that neither found a motion nor backtracked.
  const Action& action = problem.action(problem.action_at(k, l));
  double ended = 0;
  for (Steps u = 1; u <= spent; ++u) ended += action.planning.pmf(u) + action.backtrack.pmf(u);
  const double alive = 1.0 - ended;
  if (alive <= 0) return 0.0;
  bool ready = true;
  double total = attempt(key, spent, ready);
  if (!ready) {
    settle();
    ready = true;
    total = attempt(key, spent, ready);
  }
  return total / alive;
}

}  // namespace ontime
