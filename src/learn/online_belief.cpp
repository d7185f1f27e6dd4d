#include "ontime/learn/online_belief.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "ontime/util/error.hpp"

namespace ontime {

OnlineBelief::OnlineBelief(Problem prior, double strength)
    : prior_(std::move(prior)), strength_(strength), posteriors_(static_cast<std::size_t>(prior_.action_count())) {
  if (!(std::isfinite(strength) && strength > 0)) {
    throw UsageError("the prior's strength must be a positive number of attempts");
  }
  // A node "move(A,B)#2" of the prior learns with its base "move(A,B)" when the prior has it, and
  // both backtrack or neither does (one posterior gives both their distributions).
  base_.reserve(posteriors_.size());
  for (int a = 0; a < prior_.action_count(); ++a) {
    const int base = prior_.find_action(action_base_id(prior_.action(a).id));
    const bool alike = base >= 0 && prior_.action(base).culprits.empty() == prior_.action(a).culprits.empty();
    base_.push_back(alike ? base : a);
  }
}

PlanningPosterior OnlineBelief::prior_posterior(int index) const {
  const Action& prior = prior_.action(index);
  if (prior.culprits.empty()) return {prior.planning, prior_.deadline(), strength_};
  // An action that backtracks: up to the last step of its prior when that is beyond the deadline,
  // so that its backtrack mass stays (an instance needs some with culprits) wherever it lies.
  const auto last = [](const Distribution& d) { return d.max_step() == kNever ? Steps{0} : d.max_step(); };
  const Steps horizon = std::max({prior_.deadline(), last(prior.planning), last(prior.backtrack)});
  return {prior.planning, prior.backtrack, horizon, strength_};
}

int OnlineBelief::index_of(std::string_view id) const {
  int index = prior_.find_action(id);
  if (index < 0) index = prior_.find_action(action_base_id(id));
  if (index < 0) throw UsageError("the belief has no action '" + std::string(id) + "' (nor its base action)");
  return base_[static_cast<std::size_t>(index)];
}

void OnlineBelief::observe(std::string_view id, const ActionAttempt& attempt) {
  const auto index = static_cast<std::size_t>(index_of(id));
  if (attempt.effort <= 0 && attempt.ended.empty()) return;
  const Action& prior = prior_.action(static_cast<int>(index));
  // Backtracks are learned for an action whose prior backtracks (it names the culprits to blame);
  // for another, a backtrack is an attempt that survived its steps without a motion.
  const bool backtracks = !prior.culprits.empty();
  std::optional<PlanningPosterior>& posterior = posteriors_[index];
  if (!posterior) posterior.emplace(prior_posterior(static_cast<int>(index)));
  for (const EndedAttempt& ended : attempt.ended) {
    if (ended.effort <= 0) continue;
    if (ended.found) {
      posterior->observe_found(ended.effort);
    } else if (ended.backtracked && backtracks) {
      posterior->observe_backtrack(ended.effort);
    } else {
      posterior->observe_cut_off(ended.effort);
    }
    ++observations_;
  }
  if (attempt.effort <= 0) return;
  if (attempt.found) {
    posterior->observe_found(attempt.effort);
  } else {
    posterior->observe_cut_off(attempt.effort);
  }
  ++observations_;
}

void OnlineBelief::observe(const Problem& problem, std::span<const ActionAttempt> attempts) {
  if (attempts.size() != static_cast<std::size_t>(problem.action_count())) {
    throw UsageError("attempts for " + std::to_string(attempts.size()) + " actions of a problem with " +
                     std::to_string(problem.action_count()));
  }
  for (int a = 0; a < problem.action_count(); ++a) {
    const ActionAttempt& attempt = attempts[static_cast<std::size_t>(a)];
    if (attempt.effort > 0 || !attempt.ended.empty()) (void)index_of(problem.action(a).id);
  }
  for (int a = 0; a < problem.action_count(); ++a) observe(problem.action(a).id, attempts[static_cast<std::size_t>(a)]);
}

Problem OnlineBelief::believed() const {
  std::vector<Action> actions(prior_.actions().begin(), prior_.actions().end());
  for (std::size_t a = 0; a < actions.size(); ++a) {
    const auto base = static_cast<std::size_t>(base_[a]);
    if (!posteriors_[base]) continue;
    actions[a].planning = posteriors_[base]->mean();
    // (An action whose prior backtracks: its posterior's backtrack PMF, which sums with the
    // planning PMF to at most 1. Any other keeps its prior's: none.)
    if (!actions[a].culprits.empty()) actions[a].backtrack = posteriors_[base]->backtrack_mean();
  }
  return prior_.with_actions(std::move(actions));
}

Problem OnlineBelief::believed_for(const Problem& structure) const {
  return with_distributions_of(structure, believed());
}

Distribution OnlineBelief::planning(std::string_view id) const {
  const auto index = static_cast<std::size_t>(index_of(id));
  return posteriors_[index] ? posteriors_[index]->mean() : prior_.action(static_cast<int>(index)).planning;
}

Distribution OnlineBelief::backtrack(std::string_view id) const {
  const auto index = static_cast<std::size_t>(index_of(id));
  const Action& prior = prior_.action(static_cast<int>(index));
  return posteriors_[index] && !prior.culprits.empty() ? posteriors_[index]->backtrack_mean() : prior.backtrack;
}

}  // namespace ontime
