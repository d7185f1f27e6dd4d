// CLI tests of conditional time models: worlds of a family collected with --features, a model
// fitted over them with `fit --conditional`, and `predict` writing the instance of a world none
// of them is (the domains build only).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "apps/cli_test_support.hpp"

namespace ontime {
namespace {

using namespace cli_test;

// Three small buildings with many narrow doors, collected with features; seeds 1-3 train, seed 4
// is predicted.
struct Corpus {
  std::filesystem::path dir;
  std::vector<std::string> logs;
  std::string unseen;
};

// Each test makes its own (CTest runs tests as processes side by side).
Corpus corpus(const std::string& folder) {
  Corpus c;
  c.dir = scratch(folder);
  {
    for (const std::string seed : {"1", "2", "3", "4"}) {
      const std::string world = (c.dir / ("w" + seed + ".json")).string();
      EXPECT_EQ(
          ontime({"generate-world", "--rows", "2", "--cols", "3", "--narrow-doors", "0.5", "--seed", seed, "-o", world})
              .exit_code,
          0);
      if (seed == "4") {
        c.unseen = world;
        continue;
      }
      const std::string log = (c.dir / ("w" + seed + ".jsonl")).string();
      const auto collected =
          ontime({"collect", "--domain", "navigation", "--world", world, "--every-action", "--features", "--trials",
                  "6", "--threads", "2", "--log", log, "-o", (c.dir / ("w" + seed + ".instance.json")).string()});
      EXPECT_EQ(collected.exit_code, 0) << collected.err;
      c.logs.push_back(log);
    }
  }
  return c;
}

TEST(Cli, PredictWritesTheInstanceOfAnUnseenWorld) {
  const Corpus c = corpus("predict");
  const json record = json::parse(read_file(c.logs[0]).substr(0, read_file(c.logs[0]).find('\n')));
  EXPECT_EQ(record["world"], "w1");
  EXPECT_EQ(record["features"].size(), 11u);
  const std::string model = (c.dir / "hazard.json").string();
  std::vector<std::string> fit{"fit"};
  fit.insert(fit.end(), c.logs.begin(), c.logs.end());
  for (const std::string arg : {"--conditional", "hazard", "--domain", "navigation", "--step", "3", "-o"}) {
    fit.push_back(arg);
  }
  fit.push_back(model);
  fit.push_back("--json");
  const auto fitted = ontime(fit);
  ASSERT_EQ(fitted.exit_code, 0) << fitted.err;
  const json summary = json::parse(fitted.out);
  EXPECT_EQ(summary["worlds"].get<int>(), 3);
  EXPECT_EQ(summary["feature_names"][0], "door_width");
  EXPECT_EQ(json::parse(read_file(model))["version"].get<int>(), 1);

  const std::string instance = (c.dir / "w4.predicted.json").string();
  const auto predicted =
      ontime({"predict", "--domain", "navigation", "--world", c.unseen, "--model", model, "-o", instance, "--json"});
  ASSERT_EQ(predicted.exit_code, 0) << predicted.err;
  const json out = json::parse(predicted.out);
  const json problem = json::parse(read_file(instance));
  // Every doorway move of the unseen building, both ways, one skeleton each; its deadline.
  const json world = json::parse(read_file(c.unseen));
  EXPECT_EQ(out["actions"].get<std::size_t>(), 2 * world["doors"].size());
  EXPECT_EQ(out["skeletons"], out["actions"]);
  EXPECT_EQ(problem["deadline"], world["collection"]["deadline"]);
  // Features matter: the move through the unseen building's narrowest door is predicted slower to
  // plan than the move through its widest.
  std::string narrow, wide;
  double narrowest = 10, widest = 0;
  for (const json& door : world["doors"]) {
    const std::string move =
        "move(" + door["rooms"][0].get<std::string>() + "," + door["rooms"][1].get<std::string>() + ")";
    if (door["width"].get<double>() < narrowest) narrowest = door["width"].get<double>(), narrow = move;
    if (door["width"].get<double>() > widest) widest = door["width"].get<double>(), wide = move;
  }
  ASSERT_LT(narrowest, 0.9);
  ASSERT_GT(widest, 1.0);
  const auto found_by = [&](const std::string& action, int steps) {
    double mass = 0;
    for (const auto& [step, p] : problem["actions"][action]["planning"]["pmf"].items()) {
      if (std::stoi(step) <= steps) mass += p.get<double>();
    }
    return mass;
  };
  EXPECT_LT(found_by(narrow, 3), found_by(wide, 3)) << narrow << " against " << wide;
  // The same model and world write the same file, whatever the threads computing the features
  // (the first run: one per hardware thread).
  for (const std::string threads : {"1", "3"}) {
    const std::string again = (c.dir / ("w4.again" + threads + ".json")).string();
    ASSERT_EQ(ontime({"predict", "--domain", "navigation", "--world", c.unseen, "--model", model, "-o", again,
                      "--threads", threads})
                  .exit_code,
              0);
    EXPECT_EQ(read_file(again), read_file(instance)) << threads << " threads";
  }
}

TEST(Cli, PredictRefusesAModelOfOtherFeaturesAndWritesNothing) {
  const Corpus c = corpus("predict-refused");
  const std::string unnamed = (c.dir / "unnamed.json").string();
  ASSERT_EQ(ontime({"fit", c.logs[0], "--conditional", "pooled", "--step", "3", "-o", unnamed}).exit_code, 0);
  const std::string instance = (c.dir / "refused.json").string();
  const auto refused =
      ontime({"predict", "--domain", "navigation", "--world", c.unseen, "--model", unnamed, "-o", instance});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("fitted on other features"), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(instance));
  // A log without features, and --deadline with --conditional, are refused before any fit.
  const auto plain = ontime({"fit", testing::source_path("data/logs/navigation.jsonl").string(), "--conditional",
                             "hazard", "--step", "3", "-o", (c.dir / "plain.json").string()});
  EXPECT_EQ(plain.exit_code, 2);
  EXPECT_NE(plain.err.find("record 1: has no 'features'"), std::string::npos) << plain.err;
  EXPECT_EQ(ontime({"fit", c.logs[0], "--conditional", "hazard", "--step", "3", "--deadline", "4", "-o",
                    (c.dir / "x.json").string()})
                .exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(c.dir / "plain.json"));
}

// A model file with a number that is not finite, or whose finite numbers overflow where they meet
// the world's features, is refused with exit 2 and one line naming the file and the place (`line
// L, column C`; `parameters`), and nothing is written.
TEST(Cli, PredictRefusesAModelWhoseNumbersAreNotFiniteOrOverflow) {
  const auto dir = scratch("predict-overflow");
  const std::string trained = (dir / "w1.json").string(), unseen = (dir / "w4.json").string();
  ASSERT_EQ(
      ontime({"generate-world", "--rows", "2", "--cols", "3", "--narrow-doors", "0.5", "--seed", "1", "-o", trained})
          .exit_code,
      0);
  ASSERT_EQ(ontime({"generate-world", "--rows", "2", "--cols", "3", "--seed", "4", "-o", unseen}).exit_code, 0);
  const std::string log = (dir / "w1.jsonl").string();
  const auto collected =
      ontime({"collect", "--domain", "navigation", "--world", trained, "--every-action", "--features", "--trials", "6",
              "--threads", "2", "--log", log, "-o", (dir / "w1.instance.json").string()});
  ASSERT_EQ(collected.exit_code, 0) << collected.err;
  const std::string model = (dir / "hazard.json").string();
  ASSERT_EQ(
      ontime({"fit", log, "--conditional", "hazard", "--domain", "navigation", "--step", "3", "-o", model}).exit_code,
      0);
  json file = json::parse(read_file(model));
  const std::string instance = (dir / "predicted.json").string();
  const auto refused = [&](const std::string& text, const std::string& name, const std::string& place) {
    const std::string bad = (dir / name).string();
    std::ofstream(bad, std::ios::binary) << text;
    const auto result =
        ontime({"predict", "--domain", "navigation", "--world", unseen, "--model", bad, "-o", instance});
    EXPECT_EQ(result.exit_code, 2) << name << ": " << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_NE(result.err.find(bad + ": " + place), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(instance)) << name;
  };
  file["parameters"]["hazard"][0] = 12345.5;
  const std::string marked = file.dump(2);
  for (const std::string number : {"1e999", "NaN"}) {
    std::string text = marked;
    text.replace(text.find("12345.5"), 7, number);
    refused(text, number + ".json", "line ");
  }
  for (std::size_t i = 0; i < file["parameters"]["hazard"].size(); ++i) {
    file["parameters"]["hazard"][i] = i % 2 == 0 ? 1e308 : -1e308;
  }
  refused(file.dump(2), "overflow.json", "parameters: the model's numbers overflow for some features");
}

// The kitchen family end to end: small generated scenes (one target, one or two neighbours), a
// few trials of every action with features, a pooled model over them, the instance of a scene
// none of them is; --library is refused (the kitchen cannot list its actions on their own).
TEST(Cli, PredictWritesTheInstanceOfAnUnseenKitchen) {
  const std::filesystem::path dir = scratch("predict-kitchen");
  std::vector<std::string> logs;
  std::string unseen;
  for (const std::string seed : {"1", "2", "3"}) {
    const std::string world = (dir / ("k" + seed + ".json")).string();
    ASSERT_EQ(ontime({"generate-world", "--domain", "manipulation", "--targets", "1", "--min-objects", "3",
                      "--max-objects", "3", "--min-clutter", "1", "--max-clutter", "2", "--seed", seed, "-o", world})
                  .exit_code,
              0);
    if (seed == "3") {
      unseen = world;
      continue;
    }
    const std::string log = (dir / ("k" + seed + ".jsonl")).string();
    const auto collected =
        ontime({"collect", "--domain", "manipulation", "--world", world, "--features", "--trials", "2", "--budget", "4",
                "--threads", "2", "--log", log, "-o", (dir / ("k" + seed + ".instance.json")).string()});
    ASSERT_EQ(collected.exit_code, 0) << collected.err;
    logs.push_back(log);
  }
  const std::string first = read_file(logs[0]);
  const json record = json::parse(first.substr(0, first.find('\n')));
  EXPECT_EQ(record["world"], "k1");
  EXPECT_EQ(record["features"].size(), 12u);            // the last, log_reach_share
  EXPECT_EQ(record["features"][0].get<double>(), 0.0);  // the first action picks

  const std::string model = (dir / "pooled.json").string();
  std::vector<std::string> fit{"fit"};
  fit.insert(fit.end(), logs.begin(), logs.end());
  for (const std::string arg : {"--conditional", "pooled", "--domain", "manipulation", "--step", "7", "--json", "-o"}) {
    fit.push_back(arg);
  }
  fit.push_back(model);
  const auto fitted = ontime(fit);
  ASSERT_EQ(fitted.exit_code, 0) << fitted.err;
  EXPECT_EQ(json::parse(fitted.out)["worlds"].get<int>(), 2);
  EXPECT_EQ(json::parse(fitted.out)["feature_names"][0], "is_place");

  const std::string instance = (dir / "k3.predicted.json").string();
  const auto predicted =
      ontime({"predict", "--domain", "manipulation", "--world", unseen, "--model", model, "-o", instance, "--json"});
  ASSERT_EQ(predicted.exit_code, 0) << predicted.err;
  const json world = json::parse(read_file(unseen));
  const json problem = json::parse(read_file(instance));
  EXPECT_EQ(problem["skeletons"], world["skeletons"]);
  EXPECT_EQ(problem["deadline"], world["collection"]["deadline"]);
  EXPECT_EQ(json::parse(predicted.out)["skeletons"].get<std::size_t>(), world["skeletons"].size());
  const auto solved = ontime({"solve", instance, "--json"});
  EXPECT_EQ(solved.exit_code, 0) << solved.err;

  // A model of unnamed features (fitted without --domain) is refused, as for buildings.
  const std::string unnamed = (dir / "unnamed.json").string();
  ASSERT_EQ(ontime({"fit", logs[0], "--conditional", "pooled", "--step", "7", "-o", unnamed}).exit_code, 0);
  const auto other = ontime({"predict", "--domain", "manipulation", "--world", unseen, "--model", unnamed, "-o",
                             (dir / "other.json").string()});
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("fitted on other features"), std::string::npos) << other.err;

  const auto library = ontime({"predict", "--domain", "manipulation", "--world", unseen, "--model", model, "--library",
                               "-o", (dir / "library.json").string()});
  EXPECT_EQ(library.exit_code, 2);
  EXPECT_NE(library.err.find("cannot list every action"), std::string::npos) << library.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "library.json"));
}

}  // namespace
}  // namespace ontime
