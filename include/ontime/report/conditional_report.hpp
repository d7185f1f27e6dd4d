#pragma once
// What `ontime fit --conditional` prints and Python's fit_conditional returns beside the model
// file: the kind, the training data (rows, worlds, found share), the horizon and the planning
// log-likelihood per row where the kind has one; and a table of predicted means for reading.

#include <span>
#include <string>

#include "ontime/learn/attempt_scores.hpp"
#include "ontime/learn/conditional_model.hpp"

namespace ontime::report {

// JSON object: kind, feature_names, step_seconds, horizon, rows, worlds, found (share of rows),
// model (the output path, when given), parameters (the kind's members of the model file, but for
// the boosted kind's boosters).
std::string conditional_fit_json(const ConditionalTimeModel& model, const ConditionalData& data,
                                 const std::string& output);
std::string conditional_fit_text(const ConditionalTimeModel& model, const ConditionalData& data,
                                 const std::string& output);

// What `ontime score` prints: the instance scored (as given), its deadline and the horizon, the
// attempts (found, censored, skipped) and the three scores of attempt_scores.hpp. JSON members:
// instance, logs, horizon, attempts, found, censored, skipped, planning_nll, integrated_brier,
// executions, execution_nll, floored, floor.
struct ScoreReport {
  std::string instance;
  std::span<const std::string> logs;
  const Problem* problem = nullptr;
  AttemptScoreOptions options;
  AttemptScores scores;
};
// The JSON object of `ontime score --json`, with the members above.
std::string attempt_scores_json(const ScoreReport& report);
// The text of `ontime score`: the same for people.
std::string attempt_scores_text(const ScoreReport& report);

}  // namespace ontime::report
