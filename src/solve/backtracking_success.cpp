#include "ontime/solve/backtracking_success.hpp"

#include <algorithm>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

void append(std::string& key, std::int64_t value) {
  const auto bits = static_cast<std::uint16_t>(value);
  key.push_back(static_cast<char>(bits & 0xFF));
  key.push_back(static_cast<char>(bits >> 8));
}

}  // namespace

BacktrackingSuccess::BacktrackingSuccess(const Mdp& mdp, Aggregation aggregation)
    : mdp_(&mdp), aggregation_(aggregation), deadline_(mdp.deadline()) {
  if (!mdp.has_backtracking()) {
    throw UsageError(
        "BacktrackingSuccess is for an instance with backtracking; ContiguousSuccessTable serves the others");
  }
}

double BacktrackingSuccess::found_continuation(int k, int l, std::int64_t ct, std::int64_t et,
                                               const std::vector<std::uint16_t>& restores) {
  const Problem& problem = mdp_->problem();
  const int action = problem.action_at(k, l);
  const Distribution& execution = problem.action(action).execution;
  const std::int64_t left = std::int64_t{deadline_} - ct - et;
  if (left < 0) return 0.0;
  if (l + 1 == problem.skeleton_length(k)) return execution.cdf(static_cast<Steps>(left));
  std::vector<std::uint16_t> next = restores;
  next.push_back(problem.culprit_slot(action) >= 0
                     ? static_cast<std::uint16_t>(std::min<std::int64_t>(et, deadline_ + 1))
                     : std::uint16_t{0});
  // A skeleton sharing this action that ends with it is complete, and succeeds (x <= left), as
  // in Eq. (1).
  const auto next_value = [&](int member, std::int64_t x) {
    return problem.skeleton_length(member) == l + 1 ? 1.0 : fresh(member, l + 1, ct, et + x, next);
  };
  double total = 0;
  for (std::int64_t x = 0; x <= left; ++x) {
    const double mass = execution.pmf(static_cast<Steps>(x));
    if (mass <= 0) continue;
    double combined = 0;
    switch (aggregation_) {
      case Aggregation::self:
        combined = fresh(k, l + 1, ct, et + x, next);
        break;
      case Aggregation::sum:
        for (const int member : problem.members(action)) combined += next_value(member, x);
        break;
      case Aggregation::max:
        for (const int member : problem.members(action)) combined = std::max(combined, next_value(member, x));
        break;
    }
    total += mass * combined;
  }
  return total;
}

double BacktrackingSuccess::backtrack_continuation(int k, int l, std::int64_t ct,
                                                   const std::vector<std::uint16_t>& restores) {
  const Problem& problem = mdp_->problem();
  double total = 0;
  for (const Problem::CulpritIndex& culprit : problem.culprits(problem.action_at(k, l))) {
    const auto position = static_cast<std::size_t>(problem.position(culprit.action));
    const std::vector<std::uint16_t> before(restores.begin(), restores.begin() + static_cast<std::ptrdiff_t>(position));
    total += culprit.probability * fresh(k, static_cast<int>(position), ct, restores[position], before);
  }
  return total;
}

double BacktrackingSuccess::fresh(int k, int l, std::int64_t ct, std::int64_t et,
                                  const std::vector<std::uint16_t>& restores) {
  if (ct >= deadline_ || et > deadline_) return 0.0;
  std::string key;
  key.reserve(8 + 2 * restores.size());
  append(key, k);
  append(key, l);
  append(key, ct);
  append(key, et);
  for (const std::uint16_t restore : restores) append(key, restore);
  if (const auto known = memo_.find(key); known != memo_.end()) return known->second;

  const Action& action = mdp_->problem().action(mdp_->problem().action_at(k, l));
  double total = 0;
  for (std::int64_t t = 1; ct + t <= deadline_; ++t) {
    const double found = action.planning.pmf(static_cast<Steps>(t));
    const double back = action.backtrack.pmf(static_cast<Steps>(t));
    if (found > 0) total += found * found_continuation(k, l, ct + t, et, restores);
    if (back > 0) total += back * backtrack_continuation(k, l, ct + t, restores);
  }
  memo_.emplace(std::move(key), total);
  return total;
}

double BacktrackingSuccess::success_probability(const State& state, int k) {
  const Problem& problem = mdp_->problem();
  const auto slot = static_cast<std::size_t>(k);
  const int l = state.refined[slot];
  if (l >= problem.skeleton_length(k)) return 0.0;
  std::vector<std::uint16_t> restores(static_cast<std::size_t>(l), 0);
  for (int position = 0; position < l; ++position) {
    const int culprit_slot = problem.culprit_slot(problem.action_at(k, position));
    if (culprit_slot >= 0)
      restores[static_cast<std::size_t>(position)] = state.restore[static_cast<std::size_t>(culprit_slot)];
  }
  const std::int64_t ct = state.time;
  const std::int64_t et = state.execution[slot];
  const Steps spent = state.spent[slot];
  if (spent == 0) return fresh(k, l, ct, et, restores);
  // The attempt conditioned on `spent` steps that neither found a motion nor backtracked.
  const Action& action = problem.action(problem.action_at(k, l));
  double ended = 0;
  for (Steps u = 1; u <= spent; ++u) ended += action.planning.pmf(u) + action.backtrack.pmf(u);
  const double alive = 1.0 - ended;
  if (alive <= 0) return 0.0;
  double total = 0;
  for (std::int64_t t = 1; ct + t <= deadline_; ++t) {
    const double found = action.planning.pmf(static_cast<Steps>(spent + t));
    const double back = action.backtrack.pmf(static_cast<Steps>(spent + t));
    if (found > 0) total += found * found_continuation(k, l, ct + t, et, restores);
    if (back > 0) total += back * backtrack_continuation(k, l, ct + t, restores);
  }
  return total / alive;
}

}  // namespace ontime
