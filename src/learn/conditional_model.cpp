#include "ontime/learn/conditional_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "learn/conditional_kinds.hpp"
#include "ontime/learn/boosted_time_model.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/learn/hazard_time_model.hpp"
#include "ontime/learn/pooled_time_model.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

using detail::ModelJson;

std::string record_place(std::size_t i) { return "record " + std::to_string(i + 1); }

}  // namespace

ConditionalData conditional_data(std::span<const RefinementAttempt> attempts, double step_seconds,
                                 std::string_view source) {
  if (!(std::isfinite(step_seconds) && step_seconds > 0))
    throw UsageError("the step must be a positive number of seconds");
  ConditionalData data;
  data.step_seconds = step_seconds;
  data.feature_count = attempts.empty() ? 0 : attempts.front().features.size();
  data.features.reserve(attempts.size() * data.feature_count);
  for (std::size_t i = 0; i < attempts.size(); ++i) {
    const RefinementAttempt& attempt = attempts[i];
    if (attempt.features.empty()) {
      throw InputError(std::string(source), record_place(i),
                       "has no 'features': a conditional model learns from records that carry the action's feature "
                       "vector (collect --features)");
    }
    if (attempt.features.size() != data.feature_count) {
      throw InputError(std::string(source), record_place(i),
                       "has " + std::to_string(attempt.features.size()) + " features, the first record " +
                           std::to_string(data.feature_count));
    }
    for (std::size_t f = 0; f < attempt.features.size(); ++f) {
      if (!(std::abs(attempt.features[f]) <= ConditionalData::kMaxFeature)) {
        throw InputError(std::string(source), record_place(i) + ": features[" + std::to_string(f) + "]",
                         "a feature must be within [-1e15, 1e15] (the boosted kind computes in 32-bit floats and "
                         "the hazard kind squares the features)");
      }
    }
    data.features.insert(data.features.end(), attempt.features.begin(), attempt.features.end());
    data.found.push_back(attempt.found ? 1 : 0);
    // Rounded as `fit` rounds them: a motion found within no time took its first step.
    data.planning.push_back(attempt.found
                                ? std::max<Steps>(1, steps_to_complete(attempt.planning_seconds, step_seconds))
                                : whole_steps_within(attempt.planning_seconds, step_seconds));
    data.execution_seconds.push_back(attempt.found ? attempt.execution_seconds : 0.0);
    data.worlds.push_back(attempt.world.value_or(""));
    data.actions.push_back(attempt.action);
  }
  return data;
}

ConditionalData load_conditional_data(std::span<const std::filesystem::path> logs, double step_seconds) {
  if (logs.empty()) throw UsageError("no planner logs to fit a conditional model to");
  ConditionalData data;
  for (const std::filesystem::path& path : logs) {
    ConditionalData part = conditional_data(load_planner_log(path), step_seconds, path.string());
    if (&path == &logs.front()) {
      data = std::move(part);
      continue;
    }
    if (part.feature_count != data.feature_count) {
      throw InputError(path.string(), "record 1",
                       "has " + std::to_string(part.feature_count) + " features, the records of " +
                           logs.front().string() + " " + std::to_string(data.feature_count));
    }
    const auto append = [](auto& to, auto& from) {
      to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
    };
    append(data.features, part.features);
    append(data.planning, part.planning);
    append(data.found, part.found);
    append(data.execution_seconds, part.execution_seconds);
    append(data.worlds, part.worlds);
    append(data.actions, part.actions);
  }
  return data;
}

ConditionalData load_conditional_data_for(const ConditionalTimeModel& model, std::string_view model_file,
                                          std::span<const std::filesystem::path> logs) {
  ConditionalData data = load_conditional_data(logs, model.step_seconds());
  // Every log has the first one's feature count (load_conditional_data): a mismatch is its first record's.
  if (data.feature_count != model.feature_count()) {
    throw InputError(logs.front().string(), "record 1",
                     "has " + std::to_string(data.feature_count) + " features, the model " + std::string(model_file) +
                         " takes " + std::to_string(model.feature_count()));
  }
  return data;
}

const std::vector<ConditionalModelKind>& conditional_model_kinds() {
  static const std::vector<ConditionalModelKind> kinds{
      {PooledTimeModel::kind_name(),
       "Kaplan-Meier planning and empirical execution over every record, features ignored (what one pooled fit "
       "gives)",
       {}},
      {HazardTimeModel::kind_name(),
       "Discrete-time logistic hazard with a cure fraction (planning, right-censored) and log-normal regression "
       "(execution) on the standardised features",
       {{"ridge", "0.001", "L2 penalty on the feature weights (>= 0)"},
        {"bins", "0", "baseline hazard levels over 1..horizon, log-spaced (0: one per step)"}}},
      {BoostedTimeModel::kind_name(),
       "Gradient-boosted trees (XGBoost): a cure fraction and an accelerated failure time fitted together to the "
       "right-censored planning times, and a log-normal execution time with a boosted location",
       {{"trees", "100", "boosting rounds: the trees of each booster (1 to 10000)"},
        {"depth", "3", "a tree's largest depth (1 to 16)"},
        {"learning_rate", "0.3", "the shrinkage of each tree, XGBoost's eta (in (0, 1])"},
        {"min_child_weight", "1", "the least hessian sum of a leaf (>= 0)"},
        {"aft_distribution", "normal",
         "the law of log(planning time) of an attempt that finds: normal, logistic or extreme (Weibull times)"},
        {"aft_scale", "1", "the scale of that law (> 0, at most 100)"}}},
  };
  return kinds;
}

ConditionalTimeModel::ConditionalTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon,
                                           std::size_t training_rows, std::size_t training_worlds)
    : feature_names_(std::move(feature_names)),
      step_seconds_(step_seconds),
      horizon_(horizon),
      training_rows_(training_rows),
      training_worlds_(training_worlds) {}

void ConditionalTimeModel::check_features(std::span<const double> features) const {
  if (features.size() != feature_count()) {
    throw UsageError("the " + kind() + " model takes " + std::to_string(feature_count()) + " features, got " +
                     std::to_string(features.size()));
  }
  for (std::size_t i = 0; i < features.size(); ++i) {
    if (!std::isfinite(features[i])) {
      throw UsageError("feature " + std::to_string(i + 1) + " (" + feature_names_[i] + ") is not a finite number");
    }
  }
}

PredictedTimes ConditionalTimeModel::predict(std::span<const double> features) const {
  check_features(features);
  try {
    return predict_checked(features);
  } catch (const UsageError&) {
    throw_for_parameters();
  }
}

void ConditionalTimeModel::throw_for_parameters() const {
  // The features were checked: what fails now is the model's numbers (finite, each within the
  // file's rules, but overflowing together), which a file brings.
  try {
    throw;
  } catch (const UsageError& error) {
    if (source_.empty()) throw;
    throw InputError(source_, "parameters",
                     std::string("the model's numbers overflow for some features: ") + error.what());
  }
}

std::vector<PredictedTimes> ConditionalTimeModel::predict_rows(std::span<const double> rows, std::size_t count) const {
  if (rows.size() != count * feature_count()) {
    throw UsageError(std::to_string(count) + " rows of the " + kind() + " model's " + std::to_string(feature_count()) +
                     " features are " + std::to_string(count * feature_count()) + " numbers, got " +
                     std::to_string(rows.size()));
  }
  for (std::size_t r = 0; r < count; ++r) {
    try {
      check_features(rows.subspan(r * feature_count(), feature_count()));
    } catch (const UsageError& error) {
      throw UsageError("row " + std::to_string(r + 1) + ": " + error.what());
    }
  }
  if (count == 0) return {};
  try {
    return predict_rows_checked(rows, count);
  } catch (const UsageError&) {
    throw_for_parameters();
  }
}

std::vector<PredictedTimes> ConditionalTimeModel::predict_rows_checked(std::span<const double> rows,
                                                                       std::size_t count) const {
  std::vector<PredictedTimes> out;
  out.reserve(count);
  for (std::size_t r = 0; r < count; ++r)
    out.push_back(predict_checked(rows.subspan(r * feature_count(), feature_count())));
  return out;
}

std::string ConditionalTimeModel::to_json() const {
  ModelJson json = ModelJson::object();
  json["format"] = std::string(kFormat);
  json["version"] = kVersion;
  json["kind"] = kind();
  json["feature_names"] = feature_names_;
  json["step_seconds"] = step_seconds_;
  json["horizon"] = horizon_;
  json["training"] = {{"rows", training_rows_}, {"worlds", training_worlds_}};
  json["parameters"] = ModelJson::parse(parameters_json());
  return json.dump(2) + "\n";
}

std::unique_ptr<ConditionalTimeModel> fit_conditional_model(const ConditionalData& data,
                                                            const ConditionalFitOptions& options) {
  if (data.rows() == 0) throw UsageError("no records to fit a conditional model to");
  std::vector<std::string> names = options.feature_names;
  if (names.empty()) {
    for (std::size_t i = 0; i < data.feature_count; ++i) names.push_back("f" + std::to_string(i + 1));
  }
  if (names.size() != data.feature_count) {
    throw UsageError(std::to_string(names.size()) + " feature names for records of " +
                     std::to_string(data.feature_count) + " features");
  }
  Steps horizon = options.horizon;
  if (horizon == 0) {
    for (const Steps t : data.planning) horizon = std::max(horizon, t);
    horizon = std::max<Steps>(horizon, 1);
  }
  if (horizon < 1 || horizon > Problem::kMaxDeadline) {
    throw UsageError("the horizon must be between 1 and " + std::to_string(Problem::kMaxDeadline) + " steps");
  }
  if (options.kind == PooledTimeModel::kind_name()) return PooledTimeModel::fit(data, std::move(names), horizon);
  if (options.kind == HazardTimeModel::kind_name()) {
    if (!(options.ridge >= 0 && options.ridge <= ConditionalFitOptions::kMaxRidge)) {
      throw UsageError("the ridge must be a number from 0 to 1e6");
    }
    if (options.bins < 0 || options.bins > horizon) {
      throw UsageError("the bins must be between 0 and the horizon (" + std::to_string(horizon) + ")");
    }
    return HazardTimeModel::fit(data, std::move(names), horizon, options.ridge, options.bins);
  }
  if (options.kind == BoostedTimeModel::kind_name()) {
    BoostedSettings settings;
    settings.trees = options.trees;
    settings.depth = options.depth;
    settings.learning_rate = options.learning_rate;
    settings.min_child_weight = options.min_child_weight;
    settings.aft_distribution = options.aft_distribution;
    settings.aft_scale = options.aft_scale;
    return BoostedTimeModel::fit(data, std::move(names), horizon, settings);
  }
  std::vector<std::string> known;
  for (const ConditionalModelKind& kind : conditional_model_kinds()) known.push_back(kind.name);
  throw unknown_name_error("conditional model kind", options.kind, known);
}

// ---- model files ----

namespace detail {

const ModelJson& ParameterReader::at(const std::string& key) const {
  if (!parameters_.contains(key)) fail(key, "missing");
  return parameters_[key];
}

void ParameterReader::fail(const std::string& key, const std::string& rule) const {
  throw InputError(source_, "parameters." + key, rule);
}

std::string ParameterReader::text(const std::string& key) const {
  const ModelJson& value = at(key);
  if (!value.is_string()) fail(key, "must be a string");
  return value.get<std::string>();
}

double ParameterReader::real(const std::string& key) const {
  const ModelJson& value = at(key);
  if (!value.is_number() || !std::isfinite(value.get<double>())) fail(key, "must be a finite number");
  return value.get<double>();
}

std::vector<double> ParameterReader::reals(const std::string& key, std::size_t size) const {
  const ModelJson& value = at(key);
  if (!value.is_array()) fail(key, "must be an array of numbers");
  if (size != 0 && value.size() != size) fail(key, "must hold " + std::to_string(size) + " numbers");
  std::vector<double> out;
  for (const ModelJson& item : value) {
    if (!item.is_number() || !std::isfinite(item.get<double>())) fail(key, "must hold finite numbers only");
    out.push_back(item.get<double>());
  }
  return out;
}

std::vector<int> ParameterReader::whole_numbers(const std::string& key) const {
  const ModelJson& value = at(key);
  if (!value.is_array() || value.empty()) fail(key, "must be a non-empty array of whole numbers");
  std::vector<int> out;
  for (const ModelJson& item : value) {
    const auto number =
        detail::json_whole_number(item, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
    if (!number) fail(key, "must hold whole numbers of 32 bits only");
    out.push_back(static_cast<int>(*number));
  }
  return out;
}

}  // namespace detail

std::unique_ptr<ConditionalTimeModel> parse_conditional_model(std::string_view text, std::string_view source) {
  const std::string name(source);
  const auto json = detail::parse_json_strict<ModelJson>(text, name);
  const auto fail = [&](const std::string& place, const std::string& rule) -> void {
    throw InputError(name, place, rule);
  };
  if (!json.is_object()) fail("file", "a conditional time model is a JSON object");
  if (!json.contains("format") || json["format"] != std::string(ConditionalTimeModel::kFormat)) {
    fail("format", "not a conditional time model (expected \"" + std::string(ConditionalTimeModel::kFormat) + "\")");
  }
  // Whole numbers by the instance reader's rules (`1` or `1.0`; nothing truncated to 32 bits).
  if (!json.contains("version") ||
      detail::json_whole_number(json["version"], std::numeric_limits<std::int64_t>::min(),
                                std::numeric_limits<std::int64_t>::max()) != ConditionalTimeModel::kVersion) {
    fail("version", "this OnTime reads version " + std::to_string(ConditionalTimeModel::kVersion) +
                        " of the model format (got " +
                        (json.contains("version") ? detail::quote_json(json["version"]) : "none") + ")");
  }
  detail::ModelHeader header;
  if (!json.contains("feature_names") || !json["feature_names"].is_array())
    fail("feature_names", "must be an array of names");
  for (const ModelJson& feature : json["feature_names"]) {
    if (!feature.is_string() || feature.get<std::string>().empty()) fail("feature_names", "must hold non-empty names");
    header.feature_names.push_back(feature.get<std::string>());
  }
  if (!json.contains("step_seconds") || !json["step_seconds"].is_number() ||
      !(json["step_seconds"].get<double>() > 0)) {
    fail("step_seconds", "must be a positive number of seconds");
  }
  header.step_seconds = json["step_seconds"].get<double>();
  const auto horizon =
      json.contains("horizon") ? detail::json_whole_number(json["horizon"], 1, Problem::kMaxDeadline) : std::nullopt;
  if (!horizon) fail("horizon", "must be a whole number of steps from 1 to " + std::to_string(Problem::kMaxDeadline));
  header.horizon = static_cast<Steps>(*horizon);
  if (json.contains("training") && json["training"].is_object()) {
    const ModelJson& training = json["training"];
    if (training.contains("rows") && training["rows"].is_number_unsigned())
      header.rows = training["rows"].get<std::size_t>();
    if (training.contains("worlds") && training["worlds"].is_number_unsigned()) {
      header.worlds = training["worlds"].get<std::size_t>();
    }
  }
  if (!json.contains("parameters") || !json["parameters"].is_object()) fail("parameters", "must be an object");
  const detail::ParameterReader reader(json["parameters"], name);
  const std::string kind = json.contains("kind") && json["kind"].is_string() ? json["kind"].get<std::string>() : "";
  std::unique_ptr<ConditionalTimeModel> model;
  if (kind == PooledTimeModel::kind_name()) {
    model = detail::read_pooled_model(reader, std::move(header));
  } else if (kind == HazardTimeModel::kind_name()) {
    model = detail::read_hazard_model(reader, std::move(header));
  } else if (kind == BoostedTimeModel::kind_name()) {
    model = detail::read_boosted_model(reader, std::move(header));
  }
  if (model) {
    model->set_source(name);
    return model;
  }
  std::string known;
  for (const ConditionalModelKind& k : conditional_model_kinds()) known += (known.empty() ? "" : ", ") + k.name;
  throw InputError(name, "kind", "unknown kind '" + kind + "' (known: " + known + ")");
}

std::unique_ptr<ConditionalTimeModel> load_conditional_model(const std::filesystem::path& path) {
  return parse_conditional_model(read_input_file(path, "conditional time model"), path.string());
}

Problem predict_problem(const ConditionalTimeModel& model, std::span<const ActionFeatures> actions,
                        const std::vector<std::vector<std::string>>& skeletons, Steps deadline, std::string name,
                        std::string description) {
  if (deadline < 1 || deadline > Problem::kMaxDeadline) {
    throw UsageError("the deadline must be between 1 and " + std::to_string(Problem::kMaxDeadline) + " steps");
  }
  // Mass beyond the deadline is "never": the PMF cut at the deadline.
  const auto truncated = [deadline](const Distribution& distribution) {
    std::vector<double> masses(distribution.masses().begin(), distribution.masses().end());
    if (masses.size() > static_cast<std::size_t>(deadline) + 1) masses.resize(static_cast<std::size_t>(deadline) + 1);
    return Distribution::from_pmf(std::move(masses));
  };
  // The distinct actions (the first of each id), checked one by one (an error names the action),
  // then predicted in one call.
  std::map<std::string, int> index_of;
  std::vector<const ActionFeatures*> distinct;
  std::vector<double> rows;
  for (const ActionFeatures& action : actions) {
    if (!index_of.emplace(action.id, static_cast<int>(distinct.size())).second) continue;
    try {
      model.check_features(action.features);
    } catch (const UsageError& error) {
      throw UsageError(action.id + ": " + error.what());
    }
    distinct.push_back(&action);
    rows.insert(rows.end(), action.features.begin(), action.features.end());
  }
  const std::vector<PredictedTimes> times = model.predict_rows(rows, distinct.size());
  std::vector<Action> predicted;
  for (std::size_t a = 0; a < distinct.size(); ++a) {
    predicted.emplace_back(distinct[a]->id, truncated(times[a].planning), truncated(times[a].execution));
  }
  std::vector<std::vector<int>> indices;
  if (skeletons.empty()) {
    for (int a = 0; a < static_cast<int>(predicted.size()); ++a) indices.push_back({a});
  } else {
    for (const std::vector<std::string>& skeleton : skeletons) {
      std::vector<int> row;
      for (const std::string& id : skeleton) {
        const auto found = index_of.find(id);
        if (found == index_of.end()) throw UsageError("no features for action '" + id + "' of a skeleton");
        row.push_back(found->second);
      }
      indices.push_back(std::move(row));
    }
  }
  return Problem(std::move(name), deadline, model.step_seconds(), std::move(predicted), std::move(indices),
                 std::move(description));
}

}  // namespace ontime
