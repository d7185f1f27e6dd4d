#pragma once
// What `ontime fit --conditional` prints and Python's fit_conditional returns beside the model
// file: the kind, the training data (rows, worlds, found share), the horizon and the planning
// log-likelihood per row where the kind has one; and a table of predicted means for reading.

#include <span>
#include <string>

#include "ontime/learn/conditional_model.hpp"

namespace ontime::report {

// JSON object: kind, feature_names, step_seconds, horizon, rows, worlds, found (share of rows),
// model (the output path, when given), parameters (the kind's members of the model file, but for
// the boosted kind's boosters).
std::string conditional_fit_json(const ConditionalTimeModel& model, const ConditionalData& data,
                                 const std::string& output);
std::string conditional_fit_text(const ConditionalTimeModel& model, const ConditionalData& data,
                                 const std::string& output);

}  // namespace ontime::report
