#include "ontime/learn/attempt_scores.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <vector>

#include "ontime/learn/fitting.hpp"
#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// One attempt in steps, coarsened at the horizon.
struct Outcome {
  int action = 0;
  Steps time = 0;      // the event's step, or the steps survived
  bool event = false;  // T = time; otherwise T > time
  Steps execution = -1;
};

}  // namespace

AttemptScores score_attempts(std::span<const RefinementAttempt> attempts, const Problem& instance,
                             std::string_view source, const AttemptScoreOptions& options) {
  if (options.horizon < 0 || options.horizon > instance.deadline()) {
    throw UsageError("the horizon must be between 1 and the instance's deadline (" +
                     std::to_string(instance.deadline()) + " steps)");
  }
  if (!(options.floor > 0 && options.floor < 1)) throw UsageError("the probability floor must be in (0, 1)");
  const Steps horizon = options.horizon > 0 ? options.horizon : instance.deadline();
  const double step = instance.step_seconds();

  AttemptScores scores;
  std::unordered_map<std::string, int> index;
  for (int a = 0; a < instance.action_count(); ++a) index.emplace(instance.action(a).id, a);
  std::vector<Outcome> outcomes;
  outcomes.reserve(attempts.size());
  for (const RefinementAttempt& attempt : attempts) {
    const auto found = index.find(attempt.action);
    if (found == index.end()) {
      if (options.skip_unknown) {
        ++scores.skipped;
        continue;
      }
      throw UsageError(std::string(source) + ": the instance has no action " + attempt.action);
    }
    Outcome outcome{.action = found->second};
    if (attempt.found) {
      // As fitting.cpp: a motion found at once took its first step.
      const Steps t = std::max<Steps>(1, steps_to_complete(attempt.planning_seconds, step));
      outcome.event = t <= horizon;
      outcome.time = std::min(t, horizon);
      outcome.execution = steps_to_complete(attempt.execution_seconds, step);
    } else {
      outcome.time = std::min(whole_steps_within(attempt.planning_seconds, step), horizon);
    }
    outcomes.push_back(outcome);
  }
  if (outcomes.empty()) throw UsageError(std::string(source) + ": no attempt to score");
  scores.attempts = outcomes.size();

  const auto probability = [&](double p) {
    if (p >= options.floor) return p;
    ++scores.floored;
    return options.floor;
  };
  const auto H = static_cast<std::size_t>(horizon);
  // Censoring law, K(t) = P(C >= t), by Kaplan-Meier: censoring at c comes after the step c
  // (an attempt found at c is not at risk of it; one found later, or cut off at c or later, is).
  std::vector<double> censored_at(H + 1, 0.0), events_at(H + 1, 0.0);
  for (const Outcome& outcome : outcomes) {
    (outcome.event ? events_at : censored_at)[static_cast<std::size_t>(outcome.time)] += 1;
  }
  std::vector<double> at_least(H + 2, 1.0);  // K(t), t = 0..H+1
  auto at_risk = static_cast<double>(outcomes.size());
  for (std::size_t c = 0; c <= H; ++c) {
    at_risk -= events_at[c];  // found at c: not at risk of censoring at c
    const double keep = at_risk > 0 ? 1.0 - censored_at[c] / at_risk : 0.0;
    at_least[c + 1] = at_least[c] * keep;
    at_risk -= censored_at[c];
  }

  double planning_nll = 0, execution_nll = 0;
  std::vector<double> brier(H + 1, 0.0);  // sum of weighted squared errors at t = 1..H
  std::vector<double> survival(H + 1);
  for (const Outcome& outcome : outcomes) {
    const Action& action = instance.action(outcome.action);
    if (outcome.event) {
      ++scores.found;
      planning_nll -= std::log(probability(action.planning.pmf(outcome.time)));
    } else {
      ++scores.censored;
      planning_nll -= std::log(probability(action.planning.survival(outcome.time)));
    }
    if (outcome.execution >= 0) {
      ++scores.executions;
      const double p =
          outcome.execution <= horizon ? action.execution.pmf(outcome.execution) : action.execution.survival(horizon);
      execution_nll -= std::log(probability(p));
    }
    for (std::size_t t = 1; t <= H; ++t) survival[t] = action.planning.survival(static_cast<Steps>(t));
    const auto time = static_cast<std::size_t>(outcome.time);
    for (std::size_t t = 1; t <= H; ++t) {
      if (outcome.event && time <= t) {
        // Known found by t; seen only when the censoring came no earlier than the event.
        if (at_least[time] > 0) brier[t] += survival[t] * survival[t] / at_least[time];
      } else if (time >= t) {
        // Known not found by t (found later, or cut off at t or later).
        if (at_least[t] > 0) brier[t] += (1 - survival[t]) * (1 - survival[t]) / at_least[t];
      }
    }
  }
  const auto n = static_cast<double>(outcomes.size());
  scores.planning_nll = planning_nll / n;
  double integrated = 0;
  for (std::size_t t = 1; t <= H; ++t) integrated += brier[t] / n;
  scores.integrated_brier = integrated / static_cast<double>(H);
  scores.execution_nll = scores.executions > 0 ? execution_nll / static_cast<double>(scores.executions) : 0.0;
  return scores;
}

}  // namespace ontime
