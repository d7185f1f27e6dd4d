#include "ontime/learn/fitting.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

constexpr double kRelativeSlack = 1e-9;
// Times beyond every supported deadline are all alike ("never"); clamping keeps them in range.
constexpr double kLargestStep = static_cast<double>(Distribution::kMaxStep) + 1;

double steps_exactly(double seconds, double step_seconds) {
  if (!(std::isfinite(step_seconds) && step_seconds > 0)) {
    throw UsageError("the step must be a positive number of seconds");
  }
  if (!(seconds >= 0)) throw UsageError("a time must be a number of seconds >= 0");
  return std::min(seconds / step_seconds, kLargestStep);
}

// Above this, alpha swamps any log a planner can write (the estimates are then the uniform
// distribution, whatever the data), and alpha times the categories may overflow to infinity,
// which would empty the fitted PMFs.
constexpr double kMaxLaplace = 1e6;

std::string laplace_rule(double laplace) {
  return fmt::format(
      "laplace: the Laplace smoothing alpha must be between 0 and {:g}, larger values swamp the log "
      "(got {:g})",
      kMaxLaplace, laplace);
}

void check_estimation_options(Steps deadline, double laplace) {
  if (deadline < 1 || deadline > Problem::kMaxDeadline) {
    throw UsageError("the deadline must be between 1 and " + std::to_string(Problem::kMaxDeadline) + " steps");
  }
  if (!(laplace >= 0 && laplace <= kMaxLaplace)) throw UsageError(laplace_rule(laplace));
}

}  // namespace

Steps steps_to_complete(double seconds, double step_seconds) {
  const double steps = steps_exactly(seconds, step_seconds);
  return static_cast<Steps>(std::max(0.0, std::ceil(steps - kRelativeSlack * std::max(1.0, steps))));
}

Steps whole_steps_within(double seconds, double step_seconds) {
  const double steps = steps_exactly(seconds, step_seconds);
  return static_cast<Steps>(std::floor(steps + kRelativeSlack * std::max(1.0, steps)));
}

Distribution estimate_planning(const PlanningSample& sample, Steps deadline, double laplace) {
  check_estimation_options(deadline, laplace);
  const auto size = static_cast<std::size_t>(deadline) + 1;
  std::vector<double> found_at(size, 0.0);    // d_t, t <= D
  std::vector<double> leaving_at(size, 0.0);  // attempts last at risk at step t (cut off after t steps)
  double at_risk = 0;                         // n_1
  for (const Steps t : sample.found) {
    if (t < 1) throw UsageError("a planning time is at least 1 step");
    // Found after the deadline: within the deadline it only survived, like a cut-off attempt.
    if (t <= deadline) {
      found_at[static_cast<std::size_t>(t)] += 1;
    } else {
      leaving_at[static_cast<std::size_t>(deadline)] += 1;
    }
    at_risk += 1;
  }
  for (const Steps c : sample.censored) {
    if (c < 0) throw UsageError("a cut-off attempt survived at least 0 steps");
    leaving_at[static_cast<std::size_t>(std::min(c, deadline))] += 1;
    at_risk += 1;
  }
  at_risk -= leaving_at[0];  // cut off before the first step ended: no information
  std::vector<double> masses(size, 0.0);
  double survival = 1.0;
  for (Steps t = 1; t <= deadline; ++t) {
    const auto slot = static_cast<std::size_t>(t);
    const auto categories_left = static_cast<double>(deadline - t + 2);  // t..D and "never"
    const double denominator = at_risk + laplace * categories_left;
    const double hazard = denominator > 0 ? (found_at[slot] + laplace) / denominator : 0.0;
    masses[slot] = survival * hazard;
    survival *= 1.0 - hazard;
    at_risk -= found_at[slot] + leaving_at[slot];
  }
  return Distribution::from_pmf(std::move(masses));
}

AttemptEstimate estimate_attempts(const PlanningSample& sample, Steps deadline, double laplace) {
  if (sample.backtracked.empty()) return {estimate_planning(sample, deadline, laplace), Distribution{}, {}};
  check_estimation_options(deadline, laplace);
  if (sample.blamed.size() != sample.backtracked.size()) {
    throw UsageError("every backtracked attempt names the action it blamed");
  }
  const auto size = static_cast<std::size_t>(deadline) + 1;
  std::vector<double> found_at(size, 0.0), back_at(size, 0.0), leaving_at(size, 0.0);
  double at_risk = 0;
  const auto event = [&](Steps t, std::vector<double>& at) {
    if (t < 1) throw UsageError("an attempt ends after at least 1 step");
    if (t <= deadline) {
      at[static_cast<std::size_t>(t)] += 1;
    } else {
      leaving_at[static_cast<std::size_t>(deadline)] += 1;  // within D it only survived
    }
    at_risk += 1;
  };
  for (const Steps t : sample.found) event(t, found_at);
  for (const Steps t : sample.backtracked) event(t, back_at);
  for (const Steps c : sample.censored) {
    if (c < 0) throw UsageError("a cut-off attempt survived at least 0 steps");
    leaving_at[static_cast<std::size_t>(std::min(c, deadline))] += 1;
    at_risk += 1;
  }
  at_risk -= leaving_at[0];
  std::vector<double> planning(size, 0.0), backtrack(size, 0.0);
  double survival = 1.0;
  for (Steps t = 1; t <= deadline; ++t) {
    const auto slot = static_cast<std::size_t>(t);
    const double denominator = at_risk + laplace * static_cast<double>(deadline - t + 2);
    const double found = denominator > 0 ? (found_at[slot] + laplace) / denominator : 0.0;
    const double back = denominator > 0 ? back_at[slot] / denominator : 0.0;
    planning[slot] = survival * found;
    backtrack[slot] = survival * back;
    survival *= std::max(0.0, 1.0 - found - back);
    at_risk -= found_at[slot] + back_at[slot] + leaving_at[slot];
  }
  AttemptEstimate estimate{
      Distribution::from_pmf(std::move(planning)), Distribution::from_pmf(std::move(backtrack)), {}};
  if (estimate.backtrack.never() < 1.0) {
    for (const std::string& id : sample.blamed) {
      auto known = std::find_if(estimate.culprits.begin(), estimate.culprits.end(),
                                [&id](const Culprit& culprit) { return culprit.id == id; });
      if (known == estimate.culprits.end()) known = estimate.culprits.insert(estimate.culprits.end(), Culprit{id, 0.0});
      known->probability += 1.0;
    }
    for (Culprit& culprit : estimate.culprits) culprit.probability /= static_cast<double>(sample.blamed.size());
  }
  return estimate;
}

Distribution estimate_execution(std::span<const Steps> execution_steps, Steps deadline, double laplace) {
  check_estimation_options(deadline, laplace);
  const auto size = static_cast<std::size_t>(deadline) + 1;
  std::vector<double> counts(size, 0.0);
  for (const Steps x : execution_steps) {
    if (x < 0) throw UsageError("an execution time is at least 0 steps");
    if (x <= deadline) counts[static_cast<std::size_t>(x)] += 1;  // beyond D: "never"
  }
  const double total = static_cast<double>(execution_steps.size()) + laplace * static_cast<double>(deadline + 2);
  std::vector<double> masses(size, 0.0);
  if (total > 0) {
    for (std::size_t x = 0; x < size; ++x) masses[x] = (counts[x] + laplace) / total;
  }
  return Distribution::from_pmf(std::move(masses));
}

SkeletonList single_action_skeletons(std::span<const RefinementAttempt> attempts, std::string_view source) {
  SkeletonList list{std::string(source), {}};
  std::set<std::string_view> seen;
  for (const RefinementAttempt& attempt : attempts) {
    if (!seen.insert(attempt.action).second) continue;
    if (list.skeletons.size() == static_cast<std::size_t>(Problem::kMaxSkeletons)) {
      throw UsageError(std::string(source) + ": more than " + std::to_string(Problem::kMaxSkeletons) +
                       " actions, one skeleton each, is more skeletons than an instance holds");
    }
    list.skeletons.push_back({attempt.action});
  }
  return list;
}

FitResult fit_problem(std::span<const RefinementAttempt> attempts, std::string_view log_source,
                      const SkeletonList& skeletons, const FitOptions& options) {
  if (!(std::isfinite(options.step_seconds) && options.step_seconds > 0)) {
    throw UsageError("the step must be a positive number of seconds");
  }
  if (options.deadline < 1 || options.deadline > Problem::kMaxDeadline) {
    throw UsageError("the deadline must be between 1 and " + std::to_string(Problem::kMaxDeadline) + " steps");
  }
  if (!(options.laplace >= 0 && options.laplace <= kMaxLaplace)) throw UsageError(laplace_rule(options.laplace));

  std::map<std::string, int> index_of;
  std::vector<std::vector<int>> skeleton_indices;
  std::vector<ActionFit> fits;
  for (const auto& skeleton : skeletons.skeletons) {
    std::vector<int>& indices = skeleton_indices.emplace_back();
    for (const std::string& id : skeleton) {
      const auto [entry, fresh] = index_of.try_emplace(id, static_cast<int>(fits.size()));
      if (fresh) fits.push_back(ActionFit{id, 0, 0, 0, 0});
      indices.push_back(entry->second);
    }
  }
  std::vector<PlanningSample> planning(fits.size());
  std::vector<std::vector<Steps>> execution(fits.size());
  for (const RefinementAttempt& attempt : attempts) {
    const auto known = index_of.find(attempt.action);
    if (known == index_of.end()) continue;  // an action no skeleton uses
    const auto slot = static_cast<std::size_t>(known->second);
    ++fits[slot].attempts;
    if (attempt.found) {
      ++fits[slot].found;
      planning[slot].found.push_back(
          std::max<Steps>(1, steps_to_complete(attempt.planning_seconds, options.step_seconds)));
      execution[slot].push_back(steps_to_complete(attempt.execution_seconds, options.step_seconds));
    } else if (attempt.backtrack) {
      ++fits[slot].backtracked;
      planning[slot].backtracked.push_back(
          std::max<Steps>(1, steps_to_complete(attempt.planning_seconds, options.step_seconds)));
      planning[slot].blamed.push_back(*attempt.backtrack);
    } else {
      ++fits[slot].censored;
      planning[slot].censored.push_back(whole_steps_within(attempt.planning_seconds, options.step_seconds));
    }
  }
  for (std::size_t k = 0; k < skeletons.skeletons.size(); ++k) {
    for (std::size_t l = 0; l < skeletons.skeletons[k].size(); ++l) {
      const std::string& id = skeletons.skeletons[k][l];
      if (fits[static_cast<std::size_t>(index_of.at(id))].attempts == 0) {
        throw InputError(skeletons.source, detail::json_index(detail::json_index("skeletons", k), l),
                         "action '" + id + "' has no record in the log " + std::string(log_source));
      }
    }
  }
  std::vector<Action> actions;
  for (std::size_t a = 0; a < fits.size(); ++a) {
    AttemptEstimate attempt = estimate_attempts(planning[a], options.deadline, options.laplace);
    actions.emplace_back(fits[a].id, std::move(attempt.planning),
                         estimate_execution(execution[a], options.deadline, options.laplace),
                         std::move(attempt.backtrack), std::move(attempt.culprits));
  }
  try {
    Problem problem(options.name, options.deadline, options.step_seconds, std::move(actions),
                    std::move(skeleton_indices), options.description);
    return FitResult{std::move(problem), std::move(fits)};
  } catch (const BacktrackingError& error) {
    // A backtrack record blaming an action that is not before it on the skeletons' path.
    throw InputError(std::string(log_source), "action '" + error.action() + "'",
                     error.culprit().empty() ? error.rule()
                                             : "blames '" + error.culprit() + "': " + error.rule() + " (skeletons " +
                                                   skeletons.source + ")");
  }
}

}  // namespace ontime
