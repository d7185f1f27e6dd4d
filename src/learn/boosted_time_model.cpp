#include "ontime/learn/boosted_time_model.hpp"

#include <fmt/format.h>
#include <xgboost/c_api.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "learn/booster_check.hpp"
#include "learn/conditional_kinds.hpp"
#include "ontime/util/error.hpp"
#include "util/portable_math.hpp"

namespace ontime {
namespace {

// ---- XGBoost's C API ----

// A failed XGBoost call, with XGBoost's message: fit reports it as a UsageError, reading a model
// file as an InputError; anywhere else it is a defect of the library.
class XGBoostFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// XGBoost's last error: its first line, without the time stamp and source place it starts with
// ("[12:00:00] ./src/learner.cc:1008: Invalid model format") and the stack trace after it.
std::string last_error() {
  std::string text = XGBGetLastError();
  text.resize(std::min(text.size(), text.find('\n')));
  if (text.starts_with('[') && text.find("] ") != std::string::npos) text.erase(0, text.find("] ") + 2);
  const std::size_t colon = text.find(": ");
  if (colon != std::string::npos && text.substr(0, colon).find(' ') == std::string::npos &&
      text.substr(0, colon).find(':') != std::string::npos) {
    text.erase(0, colon + 2);
  }
  return text;
}

void check(int status, const char* doing) {
  if (status != 0) throw XGBoostFailure(std::string("XGBoost failed ") + doing + ": " + last_error());
}

// XGBoost prints its warnings unless told otherwise; its global configuration belongs to a thread.
void silence() {
  thread_local bool silenced = false;
  if (silenced) return;
  check(XGBSetGlobalConfig(R"({"verbosity": 0})"), "to set its verbosity");
  silenced = true;
}

// Owned handles. (Freeing does not fail on a valid handle; a destructor could not report it.)
struct MatrixFree {
  void operator()(void* handle) const noexcept { static_cast<void>(XGDMatrixFree(handle)); }
};
struct BoosterFree {
  void operator()(void* handle) const noexcept { static_cast<void>(XGBoosterFree(handle)); }
};
using DMatrix = std::unique_ptr<void, MatrixFree>;
using Booster = std::unique_ptr<void, BoosterFree>;

DMatrix dense_matrix(const std::vector<float>& values, std::size_t rows, std::size_t columns) {
  DMatrixHandle handle = nullptr;
  check(XGDMatrixCreateFromMat(values.data(), rows, columns, std::numeric_limits<float>::quiet_NaN(), &handle),
        "to make a matrix");
  return DMatrix(handle);
}

void set_info(const DMatrix& matrix, const char* field, const std::vector<float>& values) {
  check(XGDMatrixSetFloatInfo(matrix.get(), field, values.data(), values.size()),
        (std::string("to set the training rows' ") + field).c_str());
}

using Settings = std::vector<std::pair<const char*, std::string>>;

void set_parameters(const Booster& booster, const Settings& settings) {
  for (const auto& [name, value] : settings) {
    check(XGBoosterSetParam(booster.get(), name, value.c_str()), (std::string("to set ") + name).c_str());
  }
}

Booster training_booster(const DMatrix& matrix, const Settings& settings) {
  DMatrixHandle matrices[] = {matrix.get()};
  BoosterHandle handle = nullptr;
  check(XGBoosterCreate(matrices, 1, &handle), "to make a booster");
  Booster booster(handle);
  set_parameters(booster, settings);
  return booster;
}

// One thread and no messages: what every booster runs with (neither is part of the saved model).
const Settings& run_settings() {
  static const Settings settings{{"nthread", "1"}, {"verbosity", "0"}};
  return settings;
}

// The margins (sums of the trees and the base margin) of `rows` predictions, as an XGBoost
// prediction answers them.
std::vector<double> margins(int status, const bst_ulong* shape, bst_ulong dimensions, const float* values,
                            std::size_t rows) {
  check(status, "to predict");
  if (dimensions < 1 || shape[0] != rows) throw XGBoostFailure("XGBoost predicted another number of rows");
  std::vector<double> out(values, values + rows);
  return out;
}

// Margins of the training rows (XGBoost's prediction cache makes each call O(rows)).
std::vector<double> training_margins(const Booster& booster, const DMatrix& matrix, std::size_t rows) {
  const bst_ulong* shape = nullptr;
  bst_ulong dimensions = 0;
  const float* values = nullptr;
  const int status = XGBoosterPredictFromDMatrix(
      booster.get(), matrix.get(),
      R"({"type": 1, "training": false, "iteration_begin": 0, "iteration_end": 0, "strict_shape": false})", &shape,
      &dimensions, &values);
  return margins(status, shape, dimensions, values, rows);
}

std::string model_text(const Booster& booster) {
  bst_ulong length = 0;
  const char* text = nullptr;
  check(XGBoosterSaveModelToBuffer(booster.get(), R"({"format": "json"})", &length, &text), "to save a booster");
  return {text, static_cast<std::size_t>(length)};
}

// A booster from its model text; refused unless its objective is `objective` and it takes
// `features` features, and, with `aft`, unless it was fitted with that law and scale (XGBoost
// gives the scale in six digits).
Booster loaded_booster(const std::string& text, const std::string& objective, std::size_t features,
                       const BoostedSettings* aft = nullptr) {
  silence();
  BoosterHandle handle = nullptr;
  check(XGBoosterCreate(nullptr, 0, &handle), "to make a booster");
  Booster booster(handle);
  check(XGBoosterLoadModelFromBuffer(handle, text.data(), text.size()), "to read the booster");
  set_parameters(booster, run_settings());
  bst_ulong length = 0;
  const char* config = nullptr;
  check(XGBoosterSaveJsonConfig(handle, &length, &config), "to give the booster's configuration");
  using Json = detail::ModelJson;
  const Json json = Json::parse(config, config + length, nullptr, false);
  const auto member = [&json](const char* path) {
    const Json::json_pointer pointer(path);
    return !json.is_discarded() && json.contains(pointer) && json[pointer].is_string()
               ? json[pointer].get<std::string>()
               : std::string("none");
  };
  const std::string found = member("/learner/objective/name");
  if (found != objective) throw XGBoostFailure("a booster of objective " + found + ", not " + objective);
  if (aft != nullptr) {
    const std::string law = member("/learner/objective/aft_loss_param/aft_loss_distribution");
    const std::string scale = member("/learner/objective/aft_loss_param/aft_loss_distribution_scale");
    char* end = nullptr;
    const double value = std::strtod(scale.c_str(), &end);
    if (law != aft->aft_distribution || end == scale.c_str() ||
        !(std::abs(value - aft->aft_scale) <= 1e-5 * aft->aft_scale)) {
      throw XGBoostFailure("a booster fitted with aft_loss_distribution " + law + " and scale " + scale +
                           ", not the model's aft_distribution and aft_scale");
    }
  }
  bst_ulong count = 0;
  check(XGBoosterGetNumFeature(handle, &count), "to give the booster's feature count");
  if (count != features) {
    throw XGBoostFailure("a booster of " + std::to_string(count) + " features, the model has " +
                         std::to_string(features));
  }
  return booster;
}

// ---- the model's laws ----

enum class Law { normal, logistic, extreme };

Law law_of(const std::string& name) {
  if (name == "logistic") return Law::logistic;
  if (name == "extreme") return Law::extreme;
  return Law::normal;
}

// P(e > z) for the standard law (XGBoost's survival:aft's: the normal, the logistic, the Gumbel
// minimum with P(e <= z) = 1 - exp(-exp(z))).
double survival(Law law, double z) {
  switch (law) {
    case Law::logistic:
      return portable_logistic(-z);
    case Law::extreme:
      return portable_exp(-portable_exp(z));
    case Law::normal:
      break;
  }
  return 0.5 * portable_erfc(z / std::numbers::sqrt2);
}

// P(T > steps) for the planning booster's margin m: log T = log u + m + scale * e.
double planning_survival(const BoostedParameters& p, Law law, double steps, double margin) {
  if (steps <= 0) return 1;
  return survival(law, (portable_log(steps / p.planning_unit) - margin) / p.settings.aft_scale);
}

// The planning PMF over 1..H from the two margins (the rest "never").
std::vector<double> planning_pmf(const BoostedParameters& p, Law law, Steps horizon, double never_margin,
                                 double planning_margin) {
  const double finds = 1 - portable_logistic(never_margin);
  std::vector<double> masses(static_cast<std::size_t>(horizon) + 1, 0.0);
  double above = 1;  // S(t - 1)
  for (Steps t = 1; t <= horizon; ++t) {
    const double below = planning_survival(p, law, static_cast<double>(t), planning_margin);
    masses[static_cast<std::size_t>(t)] = finds * std::max(above - below, 0.0);
    above = below;
  }
  return masses;
}

// The execution PMF over 0..H (the hazard kind's discretisation of the log-normal).
std::vector<double> execution_pmf(double sigma, Steps horizon, double step_seconds, double mu) {
  std::vector<double> masses(static_cast<std::size_t>(horizon) + 1, 0.0);
  double below = 0;
  for (std::size_t k = 1; k <= static_cast<std::size_t>(horizon); ++k) {
    const double upper = 0.5 * portable_erfc(-((portable_log(static_cast<double>(k) * step_seconds) - mu) / sigma) /
                                             std::numbers::sqrt2);
    masses[k] = std::max(upper - below, 0.0);
    below = upper;
  }
  return masses;
}

// The planning rows: found at t (1..H) or cut off after c steps (0..H; found after the horizon is
// cut off at it).
struct PlanningRow {
  bool found = false;
  Steps steps = 0;
};

// log of a row's likelihood (found at t: (1 - pi)(S(t - 1) - S(t)); cut off after c: pi + (1 - pi) S(c)),
// at least log of the smallest normal double.
double log_likelihood(const BoostedParameters& p, Law law, const PlanningRow& row, double never_margin,
                      double planning_margin) {
  const double pi = portable_logistic(never_margin);
  const double s = planning_survival(p, law, static_cast<double>(row.steps), planning_margin);
  const double value =
      row.found ? (1 - pi) * (planning_survival(p, law, static_cast<double>(row.steps - 1), planning_margin) - s)
                : pi + (1 - pi) * s;
  return portable_log(std::max(value, std::numeric_limits<double>::min()));
}

std::string number_text(double value) { return fmt::format("{}", value); }

// The first setting out of its range: its name and rule.
std::optional<std::pair<std::string, std::string>> settings_error(const BoostedSettings& s) {
  if (s.trees < 1 || s.trees > 10000) return std::pair{"trees", "must be a whole number from 1 to 10000"};
  if (s.depth < 1 || s.depth > 16) return std::pair{"depth", "must be a whole number from 1 to 16"};
  if (!(s.learning_rate > 0 && s.learning_rate <= 1)) return std::pair{"learning_rate", "must be in (0, 1]"};
  if (!(s.min_child_weight >= 0 && std::isfinite(s.min_child_weight)))
    return std::pair{"min_child_weight", "must be a finite number >= 0"};
  if (s.aft_distribution != "normal" && s.aft_distribution != "logistic" && s.aft_distribution != "extreme")
    return std::pair{"aft_distribution", "must be normal, logistic or extreme"};
  if (!(s.aft_scale > 0 && s.aft_scale <= 100)) return std::pair{"aft_scale", "must be in (0, 100]"};
  return std::nullopt;
}

Settings tree_settings(const BoostedSettings& s) {
  Settings settings = run_settings();
  settings.insert(settings.end(), {{"tree_method", "exact"},
                                   {"seed", "0"},
                                   {"max_depth", std::to_string(s.depth)},
                                   {"eta", number_text(s.learning_rate)},
                                   {"min_child_weight", number_text(s.min_child_weight)}});
  return settings;
}

// The boosters' objectives.
constexpr const char* kNeverObjective = "binary:logistic";
constexpr const char* kPlanningObjective = "survival:aft";
constexpr const char* kExecutionObjective = "reg:squarederror";

// The execution booster: XGBoost's reg:squarederror on the log seconds, from their mean.
Booster execution_booster(const DMatrix& matrix, const std::vector<float>& log_seconds,
                          const BoostedSettings& settings) {
  set_info(matrix, "label", log_seconds);
  double sum = 0;
  for (const float y : log_seconds) sum += static_cast<double>(y);
  Settings booster_settings = tree_settings(settings);
  booster_settings.insert(
      booster_settings.end(),
      {{"objective", kExecutionObjective},
       {"base_score", number_text(log_seconds.empty() ? 0.0 : sum / static_cast<double>(log_seconds.size()))}});
  Booster booster = training_booster(matrix, booster_settings);
  for (int round = 0; round < settings.trees; ++round) {
    check(XGBoosterUpdateOneIter(booster.get(), round, matrix.get()), "to grow a tree of the execution booster");
  }
  return booster;
}

// sigma: the root mean square of the residuals out of fold. Found row j is in fold j % K (K = 5,
// or the rows when fewer) and predicted by a booster fitted on the other folds: the error of a
// prediction for an action the trees have not seen, which the training residuals understate by
// what the trees fit of the noise. (One row: its training residual, 0.) At least 1e-3.
double execution_sigma(const std::vector<float>& features, const std::vector<float>& log_seconds, std::size_t F,
                       const BoostedSettings& settings, const Booster& booster, const DMatrix& matrix) {
  const std::size_t rows = log_seconds.size();
  if (rows == 0) return 1;
  std::vector<double> predicted(rows);
  if (rows == 1) {
    predicted = training_margins(booster, matrix, rows);
  }
  const std::size_t folds = std::min<std::size_t>(5, rows);
  for (std::size_t fold = 0; rows > 1 && fold < folds; ++fold) {
    std::vector<float> kept_features, kept_labels, held_features;
    std::vector<std::size_t> held;
    for (std::size_t j = 0; j < rows; ++j) {
      const auto begin = features.begin() + static_cast<std::ptrdiff_t>(j * F);
      if (j % folds == fold) {
        held.push_back(j);
        held_features.insert(held_features.end(), begin, begin + static_cast<std::ptrdiff_t>(F));
      } else {
        kept_labels.push_back(log_seconds[j]);
        kept_features.insert(kept_features.end(), begin, begin + static_cast<std::ptrdiff_t>(F));
      }
    }
    const DMatrix kept = dense_matrix(kept_features, kept_labels.size(), F);
    const Booster without = execution_booster(kept, kept_labels, settings);
    const std::vector<double> margin =
        training_margins(without, dense_matrix(held_features, held.size(), F), held.size());
    for (std::size_t h = 0; h < held.size(); ++h) predicted[held[h]] = margin[h];
  }
  double squares = 0;
  for (std::size_t j = 0; j < rows; ++j) {
    squares +=
        (static_cast<double>(log_seconds[j]) - predicted[j]) * (static_cast<double>(log_seconds[j]) - predicted[j]);
  }
  return std::max(std::sqrt(squares / static_cast<double>(rows)), 1e-3);
}

}  // namespace

struct BoostedTimeModel::Boosters {
  Booster never, planning, execution;
  // XGBoost's predictions answer in a buffer of the booster's: one call at a time.
  std::mutex calls;
};

const std::string& BoostedTimeModel::kind_name() {
  static const std::string name = "boosted";
  return name;
}

BoostedTimeModel::BoostedTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon,
                                   std::size_t rows, std::size_t worlds, BoostedParameters parameters,
                                   std::unique_ptr<Boosters> boosters)
    : ConditionalTimeModel(std::move(feature_names), step_seconds, horizon, rows, worlds),
      parameters_(std::move(parameters)),
      boosters_(std::move(boosters)) {
  if (!boosters_ || !boosters_->never || !boosters_->planning || !boosters_->execution) {
    throw UsageError("a boosted model needs its three boosters");
  }
}

BoostedTimeModel::~BoostedTimeModel() = default;

std::unique_ptr<BoostedTimeModel> BoostedTimeModel::fit(const ConditionalData& data,
                                                        std::vector<std::string> feature_names, Steps horizon,
                                                        const BoostedSettings& settings) {
  if (const auto error = settings_error(settings)) throw UsageError("the " + error->first + " " + error->second);
  const std::size_t F = data.feature_count, N = data.rows();
  if (F == 0) throw UsageError("the boosted model needs at least one feature");
  BoostedParameters out;
  out.settings = settings;
  const Law law = law_of(settings.aft_distribution);
  const auto H = static_cast<std::size_t>(horizon);
  try {
    silence();
    std::vector<float> features(data.features.begin(), data.features.end());
    std::vector<PlanningRow> rows(N);
    std::vector<Steps> found_steps;
    for (std::size_t i = 0; i < N; ++i) {
      const auto t = static_cast<std::size_t>(data.planning[i]);
      rows[i] = {data.found[i] != 0 && t <= H, static_cast<Steps>(std::min(t, H))};
      if (rows[i].found) found_steps.push_back(rows[i].steps);
    }
    // The unit u: the (lower) median found step, so that the planning booster starts from a law
    // of median u (its base score 1: margin log 1 = 0, exact).
    if (!found_steps.empty()) {
      std::nth_element(found_steps.begin(),
                       found_steps.begin() + static_cast<std::ptrdiff_t>((found_steps.size() - 1) / 2),
                       found_steps.end());
      out.planning_unit = static_cast<int>(found_steps[(found_steps.size() - 1) / 2]);
    }
    const double u = out.planning_unit;
    std::vector<float> lower(N), upper(N), weight(N), gradient(N), hessian(N);
    for (std::size_t i = 0; i < N; ++i) {
      const auto steps = static_cast<double>(rows[i].steps);
      lower[i] = static_cast<float>((rows[i].found ? steps - 1 : steps) / u);
      upper[i] = rows[i].found ? static_cast<float>(steps / u) : std::numeric_limits<float>::infinity();
    }
    const DMatrix matrix = dense_matrix(features, N, F);
    set_info(matrix, "label_lower_bound", lower);
    set_info(matrix, "label_upper_bound", upper);
    Settings never_settings = tree_settings(settings), planning_settings = tree_settings(settings);
    never_settings.insert(never_settings.end(), {{"objective", kNeverObjective}, {"base_score", "0.5"}});
    planning_settings.insert(planning_settings.end(), {{"objective", kPlanningObjective},
                                                       {"aft_loss_distribution", settings.aft_distribution},
                                                       {"aft_loss_distribution_scale", number_text(settings.aft_scale)},
                                                       {"base_score", "1"}});
    const Booster never = training_booster(matrix, never_settings);
    const Booster planning = training_booster(matrix, planning_settings);
    std::vector<double> never_margin, planning_margin;
    for (int round = 0; round < settings.trees; ++round) {
      never_margin = training_margins(never, matrix, N);
      planning_margin = training_margins(planning, matrix, N);
      // The E step: w, the posterior probability that a cut-off row is never. The never
      // booster's gradient and hessian are the logistic loss's at label w (0 for a found row);
      // the planning booster weighs a cut-off row 1 - w.
      for (std::size_t i = 0; i < N; ++i) {
        const double pi = portable_logistic(never_margin[i]);
        double w = 0;
        if (!rows[i].found) {
          const double s = planning_survival(out, law, static_cast<double>(rows[i].steps), planning_margin[i]);
          w = s > 0 ? pi / (pi + (1 - pi) * s) : 1.0;
        }
        const bool informative = rows[i].found || rows[i].steps > 0;
        gradient[i] = informative ? static_cast<float>(pi - w) : 0.0F;
        hessian[i] = informative ? static_cast<float>(std::max(pi * (1 - pi), 1e-16)) : 0.0F;
        weight[i] = informative ? static_cast<float>(1 - w) : 0.0F;
      }
      set_info(matrix, "weight", weight);
      check(XGBoosterBoostOneIter(never.get(), matrix.get(), gradient.data(), hessian.data(), N),
            "to grow a tree of the never booster");
      check(XGBoosterUpdateOneIter(planning.get(), round, matrix.get()), "to grow a tree of the planning booster");
    }
    never_margin = training_margins(never, matrix, N);
    planning_margin = training_margins(planning, matrix, N);
    double total = 0;
    for (std::size_t i = 0; i < N; ++i) total += log_likelihood(out, law, rows[i], never_margin[i], planning_margin[i]);
    out.log_likelihood = total / static_cast<double>(N);

    // Execution: least squares on log(seconds) of every found row (found after the horizon too).
    std::vector<float> found_features, log_seconds;
    for (std::size_t i = 0; i < N; ++i) {
      if (data.found[i] == 0) continue;
      found_features.insert(found_features.end(), features.begin() + static_cast<std::ptrdiff_t>(i * F),
                            features.begin() + static_cast<std::ptrdiff_t>((i + 1) * F));
      log_seconds.push_back(
          static_cast<float>(portable_log(std::max(data.execution_seconds[i], 1e-6 * data.step_seconds))));
    }
    const std::size_t found = log_seconds.size();
    const DMatrix execution_matrix = dense_matrix(found_features, found, F);
    const Booster execution = execution_booster(execution_matrix, log_seconds, settings);
    out.execution_sigma = execution_sigma(found_features, log_seconds, F, settings, execution, execution_matrix);
    // The model predicts from the boosters read back from their text, as a model file's are; they
    // must give the trained boosters' margins on every training row, bit for bit (XGBoost writes
    // each float as the shortest decimal that reads back to it).
    auto boosters = std::make_unique<Boosters>();
    boosters->never = loaded_booster(model_text(never), kNeverObjective, F);
    boosters->planning = loaded_booster(model_text(planning), kPlanningObjective, F, &settings);
    boosters->execution = loaded_booster(model_text(execution), kExecutionObjective, F);
    if (training_margins(boosters->never, matrix, N) != never_margin ||
        training_margins(boosters->planning, matrix, N) != planning_margin ||
        (found > 0 && training_margins(boosters->execution, execution_matrix, found) !=
                          training_margins(execution, execution_matrix, found))) {
      throw std::logic_error("XGBoost read a booster back from its text to other predictions");
    }
    const std::set<std::string> worlds(data.worlds.begin(), data.worlds.end());
    return std::make_unique<BoostedTimeModel>(std::move(feature_names), data.step_seconds, horizon, N, worlds.size(),
                                              std::move(out), std::move(boosters));
  } catch (const XGBoostFailure& failure) {
    throw UsageError(std::string("the boosted model: ") + failure.what());
  }
}

PredictedTimes BoostedTimeModel::predict_checked(std::span<const double> features) const {
  return predict_rows_checked(features, 1).front();
}

std::vector<PredictedTimes> BoostedTimeModel::predict_rows_checked(std::span<const double> rows,
                                                                   std::size_t count) const {
  // XGBoost reads the rows in place (doubles, row-major; "missing" never occurs: every number is
  // finite).
  const std::string array = fmt::format(R"({{"data": [{}, true], "shape": [{}, {}], "typestr": "<f8", "version": 3}})",
                                        reinterpret_cast<std::uintptr_t>(rows.data()), count, feature_count());
  const char* config =
      R"({"type": 1, "training": false, "iteration_begin": 0, "iteration_end": 0, "strict_shape": false, )"
      R"("missing": NaN, "cache_id": 0})";
  std::array<std::vector<double>, 3> margin;
  {
    const std::lock_guard<std::mutex> lock(boosters_->calls);
    silence();
    const std::array<const Booster*, 3> boosters{&boosters_->never, &boosters_->planning, &boosters_->execution};
    for (std::size_t b = 0; b < boosters.size(); ++b) {
      const bst_ulong* shape = nullptr;
      bst_ulong dimensions = 0;
      const float* values = nullptr;
      const int status =
          XGBoosterPredictFromDense(boosters[b]->get(), array.c_str(), config, nullptr, &shape, &dimensions, &values);
      margin[b] = margins(status, shape, dimensions, values, count);
    }
  }
  const Law law = law_of(parameters_.settings.aft_distribution);
  std::vector<PredictedTimes> out;
  out.reserve(count);
  for (std::size_t r = 0; r < count; ++r) {
    out.push_back(
        {Distribution::from_pmf(planning_pmf(parameters_, law, horizon(), margin[0][r], margin[1][r])),
         Distribution::from_pmf(execution_pmf(parameters_.execution_sigma, horizon(), step_seconds(), margin[2][r]))});
  }
  return out;
}

std::string BoostedTimeModel::parameters_json() const {
  const BoostedParameters& p = parameters_;
  const std::lock_guard<std::mutex> lock(boosters_->calls);
  silence();
  const detail::ModelJson json = {{"trees", p.settings.trees},
                                  {"depth", p.settings.depth},
                                  {"learning_rate", p.settings.learning_rate},
                                  {"min_child_weight", p.settings.min_child_weight},
                                  {"aft_distribution", p.settings.aft_distribution},
                                  {"aft_scale", p.settings.aft_scale},
                                  {"planning_unit", p.planning_unit},
                                  {"execution_sigma", p.execution_sigma},
                                  {"log_likelihood", p.log_likelihood},
                                  {"never_booster", model_text(boosters_->never)},
                                  {"planning_booster", model_text(boosters_->planning)},
                                  {"execution_booster", model_text(boosters_->execution)}};
  return json.dump();
}

namespace detail {

std::unique_ptr<ConditionalTimeModel> read_boosted_model(const ParameterReader& reader, ModelHeader header) {
  BoostedParameters p;
  const auto whole = [&](const std::string& key) {
    const double value = reader.real(key);
    if (!(value >= std::numeric_limits<int>::min() && value <= std::numeric_limits<int>::max() &&
          value == std::floor(value))) {
      reader.fail(key, "must be a whole number");
    }
    return static_cast<int>(value);
  };
  p.settings.trees = whole("trees");
  p.settings.depth = whole("depth");
  p.settings.learning_rate = reader.real("learning_rate");
  p.settings.min_child_weight = reader.real("min_child_weight");
  p.settings.aft_distribution = reader.text("aft_distribution");
  p.settings.aft_scale = reader.real("aft_scale");
  if (const auto error = settings_error(p.settings)) reader.fail(error->first, error->second);
  p.planning_unit = whole("planning_unit");
  if (p.planning_unit < 1 || p.planning_unit > header.horizon) {
    reader.fail("planning_unit", "must be a whole number of steps from 1 to the horizon");
  }
  p.execution_sigma = reader.real("execution_sigma");
  if (!(p.execution_sigma > 0)) reader.fail("execution_sigma", "must be positive");
  p.log_likelihood = reader.real("log_likelihood");
  const std::size_t F = header.feature_names.size();
  const auto booster = [&](const std::string& key, const std::string& objective, const BoostedSettings* aft) {
    const std::string text = reader.text(key);
    // Checked whole before XGBoost, which trusts what it reads (learn/booster_check.hpp).
    if (const auto fault = booster_fault(text, F)) {
      reader.fail(key, "not a booster OnTime reads: at " + fault->place + ": " + fault->rule);
    }
    try {
      return loaded_booster(text, objective, F, aft);
    } catch (const XGBoostFailure& failure) {
      reader.fail(key, std::string("is not a booster this model reads (") + failure.what() + ")");
    }
  };
  auto boosters = std::make_unique<BoostedTimeModel::Boosters>();
  boosters->never = booster("never_booster", kNeverObjective, nullptr);
  boosters->planning = booster("planning_booster", kPlanningObjective, &p.settings);
  boosters->execution = booster("execution_booster", kExecutionObjective, nullptr);
  return std::make_unique<BoostedTimeModel>(std::move(header.feature_names), header.step_seconds, header.horizon,
                                            header.rows, header.worlds, std::move(p), std::move(boosters));
}

}  // namespace detail
}  // namespace ontime
