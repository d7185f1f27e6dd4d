#pragma once
// Conditional time models: an action's planning- and execution-time distributions predicted from
// its feature vector (docs/learning.md), so that a world never refined before gets an instance
// from its geometry alone. Trained on planner-log records that carry features (a corpus across
// worlds: `collect --features`), with right-censoring as in fitting.hpp.
//
// Every kind (conditional_model_kinds()) has fit (fit_conditional_model), predict, declared
// parameters and a model file with its format version. Predictions are in whole steps of the
// training data's step: planning over 1..horizon with the rest "never" (not found within the
// collection's cut-off, or later), execution over 0..horizon with the rest "never".
//
// The kinds:
//   pooled  Kaplan-Meier planning and empirical execution over every record, features ignored:
//           what a user without conditional models has (pooled_time_model.hpp).
//   hazard  a discrete-time logistic hazard with a cure fraction for planning and a log-normal
//           regression for execution (hazard_time_model.hpp).
//   boosted gradient-boosted trees (XGBoost): a cure fraction and an accelerated failure time
//           for planning, fitted together to the right-censored likelihood, and a log-normal
//           execution time whose location is boosted (boosted_time_model.hpp).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/model/distribution.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/model/problem.hpp"

namespace ontime {

// The training set: one row per attempt, in whole steps (steps_to_complete, whole_steps_within).
struct ConditionalData {
  std::size_t feature_count = 0;
  std::vector<double> features;           // row-major: row i at [i * feature_count, (i + 1) * feature_count)
  std::vector<Steps> planning;            // found: steps to find (>= 1); cut off: whole steps survived
  std::vector<std::uint8_t> found;        // 1: found, 0: cut off (right-censored)
  std::vector<double> execution_seconds;  // found rows only (0 for the others)
  std::vector<std::string> worlds;        // the record's world ("" when it names none)
  std::vector<std::string> actions;
  double step_seconds = 1;
  // The largest magnitude of a feature (conditional_data refuses larger ones).
  static constexpr double kMaxFeature = 1e15;

  // The attempts: one row each.
  std::size_t rows() const noexcept { return planning.size(); }
  // Row i's features (feature_count of them).
  std::span<const double> row(std::size_t i) const noexcept {
    return std::span<const double>(features).subspan(i * feature_count, feature_count);
  }
};

// The rows of `attempts`. Throws InputError (source, "record N") for a record without features
// (every record of the corpus must carry them), UsageError for a step that is not positive.
ConditionalData conditional_data(std::span<const RefinementAttempt> attempts, double step_seconds,
                                 std::string_view source);

// The rows of several planner logs (JSON Lines, docs/formats.md), in order: a corpus of one log
// per world or one for many. Throws InputError naming the log and record (no features, another
// feature count than the first log's), UsageError for no logs.
ConditionalData load_conditional_data(std::span<const std::filesystem::path> logs, double step_seconds);

struct PredictedTimes {
  Distribution planning;   // over 1..horizon, the rest "never"
  Distribution execution;  // over 0..horizon, the rest "never"
};

// A declared parameter of a kind: its name, default (as text) and meaning (docs, --help, Python).
struct ConditionalParameter {
  std::string name, default_value, meaning;
};

struct ConditionalModelKind {
  std::string name, description;
  std::vector<ConditionalParameter> parameters;
};

// Every kind of conditional model, with its declared parameters, in the order the tools list them.
const std::vector<ConditionalModelKind>& conditional_model_kinds();

struct ConditionalFitOptions {
  std::string kind = "hazard";
  std::vector<std::string> feature_names;  // as many as the data's features; empty: f1, f2, ...
  Steps horizon = 0;                       // steps predicted; 0: the largest planning step of the data
  // hazard: L2 penalty on the standardised feature weights (not on the baseline).
  double ridge = 1e-3;  // 0 to kMaxRidge
  // The largest ridge: beyond it the penalty alone sets the weights (to 0), and NLopt's L-BFGS fails
  // on some of the objective's scales (a ridge of 1e10 did, 1e12 did not).
  static constexpr double kMaxRidge = 1e6;
  // hazard: baseline bins over 1..horizon (each bin one hazard level); 0: one per step.
  int bins = 0;
  // boosted: boosting rounds (the trees of each booster, 1 to 10000), a tree's largest depth (1 to
  // 16), the shrinkage of each tree (XGBoost's eta, in (0, 1]) and the least hessian sum of a leaf
  // (XGBoost's min_child_weight, >= 0).
  int trees = 100;
  int depth = 3;
  double learning_rate = 0.3;
  double min_child_weight = 1;
  // boosted: the law of the planning time T of an attempt that finds, log T = m(x) + aft_scale * e,
  // with e "normal", "logistic" or "extreme" (the Gumbel minimum: T is Weibull, exponential at
  // scale 1); aft_scale > 0 (at most 100).
  std::string aft_distribution = "normal";
  double aft_scale = 1;
};

class ConditionalTimeModel;

// The rows of planner logs scored or updated with `model` (its step): as load_conditional_data,
// and an InputError naming the first log when its records carry another number of features than
// the model takes (`model_file` names the model in the message).
ConditionalData load_conditional_data_for(const ConditionalTimeModel& model, std::string_view model_file,
                                          std::span<const std::filesystem::path> logs);

class ConditionalTimeModel {
 public:
  // The model file's format and the version this build reads and writes.
  static constexpr std::string_view kFormat = "ontime-conditional-time-model";
  static constexpr int kVersion = 1;

  virtual ~ConditionalTimeModel() = default;
  // The kind's name, as conditional_model_kinds() lists it ("hazard", "boosted", "pooled").
  virtual const std::string& kind() const noexcept = 0;

  // The features a prediction takes, by name, in order (a world's feature vector must match).
  const std::vector<std::string>& feature_names() const noexcept { return feature_names_; }
  // How many features a prediction takes.
  std::size_t feature_count() const noexcept { return feature_names_.size(); }
  // Seconds of one step of the training data (the predicted distributions are in these steps).
  double step_seconds() const noexcept { return step_seconds_; }
  // Steps predicted: planning over 1..horizon, execution over 0..horizon, the rest "never".
  Steps horizon() const noexcept { return horizon_; }
  // The attempts it was fitted on.
  std::size_t training_rows() const noexcept { return training_rows_; }
  // The worlds those attempts came from.
  std::size_t training_worlds() const noexcept { return training_worlds_; }

  // Throws UsageError for a vector of the wrong length or with a number that is not finite, and,
  // for a model read from a file, InputError naming the file and `parameters` when its numbers
  // give tables that are not distributions for these features (finite numbers that overflow).
  PredictedTimes predict(std::span<const double> features) const;
  // The check of predict alone: UsageError for a vector predict refuses.
  void check_features(std::span<const double> features) const;
  // predict of each of `count` feature vectors laid out row after row in `rows` (row-major), the
  // same distributions as one call each, at a lower cost per row for a kind whose every call has
  // a fixed cost (boosted). UsageError for rows of the wrong total length or a number that is not
  // finite (naming the row); InputError as predict.
  std::vector<PredictedTimes> predict_rows(std::span<const double> rows, std::size_t count) const;

  // The model file it was read from (parse_conditional_model's `source`), or empty when fitted.
  const std::string& source() const noexcept { return source_; }
  // Records the file it was read from.
  void set_source(std::string source) { source_ = std::move(source); }

  // The model file (JSON, one object): format, version, kind, feature names, step, horizon,
  // training summary and the kind's parameters.
  std::string to_json() const;

 protected:
  ConditionalTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon,
                       std::size_t training_rows, std::size_t training_worlds);
  virtual PredictedTimes predict_checked(std::span<const double> features) const = 0;
  // By default predict_checked of each row.
  virtual std::vector<PredictedTimes> predict_rows_checked(std::span<const double> rows, std::size_t count) const;
  // The kind's own members of the model file, as a JSON object's text.
  virtual std::string parameters_json() const = 0;

 private:
  // Within a catch of a prediction's UsageError: InputError naming the model file, or the error again.
  [[noreturn]] void throw_for_parameters() const;

  std::vector<std::string> feature_names_;
  double step_seconds_;
  Steps horizon_;
  std::size_t training_rows_, training_worlds_;
  std::string source_;
};

// Fits the kind `options.kind` (UsageError for an unknown kind, bad options, no rows, or
// feature names that do not match the data).
std::unique_ptr<ConditionalTimeModel> fit_conditional_model(const ConditionalData& data,
                                                            const ConditionalFitOptions& options);

// Reads a model file; InputError naming the file, the place and the rule (another format or
// version, an unknown kind, a bad member).
std::unique_ptr<ConditionalTimeModel> load_conditional_model(const std::filesystem::path& path);
std::unique_ptr<ConditionalTimeModel> parse_conditional_model(std::string_view text, std::string_view source);

// An action of a world to predict: its id and feature vector.
struct ActionFeatures {
  std::string id;
  std::vector<double> features;
};

// The instance whose actions' distributions the model predicts, truncated to `deadline` (mass
// beyond it is "never"): skeletons as action ids (every one must be among `actions`), or, when
// `skeletons` is empty, one single-action skeleton per action (a library). Throws UsageError for
// a deadline out of range, an unknown action, or a feature vector the model refuses.
Problem predict_problem(const ConditionalTimeModel& model, std::span<const ActionFeatures> actions,
                        const std::vector<std::vector<std::string>>& skeletons, Steps deadline, std::string name,
                        std::string description = {});

}  // namespace ontime
