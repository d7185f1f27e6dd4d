#include "ontime/learn/online_belief.hpp"

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
  // A node "move(A,B)#2" of the prior learns with its base "move(A,B)" when the prior has it.
  base_.reserve(posteriors_.size());
  for (int a = 0; a < prior_.action_count(); ++a) {
    const int base = prior_.find_action(action_base_id(prior_.action(a).id));
    base_.push_back(base >= 0 ? base : a);
  }
}

int OnlineBelief::index_of(std::string_view id) const {
  int index = prior_.find_action(id);
  if (index < 0) index = prior_.find_action(action_base_id(id));
  if (index < 0) throw UsageError("the belief has no action '" + std::string(id) + "' (nor its base action)");
  return base_[static_cast<std::size_t>(index)];
}

void OnlineBelief::observe(std::string_view id, const ActionAttempt& attempt) {
  const auto index = static_cast<std::size_t>(index_of(id));
  if (attempt.effort <= 0) return;
  std::optional<PlanningPosterior>& posterior = posteriors_[index];
  if (!posterior) posterior.emplace(prior_.action(static_cast<int>(index)).planning, prior_.deadline(), strength_);
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
    if (attempts[static_cast<std::size_t>(a)].effort > 0) (void)index_of(problem.action(a).id);
  }
  for (int a = 0; a < problem.action_count(); ++a) observe(problem.action(a).id, attempts[static_cast<std::size_t>(a)]);
}

Problem OnlineBelief::believed() const {
  std::vector<Action> actions(prior_.actions().begin(), prior_.actions().end());
  for (std::size_t a = 0; a < actions.size(); ++a) {
    const auto base = static_cast<std::size_t>(base_[a]);
    if (posteriors_[base]) actions[a].planning = posteriors_[base]->mean();
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

}  // namespace ontime
