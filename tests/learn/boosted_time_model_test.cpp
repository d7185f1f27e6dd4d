#include "ontime/learn/boosted_time_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <thread>

#include "ontime/learn/conditional_model.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {
namespace {

// The law the rows are drawn from: feature x picks a group; an attempt of group x is never found
// with probability never[x], else found at step t with the geometric law of hazard hazard[x]
// (P(T = t) = h (1 - h)^(t - 1)); cut off after cutoff[i % cutoff.size()] steps. Execution
// seconds are log-normal, log-mean 1 + 0.5 x, sd 0.3.
struct GroupTruth {
  std::vector<double> never, hazard;
  std::vector<Steps> cutoff;

  // P(T = t | x) and P(not found within `horizon` | x).
  double pmf(std::size_t x, Steps t) const {
    return (1 - never[x]) * hazard[x] * std::pow(1 - hazard[x], static_cast<double>(t - 1));
  }
  double never_within(std::size_t x, Steps horizon) const {
    return never[x] + (1 - never[x]) * std::pow(1 - hazard[x], static_cast<double>(horizon));
  }
  // E[T | found within the horizon, x].
  double found_mean(std::size_t x, Steps horizon) const {
    double mass = 0, sum = 0;
    for (Steps t = 1; t <= horizon; ++t) {
      mass += pmf(x, t);
      sum += static_cast<double>(t) * pmf(x, t);
    }
    return sum / mass;
  }
};

ConditionalData sample_groups(const GroupTruth& truth, std::size_t per_group, std::uint64_t seed) {
  SplitMix64 random(seed);
  std::vector<RefinementAttempt> rows;
  for (std::size_t i = 0; i < per_group; ++i) {
    for (std::size_t x = 0; x < truth.never.size(); ++x) {
      const Steps cutoff = truth.cutoff[i % truth.cutoff.size()];
      const bool never = uniform01(random) < truth.never[x];
      Steps found_at = 0;
      for (Steps t = 1; t <= cutoff && !never; ++t) {
        if (uniform01(random) < truth.hazard[x]) {
          found_at = t;
          break;
        }
      }
      const double u1 = 1 - uniform01(random), u2 = uniform01(random);
      const double normal = std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
      RefinementAttempt a;
      a.action = "act";
      a.world = "w";
      a.features = {static_cast<double>(x), 7.0};
      a.found = found_at > 0;
      // A planning time inside its step (t - 0.5 s), a cut-off at the end of the last step.
      a.planning_seconds = a.found ? static_cast<double>(found_at) - 0.5 : static_cast<double>(cutoff);
      a.execution_seconds = a.found ? std::exp(1 + 0.5 * static_cast<double>(x) + 0.3 * normal) : 0.0;
      rows.push_back(std::move(a));
    }
  }
  return conditional_data(rows, 1.0, "log");
}

ConditionalFitOptions boosted(std::string law = "normal", int trees = 100) {
  ConditionalFitOptions options;
  options.kind = "boosted";
  options.aft_distribution = std::move(law);
  options.trees = trees;
  return options;
}

double found_mean(const Distribution& planning, Steps horizon) {
  double mass = 0, sum = 0;
  for (Steps t = 1; t <= horizon; ++t) {
    mass += planning.pmf(t);
    sum += static_cast<double>(t) * planning.pmf(t);
  }
  return sum / mass;
}

// Two groups far apart: found at once half the time, or a twentieth, with 10% and 30% never; cut
// off after 30 steps. With the extreme law at scale 1 the found time is exponential and its whole
// steps geometric, so the truth is a model of the kind and the error is sampling error alone.
// Bounds: 5,000 rows a group; a share p estimated from them has a standard error
// sqrt(p (1 - p) / 5000) <= 0.0071, a mean of the found steps sd / sqrt(found rows) (sd 1.4 and
// 8.2, about 4,500 and 2,750 found: 0.021 and 0.16); each bound is four of them.
TEST(BoostedTimeModel, PredictsEachGroupsLawWithinSamplingError) {
  const GroupTruth truth{{0.1, 0.3}, {0.5, 0.05}, {30}};
  const ConditionalData data = sample_groups(truth, 5000, 1);
  const auto model = fit_conditional_model(data, boosted("extreme"));
  ASSERT_EQ(model->horizon(), 30);
  const double mean_bound[] = {4 * 0.021, 4 * 0.16};
  std::vector<PredictedTimes> predicted;
  for (std::size_t x = 0; x < 2; ++x) {
    predicted.push_back(model->predict(std::vector<double>{static_cast<double>(x), 7.0}));
    const Distribution& planning = predicted.back().planning;
    const double never = truth.never_within(x, 30);
    EXPECT_NEAR(planning.never(), never, 4 * std::sqrt(never * (1 - never) / 5000)) << "x " << x;
    for (Steps t = 1; t <= 30; ++t) {
      const double p = truth.pmf(x, t);
      EXPECT_NEAR(planning.pmf(t), p, 4 * std::sqrt(p * (1 - p) / 5000)) << "x " << x << ", step " << t;
    }
    EXPECT_NEAR(found_mean(planning, 30), truth.found_mean(x, 30), mean_bound[x]) << "x " << x;
    // Execution: log-normal of log-mean 1 + 0.5 x and sd 0.3, in steps of 1 s; the fitted
    // log-mean's standard error is 0.3 / sqrt(found rows) < 0.006, a cell's below 0.0075.
    for (Steps k = 1; k <= 8; ++k) {
      const auto cdf = [&](double seconds) {
        return 0.5 * std::erfc(-(std::log(seconds) - 1 - 0.5 * static_cast<double>(x)) / (0.3 * std::numbers::sqrt2));
      };
      const double expected = cdf(static_cast<double>(k)) - (k == 1 ? 0.0 : cdf(static_cast<double>(k - 1)));
      EXPECT_NEAR(predicted.back().execution.pmf(k), expected, 0.03) << "x " << x << ", step " << k;
    }
  }
  // The execution sd, out of fold: about 7,250 found rows, a standard error of 0.3 / sqrt(2 x 7250)
  // = 0.0025.
  EXPECT_NEAR(dynamic_cast<const BoostedTimeModel&>(*model).parameters().execution_sigma, 0.3, 4 * 0.0025);
  // The fast group finds sooner and is less often never.
  EXPECT_GT(predicted[0].planning.cdf(3), predicted[1].planning.cdf(3) + 0.5);
  EXPECT_LT(predicted[0].planning.never(), predicted[1].planning.never() - 0.2);
}

// With every cut-off at the horizon the censored likelihood fits the share found within it in each
// group whatever the law of the found time: the default normal law, not the truth's, predicts
// the "never" mass within sampling error too (bounds as above).
TEST(BoostedTimeModel, TheNeverMassNeedsNoRightLaw) {
  const GroupTruth truth{{0.1, 0.3}, {0.5, 0.05}, {30}};
  const auto model = fit_conditional_model(sample_groups(truth, 5000, 2), boosted("normal"));
  for (std::size_t x = 0; x < 2; ++x) {
    const double never = truth.never_within(x, 30);
    EXPECT_NEAR(model->predict(std::vector<double>{static_cast<double>(x), 7.0}).planning.never(), never,
                4 * std::sqrt(never * (1 - never) / 5000))
        << "x " << x;
  }
}

// Half the attempts cut off after 4 steps, half after 20: the found rows are mostly early finds,
// and their mean step is far below the truth's. The censored fit is not misled. Bounds: the
// share found within 20 steps rests on the 4,000 attempts cut off at 20 (standard error
// sqrt(0.3 x 0.7 / 4000) = 0.0072); the mean found step (sd 5.2) on about 2,800 of them (0.1);
// four of each.
TEST(BoostedTimeModel, CensoringDoesNotBiasTheFoundTimeDown) {
  const GroupTruth truth{{0.2}, {0.1}, {4, 20}};
  const ConditionalData data = sample_groups(truth, 8000, 3);
  const auto model = fit_conditional_model(data, boosted("extreme"));
  ASSERT_EQ(model->horizon(), 20);
  const Distribution planning = model->predict(std::vector<double>{0.0, 7.0}).planning;
  const double never = truth.never_within(0, 20);
  EXPECT_NEAR(planning.never(), never, 4 * 0.0072);
  EXPECT_NEAR(found_mean(planning, 20), truth.found_mean(0, 20), 4 * 0.1);
  for (Steps t = 1; t <= 20; ++t) {
    EXPECT_NEAR(planning.pmf(t), truth.pmf(0, t), 4 * std::sqrt(truth.pmf(0, t) / 4000)) << "step " << t;
  }
  // What a fit of the found rows alone would see: a mean found step below the truth by more than
  // three times the bound.
  double found = 0, steps = 0;
  for (std::size_t i = 0; i < data.rows(); ++i) {
    if (data.found[i] == 0) continue;
    found += 1;
    steps += static_cast<double>(data.planning[i]);
  }
  EXPECT_LT(steps / found, truth.found_mean(0, 20) - 3 * 4 * 0.1);
}

// The model file: the same bytes from two fits, the same bytes back from the file, the same
// predictions bit for bit (at the training rows' features and between them), by one row or many.
TEST(BoostedTimeModel, TheModelFileReadsBackToTheSameBytesAndPredictions) {
  const GroupTruth truth{{0.1, 0.4}, {0.4, 0.1}, {12}};
  const ConditionalData data = sample_groups(truth, 400, 4);
  ConditionalFitOptions options = boosted("logistic", 40);
  options.depth = 2;
  options.learning_rate = 0.3;
  options.aft_scale = 0.7;
  options.min_child_weight = 0.5;
  const auto model = fit_conditional_model(data, options);
  const std::string text = model->to_json();
  EXPECT_EQ(fit_conditional_model(data, options)->to_json(), text);
  const auto back = parse_conditional_model(text, "model.json");
  EXPECT_EQ(back->kind(), "boosted");
  EXPECT_EQ(back->to_json(), text);
  const auto& parameters = dynamic_cast<const BoostedTimeModel&>(*back).parameters();
  EXPECT_EQ(parameters.settings.trees, 40);
  EXPECT_EQ(parameters.settings.aft_distribution, "logistic");
  EXPECT_EQ(parameters.settings.aft_scale, 0.7);
  std::vector<double> rows;
  for (const double x : {0.0, 0.25, 1.0, -3.0}) {
    const PredictedTimes a = model->predict(std::vector<double>{x, 7.0});
    const PredictedTimes b = back->predict(std::vector<double>{x, 7.0});
    EXPECT_EQ(a.planning, b.planning);
    EXPECT_EQ(a.execution, b.execution);
    rows.insert(rows.end(), {x, 7.0});
  }
  const std::vector<PredictedTimes> many = back->predict_rows(rows, 4);
  ASSERT_EQ(many.size(), 4u);
  EXPECT_EQ(many[2].planning, model->predict(std::vector<double>{1.0, 7.0}).planning);
  EXPECT_EQ(many[3].execution, model->predict(std::vector<double>{-3.0, 7.0}).execution);
  EXPECT_THROW(back->predict_rows(rows, 3), UsageError);
}

// Fits side by side in threads give the file of a fit alone (XGBoost runs one thread a booster).
TEST(BoostedTimeModel, FitsInThreadsGiveTheSameFile) {
  const GroupTruth truth{{0.1, 0.4}, {0.4, 0.1}, {12}};
  const ConditionalData data = sample_groups(truth, 300, 5);
  const std::string alone = fit_conditional_model(data, boosted("normal", 30))->to_json();
  std::vector<std::string> texts(2);
  std::vector<std::thread> threads;
  for (std::string& text : texts) {
    threads.emplace_back([&] { text = fit_conditional_model(data, boosted("normal", 30))->to_json(); });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(texts[0], alone);
  EXPECT_EQ(texts[1], alone);
}

TEST(BoostedTimeModel, RefusesBadSettingsAndBadFiles) {
  const GroupTruth truth{{0.1, 0.4}, {0.4, 0.1}, {6}};
  const ConditionalData data = sample_groups(truth, 100, 6);
  const auto refused_fit = [&](auto change) {
    ConditionalFitOptions options = boosted("normal", 5);
    change(options);
    EXPECT_THROW(fit_conditional_model(data, options), UsageError);
  };
  refused_fit([](ConditionalFitOptions& o) { o.trees = 0; });
  refused_fit([](ConditionalFitOptions& o) { o.depth = 17; });
  refused_fit([](ConditionalFitOptions& o) { o.learning_rate = 0; });
  refused_fit([](ConditionalFitOptions& o) { o.min_child_weight = -1; });
  refused_fit([](ConditionalFitOptions& o) { o.aft_distribution = "weibull"; });
  refused_fit([](ConditionalFitOptions& o) { o.aft_scale = 0; });
  ConditionalData featureless = data;
  featureless.feature_count = 0;
  featureless.features.clear();
  EXPECT_THROW(fit_conditional_model(featureless, boosted()), UsageError);

  const std::string text = fit_conditional_model(data, boosted("normal", 5))->to_json();
  const auto refused = [](const std::string& bad, const std::string& place, const std::string& rule) {
    try {
      parse_conditional_model(bad, "m.json");
      ADD_FAILURE() << "accepted: " << place;
    } catch (const InputError& error) {
      EXPECT_EQ(error.place(), place) << error.what();
      EXPECT_NE(error.rule().find(rule), std::string::npos) << error.what();
    }
  };
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string copy = text;
    copy.replace(copy.find(from), from.size(), to);
    return copy;
  };
  // A booster's text cut short, another JSON, one that is not XGBoost's, swapped with another
  // booster, or left out.
  const auto with = [&](const std::string& key, const nlohmann::ordered_json& value) {
    nlohmann::ordered_json json = nlohmann::ordered_json::parse(text);
    if (value.is_null()) {
      json["parameters"].erase(key);
    } else {
      json["parameters"][key] = value;
    }
    return json.dump(2);
  };
  const auto booster = [&](const std::string& key) {
    return nlohmann::ordered_json::parse(text)["parameters"][key].get<std::string>();
  };
  refused(with("never_booster", booster("never_booster").substr(0, 300)), "parameters.never_booster",
          "not a booster OnTime reads: at line 1, column 301: invalid JSON");
  refused(with("never_booster", "{}"), "parameters.never_booster", "not a booster OnTime reads: at version: missing");
  // XGBoost reads a buffer that does not begin with '{' as its binary format, trusting its lengths.
  refused(with("never_booster", " " + booster("never_booster")), "parameters.never_booster",
          "not a booster OnTime reads: at booster: must begin with '{'");
  refused(with("planning_booster", "{\"version\": [1, 7, 4], \"learner\": 3}"), "parameters.planning_booster",
          "at learner: must be an object");
  refused(with("planning_booster", 3), "parameters.planning_booster", "must be a string");
  refused(with("execution_booster", booster("never_booster")), "parameters.execution_booster",
          "objective binary:logistic, not reg:squarederror");
  refused(with("planning_booster", nullptr), "parameters.planning_booster", "missing");
  // Settings out of range, or not those the planning booster was fitted with.
  refused(replaced("\"aft_distribution\": \"normal\"", "\"aft_distribution\": \"weibull\""),
          "parameters.aft_distribution", "normal, logistic or extreme");
  refused(replaced("\"aft_distribution\": \"normal\"", "\"aft_distribution\": \"logistic\""),
          "parameters.planning_booster", "not the model's aft_distribution");
  refused(replaced("\"trees\": 5", "\"trees\": 2.5"), "parameters.trees", "whole number");
  refused(replaced("\"planning_unit\": ", "\"planning_unit\": 99"), "parameters.planning_unit",
          "from 1 to the horizon");
  // The features of another model.
  refused(replaced("\"f2\"", "\"f2\", \"f3\""), "parameters.never_booster",
          "at learner.learner_model_param.num_feature: must be 3 (the model's feature count; got 2)");
}

// Boosters crafted to break XGBoost's reader (out-of-range and negative children, a cycle, split
// indices beyond the features, counts that disagree, nesting without end): each is refused at
// its member with the place inside the booster, before XGBoost reads it.
TEST(BoostedTimeModel, ABoosterBreakingARuleIsRefusedBeforeXGBoostReadsIt) {
  const GroupTruth truth{{0.1, 0.4}, {0.4, 0.1}, {6}};
  const std::string text = fit_conditional_model(sample_groups(truth, 100, 6), boosted("normal", 3))->to_json();
  using Json = nlohmann::ordered_json;
  const Json file = Json::parse(text);
  const Json planning = Json::parse(file["parameters"]["planning_booster"].get<std::string>());
  const std::string trees = "learner.gradient_booster.model.trees";
  ASSERT_EQ(planning["learner"]["gradient_booster"]["model"]["trees"].size(), 3u);
  const Json& tree = planning["learner"]["gradient_booster"]["model"]["trees"][1];
  const auto nodes = tree["left_children"].size();
  ASSERT_GE(nodes, 3u);  // a split and its two leaves at least
  ASSERT_EQ(tree["left_children"][0], 1);
  const auto refused = [&](const std::function<void(Json&)>& change, const std::string& place,
                           const std::string& rule) {
    Json booster = planning;
    change(booster);
    Json bad = file;
    bad["parameters"]["planning_booster"] = booster.dump();
    try {
      parse_conditional_model(bad.dump(2), "m.json");
      ADD_FAILURE() << "accepted: " << place;
    } catch (const InputError& error) {
      EXPECT_EQ(error.place(), "parameters.planning_booster") << error.what();
      EXPECT_EQ(error.rule(), "not a booster OnTime reads: at " + place + ": " + rule) << error.what();
    }
  };
  const auto in_tree = [](Json& booster) -> Json& {
    return booster["learner"]["gradient_booster"]["model"]["trees"][1];
  };
  const std::string n = std::to_string(nodes);
  refused([&](Json& b) { in_tree(b)["left_children"][0] = nodes; }, trees + "[1].left_children[0]",
          "a child must be a node from 1 to " + std::to_string(nodes - 1) +
              ", or -1 for both children of a leaf (got " + n + ")");
  refused(
      [&](Json& b) { in_tree(b)["right_children"][0] = -7; }, trees + "[1].right_children[0]",
      "a child must be a node from 1 to " + std::to_string(nodes - 1) + ", or -1 for both children of a leaf (got -7)");
  refused(
      [&](Json& b) { in_tree(b)["left_children"][0] = 0; }, trees + "[1].left_children[0]",
      "a child must be a node from 1 to " + std::to_string(nodes - 1) + ", or -1 for both children of a leaf (got 0)");
  // Node 1 made a child of itself (a cycle), or of the root twice.
  refused(
      [&](Json& b) {
        in_tree(b)["left_children"][1] = 1;
        in_tree(b)["right_children"][1] = in_tree(b)["right_children"][0];
      },
      trees + "[1].left_children[1]", "node 1 is reached twice from the root (the children must form a tree)");
  refused([&](Json& b) { in_tree(b)["right_children"][0] = 1; }, trees + "[1].right_children[0]",
          "the two children of a node must differ");
  refused([&](Json& b) { in_tree(b)["parents"][1] = 2; }, trees + "[1].parents[1]",
          "must be 0, the node whose child it is (got 2)");
  refused([&](Json& b) { in_tree(b)["split_indices"][0] = 2; }, trees + "[1].split_indices[0]",
          "must be a feature index below 2 (got 2)");
  refused([&](Json& b) { in_tree(b)["split_indices"][0] = 4294967296LL; }, trees + "[1].split_indices[0]",
          "must be a whole number within 32 bits (got 4294967296)");
  refused([&](Json& b) { in_tree(b)["split_conditions"][2] = "nan"; }, trees + "[1].split_conditions[2]",
          "must be a finite number (got \"nan\")");
  refused([&](Json& b) { in_tree(b)["left_children"].erase(in_tree(b)["left_children"].size() - 1); },
          trees + "[1].left_children",
          "must hold one entry per node: " + n + " (tree_param.num_nodes), not " + std::to_string(nodes - 1));
  refused([&](Json& b) { in_tree(b)["tree_param"]["num_nodes"] = "999999999"; }, trees + "[1].loss_changes",
          "must hold one entry per node: 999999999 (tree_param.num_nodes), not " + n);
  refused([&](Json& b) { in_tree(b)["tree_param"]["num_nodes"] = 3; }, trees + "[1].tree_param.num_nodes",
          "must be a whole number written as text (got 3)");
  refused([&](Json& b) { in_tree(b)["id"] = 0; }, trees + "[1].id", "must be the tree's position in trees, 1 (got 0)");
  refused([&](Json& b) { b["learner"]["gradient_booster"]["model"]["tree_info"].erase(2); },
          "learner.gradient_booster.model.tree_info", "must hold one entry per tree: 3, not 2");
  refused([&](Json& b) { b["learner"]["gradient_booster"]["model"]["gbtree_model_param"]["num_trees"] = "4"; },
          "learner.gradient_booster.model.gbtree_model_param.num_trees", "must be 3 (the trees given; got 4)");
  refused([&](Json& b) { b["learner"]["gradient_booster"]["model"]["trees"].erase(2); },
          "learner.gradient_booster.model.gbtree_model_param.num_trees", "must be 2 (the trees given; got 3)");
  refused([&](Json& b) { b["learner"]["gradient_booster"]["name"] = "dart"; }, "learner.gradient_booster.name",
          "must be \"gbtree\" (got \"dart\")");
  refused([&](Json& b) { b["learner"]["learner_model_param"]["base_score"] = "inf"; },
          "learner.learner_model_param.base_score", "must be a finite number written as text (got \"inf\")");
  // Nesting without end inside the booster's text: refused by the parser, which does not recurse.
  Json deep = file;
  deep["parameters"]["planning_booster"] = "{\"version\": " + std::string(300'000, '[');
  try {
    parse_conditional_model(deep.dump(2), "m.json");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "parameters.planning_booster");
    EXPECT_EQ(error.rule(),
              "not a booster OnTime reads: at line 1, column 268: invalid JSON: arrays and objects nested more than "
              "256 levels deep (the limit of OnTime's files)");
  }
  // The booster as fitted reads back.
  EXPECT_NO_THROW(parse_conditional_model(file.dump(2), "m.json"));
}

TEST(BoostedTimeModel, PredictsALibraryInOneCall) {
  const GroupTruth truth{{0.1, 0.4}, {0.4, 0.1}, {8}};
  const auto model = fit_conditional_model(sample_groups(truth, 200, 7), boosted("normal", 20));
  const std::vector<ActionFeatures> actions{
      {"move(A,B)", {0.0, 7.0}}, {"move(B,C)", {1.0, 7.0}}, {"move(A,B)", {5.0, 7.0}}};
  const Problem library = predict_problem(*model, actions, {}, 6, "predicted");
  ASSERT_EQ(library.skeleton_count(), 2);
  const PredictedTimes full = model->predict(actions[1].features);
  for (Steps t = 1; t <= 6; ++t) EXPECT_EQ(library.action(1).planning.pmf(t), full.planning.pmf(t));
  EXPECT_NEAR(library.action(1).planning.never(), full.planning.survival(6), 1e-15);
  const std::vector<ActionFeatures> bad{{"move(A,B)", {0.0, std::nan("")}}};
  try {
    predict_problem(*model, bad, {}, 6, "x");
    FAIL() << "accepted";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("move(A,B): feature 2 (f2) is not a finite number"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace ontime
