#include "ontime/learn/conditional_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>

#include "ontime/learn/fitting.hpp"
#include "ontime/learn/hazard_time_model.hpp"
#include "ontime/learn/pooled_time_model.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {
namespace {

RefinementAttempt featured_attempt(std::string action, double planning, bool found, double execution,
                                   std::vector<double> features, std::string world = "w") {
  RefinementAttempt a;
  a.action = std::move(action);
  a.planning_seconds = planning;
  a.found = found;
  a.execution_seconds = found ? execution : 0.0;
  a.world = std::move(world);
  a.features = std::move(features);
  return a;
}

double logistic(double x) { return 1 / (1 + std::exp(-x)); }

FitOptions fit_options() {
  FitOptions result;
  result.step_seconds = 1.0;
  result.deadline = 5;
  return result;
}

ConditionalFitOptions options(std::string kind = "hazard", Steps horizon = 0, int bins = 0, double ridge = 1e-3) {
  ConditionalFitOptions result;
  result.kind = std::move(kind);
  result.horizon = horizon;
  result.bins = bins;
  result.ridge = ridge;
  return result;
}

// Rows drawn from the hazard model itself: feature x in {0, 1}; cure logit g0 + g x; hazard
// logit a(t) + b x; execution log-normal with mean m0 + m x and sd s; cut off after `cutoff`
// steps; step of 1 s.
struct HazardTruth {
  std::vector<double> a;  // per step 1..cutoff
  double b, g0, g, m0, m, s;
  Steps cutoff;

  double hazard(Steps t, double x) const { return logistic(a[static_cast<std::size_t>(t - 1)] + b * x); }
  double cure(double x) const { return logistic(g0 + g * x); }
  double pmf(Steps t, double x) const {
    double alive = 1 - cure(x);
    for (Steps u = 1; u < t; ++u) alive *= 1 - hazard(u, x);
    return alive * hazard(t, x);
  }
};

std::vector<RefinementAttempt> sample_hazard(const HazardTruth& truth, std::size_t per_group, std::uint64_t seed) {
  SplitMix64 random(seed);
  std::vector<RefinementAttempt> rows;
  for (const double x : {0.0, 1.0}) {
    for (std::size_t i = 0; i < per_group; ++i) {
      const bool cured = uniform01(random) < truth.cure(x);
      Steps found_at = 0;
      for (Steps t = 1; t <= truth.cutoff && !cured; ++t) {
        if (uniform01(random) < truth.hazard(t, x)) {
          found_at = t;
          break;
        }
      }
      // Box-Muller for the execution time.
      const double u1 = 1 - uniform01(random), u2 = uniform01(random);
      const double normal = std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
      const double execution = std::exp(truth.m0 + truth.m * x + truth.s * normal);
      // A planning time inside its step (t - 0.5 s), a cut-off at the end of the last step.
      rows.push_back(found_at > 0
                         ? featured_attempt("act", static_cast<double>(found_at) - 0.5, true, execution, {x, 7.0})
                         : featured_attempt("act", static_cast<double>(truth.cutoff), false, 0, {x, 7.0}));
    }
  }
  return rows;
}

TEST(ConditionalData, StepsAsFittingCountsThemAndEveryRecordNeedsFeatures) {
  const std::vector<RefinementAttempt> log{featured_attempt("a", 2.5, true, 4.0, {1, 2}),
                                           featured_attempt("a", 6.0, false, 0, {1, 2})};
  const ConditionalData data = conditional_data(log, 2.0, "log");
  ASSERT_EQ(data.rows(), 2u);
  EXPECT_EQ(data.feature_count, 2u);
  EXPECT_EQ(data.planning[0], 2);  // ceil(2.5 / 2)
  EXPECT_EQ(data.planning[1], 3);  // floor(6 / 2) steps survived
  EXPECT_EQ(data.found[1], 0);
  EXPECT_EQ(data.row(1)[1], 2.0);
  std::vector<RefinementAttempt> bare = log;
  bare[1].features.clear();
  try {
    conditional_data(bare, 2.0, "log.jsonl");
    FAIL() << "accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "log.jsonl");
    EXPECT_EQ(error.place(), "record 2");
  }
}

// A motion found in no time took its first step, as `fit` counts it; features beyond 1e15 in
// magnitude are refused naming the record and the feature; features at the bound fit every kind,
// and each model written reads back.
TEST(ConditionalData, ZeroPlanningTimesAreOneStepAndHugeFeaturesAreRefused) {
  const std::vector<RefinementAttempt> log{featured_attempt("a", 0.0, true, 1.0, {1e15}),
                                           featured_attempt("a", 2.0, true, 1.0, {-1e15}),
                                           featured_attempt("a", 3.0, false, 0, {0.0})};
  const ConditionalData data = conditional_data(log, 1.0, "log");
  EXPECT_EQ(data.planning[0], 1);
  ConditionalData three = data;
  for (int copy = 0; copy < 2; ++copy) {
    const ConditionalData more = conditional_data(log, 1.0, "log");
    three.features.insert(three.features.end(), more.features.begin(), more.features.end());
    three.planning.insert(three.planning.end(), more.planning.begin(), more.planning.end());
    three.found.insert(three.found.end(), more.found.begin(), more.found.end());
    three.execution_seconds.insert(three.execution_seconds.end(), more.execution_seconds.begin(),
                                   more.execution_seconds.end());
    three.worlds.insert(three.worlds.end(), more.worlds.begin(), more.worlds.end());
    three.actions.insert(three.actions.end(), more.actions.begin(), more.actions.end());
  }
  for (const std::string kind : {"pooled", "hazard", "boosted"}) {
    ConditionalFitOptions fit = options(kind);
    fit.trees = 2;
    const auto model = fit_conditional_model(three, fit);
    EXPECT_EQ(model->predict(std::vector<double>{1e15}).planning.pmf(0), 0.0) << kind;
    EXPECT_EQ(parse_conditional_model(model->to_json(), "m.json")->to_json(), model->to_json()) << kind;
  }
  for (const double huge : {1e16, -1e308, std::numeric_limits<double>::max()}) {
    std::vector<RefinementAttempt> bad = log;
    bad[1].features = {huge};
    try {
      conditional_data(bad, 1.0, "log.jsonl");
      ADD_FAILURE() << huge;
    } catch (const InputError& error) {
      EXPECT_EQ(error.place(), "record 2: features[0]");
      EXPECT_NE(error.rule().find("within [-1e15, 1e15]"), std::string::npos);
    }
  }
}

// Features ignored: exactly the one-action fit of fitting.hpp.
TEST(PooledTimeModel, IsTheKaplanMeierFitOfThePooledLog) {
  const std::vector<RefinementAttempt> log{
      featured_attempt("a", 0.5, true, 2.5, {1}), featured_attempt("b", 3.0, false, 0, {2}),
      featured_attempt("a", 2.2, true, 0.7, {3}), featured_attempt("b", 1.0, false, 0, {4}),
      featured_attempt("a", 3.9, true, 4.0, {5})};
  const ConditionalData data = conditional_data(log, 1.0, "log");
  const auto model = fit_conditional_model(data, options("pooled", 5));
  std::vector<RefinementAttempt> one_action = log;
  for (RefinementAttempt& a : one_action)
    a.action = std::string("x");  // (not = "x": GCC 12 warns falsely of overlapping copies, -Wrestrict)
  const FitResult fit = fit_problem(one_action, "log", {"skeletons", {{"x"}}}, fit_options());
  const PredictedTimes predicted = model->predict(std::vector<double>{42.0});
  EXPECT_EQ(predicted.planning, fit.problem.action(0).planning);
  EXPECT_EQ(predicted.execution, fit.problem.action(0).execution);
  EXPECT_EQ(model->training_rows(), 5u);
}

// No feature carries information and the baseline has one level per step: the maximum of the
// censored likelihood is the Kaplan-Meier estimate, found to the optimiser's tolerance.
TEST(HazardTimeModel, WithoutInformativeFeaturesIsKaplanMeier) {
  std::vector<RefinementAttempt> log;
  SplitMix64 random(5);
  for (int i = 0; i < 400; ++i) {
    const Steps found_at = 1 + static_cast<Steps>(uniform01(random) * 9);
    const Steps cut = static_cast<Steps>(uniform01(random) * 10);  // cut off after 0..9 steps
    log.push_back(found_at <= cut ? featured_attempt("a", static_cast<double>(found_at) - 0.5, true, 1.0, {3.0})
                                  : featured_attempt("a", static_cast<double>(cut), false, 0, {3.0}));
  }
  const ConditionalData data = conditional_data(log, 1.0, "log");
  const auto model = fit_conditional_model(data, options("hazard", 9));
  PlanningSample pooled;
  for (std::size_t i = 0; i < data.rows(); ++i) {
    (data.found[i] != 0 ? pooled.found : pooled.censored).push_back(data.planning[i]);
  }
  const Distribution km = estimate_planning(pooled, 9);
  const Distribution predicted = model->predict(std::vector<double>{3.0}).planning;
  for (Steps t = 1; t <= 9; ++t) EXPECT_NEAR(predicted.pmf(t), km.pmf(t), 1e-5) << "step " << t;
  EXPECT_NEAR(predicted.never(), km.never(), 1e-5);
}

// Rows drawn from the model: the fit recovers the law of each group. With 20,000 rows per group
// a PMF cell's standard error is below 0.0035; the bound is about three of them.
TEST(HazardTimeModel, RecoversTheLawItWasDrawnFrom) {
  HazardTruth truth{{-1.0, -0.8, -0.9, -1.2, -1.5, -1.5, -1.8, -2.0}, -1.2, -2.0, 1.5, 1.0, 0.5, 0.3, 8};
  const ConditionalData data = conditional_data(sample_hazard(truth, 20000, 11), 1.0, "log");
  ConditionalFitOptions named = options("hazard", 0, 0, 0.0);
  named.feature_names = {"x", "constant"};
  const auto model = fit_conditional_model(data, named);
  ASSERT_EQ(model->horizon(), 8);
  for (const double x : {0.0, 1.0}) {
    const PredictedTimes predicted = model->predict(std::vector<double>{x, 7.0});
    for (Steps t = 1; t <= 8; ++t) {
      EXPECT_NEAR(predicted.planning.pmf(t), truth.pmf(t, x), 0.01) << "x " << x << ", step " << t;
    }
    double tail = 1;
    for (Steps t = 1; t <= 8; ++t) tail -= truth.pmf(t, x);
    EXPECT_NEAR(predicted.planning.never(), tail, 0.01) << "x " << x;
    // Execution: log-normal with mean 1 + 0.5 x and sd 0.3, in steps of 1 s.
    for (Steps k = 1; k <= 8; ++k) {
      const auto cdf = [&](double seconds) {
        return 0.5 * std::erfc(-(std::log(seconds) - truth.m0 - truth.m * x) / (truth.s * std::numbers::sqrt2));
      };
      const double expected = cdf(static_cast<double>(k)) - (k == 1 ? 0.0 : cdf(static_cast<double>(k - 1)));
      EXPECT_NEAR(predicted.execution.pmf(k), expected, 0.01) << "x " << x << ", step " << k;
    }
  }
  // The feature that never varies has no weight.
  const auto& hazard = dynamic_cast<const HazardTimeModel&>(*model);
  EXPECT_EQ(hazard.parameters().scale[1], 0.0);
  EXPECT_EQ(hazard.parameters().hazard[1], 0.0);
}

// The same data, the same model file, and back from the file the same predictions bit for bit.
TEST(HazardTimeModel, TheModelFileReadsBackToTheSamePredictions) {
  HazardTruth truth{{-1.0, -1.0, -1.5, -1.5}, 0.7, -1.0, 0.8, 0.5, -0.2, 0.4, 4};
  const ConditionalData data = conditional_data(sample_hazard(truth, 500, 3), 1.0, "log");
  for (const std::string kind : {"hazard", "pooled"}) {
    const auto model = fit_conditional_model(data, options(kind, 0, kind == "hazard" ? 2 : 0));
    const std::string text = model->to_json();
    EXPECT_EQ(fit_conditional_model(data, options(kind, 0, kind == "hazard" ? 2 : 0))->to_json(), text);
    const auto back = parse_conditional_model(text, "model.json");
    EXPECT_EQ(back->kind(), kind);
    EXPECT_EQ(back->to_json(), text);
    for (const double x : {0.0, 0.5, 1.0}) {
      const PredictedTimes a = model->predict(std::vector<double>{x, 7.0});
      const PredictedTimes b = back->predict(std::vector<double>{x, 7.0});
      EXPECT_EQ(a.planning, b.planning);
      EXPECT_EQ(a.execution, b.execution);
    }
  }
}

TEST(ConditionalTimeModel, RefusesBadFeaturesAndBadFiles) {
  HazardTruth truth{{-1.0, -1.0}, 0.7, -1.0, 0.8, 0.5, -0.2, 0.4, 2};
  const ConditionalData data = conditional_data(sample_hazard(truth, 100, 3), 1.0, "log");
  const auto model = fit_conditional_model(data, options());
  EXPECT_THROW(model->predict(std::vector<double>{1.0}), UsageError);
  EXPECT_THROW(model->predict(std::vector<double>{1.0, std::nan("")}), UsageError);
  EXPECT_THROW(fit_conditional_model(data, options("forest")), UsageError);
  ConditionalFitOptions one_name = options();
  one_name.feature_names = {"only one"};
  EXPECT_THROW(fit_conditional_model(data, one_name), UsageError);
  EXPECT_THROW(fit_conditional_model(data, options("hazard", 0, 0, -1)), UsageError);
  // A ridge of 1e10 made NLopt fail (an internal error); above 1e6 it is refused.
  EXPECT_THROW(fit_conditional_model(data, options("hazard", 0, 0, 1e10)), UsageError);
  EXPECT_NO_THROW(fit_conditional_model(data, options("hazard", 0, 0, 1e6)));

  const std::string text = model->to_json();
  const auto refused = [](const std::string& bad, const std::string& place) {
    try {
      parse_conditional_model(bad, "m.json");
      ADD_FAILURE() << "accepted: " << place;
    } catch (const InputError& error) {
      EXPECT_EQ(error.place(), place) << error.what();
    }
  };
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string copy = text;
    copy.replace(copy.find(from), from.size(), to);
    return copy;
  };
  refused(replaced("\"version\": 1", "\"version\": 2"), "version");
  refused(replaced("ontime-conditional-time-model", "ontime-instance"), "format");
  refused(replaced("\"kind\": \"hazard\"", "\"kind\": \"forest\""), "kind");
  refused(replaced("\"execution_sigma\"", "\"sigma\""), "parameters.execution_sigma");
  refused(replaced("\"horizon\": 2", "\"horizon\": 0"), "horizon");
  // Whole numbers follow the instance reader's rules: 2^32 + 1 is not truncated to the version 1,
  // nor 2^32 + 2 to the horizon 2; `1.0` and `2.0` are whole numbers.
  refused(replaced("\"version\": 1", "\"version\": 4294967297"), "version");
  refused(replaced("\"horizon\": 2", "\"horizon\": 4294967298"), "horizon");
  refused(replaced("\"horizon\": 2", "\"horizon\": 2.5"), "horizon");
  nlohmann::ordered_json wide_bin = nlohmann::ordered_json::parse(text);
  wide_bin["parameters"]["bin_end"][0] = 4294967297LL;  // 1 in 32 bits
  refused(wide_bin.dump(2), "parameters.bin_end");
  nlohmann::ordered_json written_as_floats = nlohmann::ordered_json::parse(text);
  written_as_floats["version"] = 1.0;
  written_as_floats["horizon"] = 2.0;
  const auto whole = parse_conditional_model(written_as_floats.dump(2), "m.json");
  EXPECT_EQ(whole->horizon(), 2);
  EXPECT_EQ(whole->to_json(), text);
}

// A model file's numbers: one that is not a finite number (1e999, NaN, Infinity) is refused where
// the reader meets it; finite numbers that overflow together (a scale of 1e-308 makes a feature's
// standard score infinite, and a coefficient of 0 makes it NaN) are refused when a prediction meets
// them, naming the file and its parameters, not with a table that is not a distribution and no
// file. A fitted model's prediction is as it was.
TEST(ConditionalTimeModel, AFileWhoseNumbersAreNotFiniteOrOverflowIsRefusedNamingTheFile) {
  HazardTruth truth{{-1.0, -1.0}, 0.7, -1.0, 0.8, 0.5, -0.2, 0.4, 2};
  const auto model = fit_conditional_model(conditional_data(sample_hazard(truth, 100, 3), 1.0, "log"), options());
  nlohmann::ordered_json file = nlohmann::ordered_json::parse(model->to_json());
  file["parameters"]["hazard"][0] = 12345.5;
  const std::string marked = file.dump(2);
  for (const std::string number : {"1e999", "-1e999", "NaN", "Infinity"}) {
    std::string bad = marked;
    bad.replace(bad.find("12345.5"), 7, number);
    try {
      parse_conditional_model(bad, "m.json");
      ADD_FAILURE() << number << " accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), "m.json") << number;
      EXPECT_EQ(error.place().rfind("line ", 0), 0U) << number << ": " << error.what();
    }
  }
  file["parameters"]["hazard"] = {0.0, 0.0};
  file["parameters"]["scale"][0] = 1e-308;
  const auto overflowing = parse_conditional_model(file.dump(2), "m.json");
  const std::vector<double> far{1e6, 1e6};
  for (const bool rows : {false, true}) {
    try {
      if (rows) {
        (void)overflowing->predict_rows(far, 1);
      } else {
        (void)overflowing->predict(far);
      }
      ADD_FAILURE() << "a prediction of probabilities that are not numbers";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), "m.json");
      EXPECT_EQ(error.place(), "parameters");
      EXPECT_NE(error.rule().find("the model's numbers overflow for some features"), std::string::npos) << error.what();
    }
  }
  EXPECT_EQ(overflowing->source(), "m.json");
  EXPECT_EQ(model->source(), "");
  EXPECT_NO_THROW((void)model->predict(far));
}

TEST(ConditionalTimeModel, PredictsALibraryCutAtTheDeadline) {
  HazardTruth truth{{-1.0, -1.0, -1.0, -1.0, -1.0, -1.0}, 0.7, -1.0, 0.8, 0.5, -0.2, 0.4, 6};
  const ConditionalData data = conditional_data(sample_hazard(truth, 300, 9), 1.0, "log");
  const auto model = fit_conditional_model(data, options());
  const std::vector<ActionFeatures> actions{{"move(A,B)", {0.0, 7.0}}, {"move(B,C)", {1.0, 7.0}}};
  const Problem library = predict_problem(*model, actions, {}, 4, "predicted");
  ASSERT_EQ(library.skeleton_count(), 2);
  EXPECT_EQ(library.deadline(), 4);
  const PredictedTimes full = model->predict(actions[1].features);
  for (Steps t = 1; t <= 4; ++t) EXPECT_EQ(library.action(1).planning.pmf(t), full.planning.pmf(t));
  EXPECT_EQ(library.action(1).planning.pmf(5), 0.0);
  EXPECT_NEAR(library.action(1).planning.never(), full.planning.survival(4), 1e-15);
  const Problem chained = predict_problem(*model, actions, {{"move(A,B)", "move(B,C)"}}, 6, "chain");
  EXPECT_EQ(chained.skeleton_count(), 1);
  EXPECT_THROW(predict_problem(*model, actions, {{"move(C,D)"}}, 6, "x"), UsageError);
}

}  // namespace
}  // namespace ontime
