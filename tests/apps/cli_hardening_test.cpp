// Inputs made to break the tool: nesting without end in every kind of JSON file it reads (an
// instance, a planner log, a chain log, a model file), and boosted models whose boosters would
// crash or hang XGBoost. Each is refused with exit 2 and one line naming the file, the place and
// the rule.

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "apps/cli_test_support.hpp"

namespace ontime {
namespace {

using namespace cli_test;

void write_probe(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string replaced_once(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// `command` exits 2 with one line that starts with `file: PLACE: ` and holds `rule`.
void expect_refused_probe(const std::vector<std::string>& command, const std::string& file, const std::string& place,
                          const std::string& rule) {
  const auto result = ontime(command);
  EXPECT_EQ(result.exit_code, 2) << command[0] << " " << file << ": " << result.err.substr(0, 300);
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err.substr(0, 300);
  EXPECT_NE(result.err.find(file + ": " + place + ": "), std::string::npos) << result.err.substr(0, 300);
  EXPECT_NE(result.err.find(rule), std::string::npos) << result.err.substr(0, 300);
}

const std::string kTooDeepRule = "nested more than 256 levels deep";

const std::string kProbeLog =
    "{\"action\": \"a\", \"planning_seconds\": 2, \"found\": false, \"world\": \"t\", \"features\": [0]}\n"
    "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1, \"world\": \"t\", "
    "\"features\": [0]}\n";

TEST(Cli, DeepNestingIsRefusedInEveryFileKindAtItsPlace) {
  const auto dir = scratch("deep-nesting");
  const std::string deep(300'000, '[');

  // An instance whose chain state is 300,000 nested '[' (SPEC §9).
  const std::string coffee = read_file(testing::source_path("data/instances/chains/coffee-building.json"));
  const std::string instance = (dir / "instance.json").string();
  write_probe(instance, replaced_once(coffee, "\"start\": \"0\"", "\"start\": " + deep));
  const std::size_t line = 1 + std::count(coffee.begin(), coffee.begin() + coffee.find("\"start\": \"0\""), '\n');
  // The line starts with three spaces and `"start": `: its first '[' is at column 13 and is the
  // fourth container open (the file, `chains`, `queue`); the 257th is 253 columns on.
  expect_refused_probe({"solve", instance}, instance, "line " + std::to_string(line) + ", column 266", kTooDeepRule);

  // A planner log whose second record's features are nested without end.
  const std::string log = (dir / "log.jsonl").string();
  write_probe(log,
              replaced_once(kProbeLog, "\"features\": [0]}\n{", "\"features\": [0]}\n{\"features\": " + deep + "\n{"));
  expect_refused_probe({"fit", log, "--conditional", "pooled", "--step", "1", "-o", (dir / "m.json").string()}, log,
                       "line 2, column 269", kTooDeepRule);

  // A chain log.
  const std::string chain_log = (dir / "queue.jsonl").string();
  write_probe(chain_log,
              "{\"sequence\": \"mon\", \"step\": 0, \"state\": 0}\n{\"sequence\": \"mon\", \"step\": 1, "
              "\"state\": " +
                  deep + "}\n");
  expect_refused_probe({"fit-chain", chain_log, "-o", (dir / "chain.json").string()}, chain_log, "line 2, column 296",
                       kTooDeepRule);

  // Model files: nesting without end in `version`, `kind` and `feature_names`, read by
  // fit-strength; and nesting within the limit, quoted in the message without walking it.
  const std::string train = (dir / "train.jsonl").string();
  write_probe(train, kProbeLog);
  const std::string model = (dir / "model.json").string();
  ASSERT_EQ(ontime({"fit", train, "--conditional", "pooled", "--step", "1", "-o", model}).exit_code, 0);
  const std::string text = read_file(model);
  for (const std::string key : {"version", "kind", "feature_names"}) {
    const std::size_t at = text.find("\"" + key + "\": ");
    ASSERT_NE(at, std::string::npos) << key;
    const std::size_t end = text.find('\n', at);
    const std::string member = text.substr(at, end - at);
    const std::string bad = (dir / ("deep-" + key + ".json")).string();
    write_probe(bad, replaced_once(text, member, "\"" + key + "\": " + deep));
    const std::size_t line_of = 1 + std::count(text.begin(), text.begin() + at, '\n');
    // The first '[' follows `"KEY": ` and is the second container open (the file the first).
    const std::size_t column = at - text.rfind('\n', at) + key.size() + 4 + 255;
    expect_refused_probe({"fit-strength", train, "--model", bad, "--strengths", "1"}, bad,
                         "line " + std::to_string(line_of) + ", column " + std::to_string(column), kTooDeepRule);
  }
  const std::size_t version = text.find("\"version\": ");
  const std::string nested = (dir / "nested-version.json").string();
  write_probe(nested, replaced_once(text, text.substr(version, text.find('\n', version) - version),
                                    "\"version\": " + std::string(255, '[') + std::string(255, ']') + ","));
  expect_refused_probe({"fit-strength", train, "--model", nested, "--strengths", "1"}, nested, "version",
                       "(got [[[...]]])");
}

// A boosted model whose planning booster has a cycle of children (prediction would loop forever)
// or a child beyond its nodes (read out of bounds): refused before XGBoost reads it.
// Item 5 of round 4: features out of range are refused naming the log, the record and the feature,
// for both kinds, before any fit (the hazard kind's optimiser and XGBoost never see them); a motion
// found in no time takes its first step, as `fit` counts it, and the model written reads back.
TEST(Cli, AConditionalFitRefusesHugeFeaturesAtTheirRecordAndTakesInstantMotions) {
  const auto dir = scratch("conditional-features");
  const std::string log = (dir / "huge.jsonl").string();
  for (const std::string huge : {"1e308", "-1e308", "3.5e38", "1e16"}) {
    write_probe(log, replaced_once(kProbeLog, "\"features\": [0]}\n{", "\"features\": [" + huge + "]}\n{"));
    for (const std::string kind : {"pooled", "hazard", "boosted"}) {
      expect_refused_probe({"fit", log, "--conditional", kind, "--step", "1", "-o", (dir / "m.json").string()}, log,
                           "record 1: features[0]", "a feature must be within [-1e15, 1e15]");
      EXPECT_FALSE(std::filesystem::exists(dir / "m.json")) << kind << " " << huge;
    }
  }
  const std::string instant = (dir / "instant.jsonl").string();
  write_probe(instant, replaced_once(kProbeLog, "\"planning_seconds\": 1,", "\"planning_seconds\": 0,"));
  for (const std::string kind : {"pooled", "hazard", "boosted"}) {
    const std::string model = (dir / (kind + ".json")).string();
    const auto fitted = ontime({"fit", instant, "--conditional", kind, "--step", "1", "--json", "-o", model});
    ASSERT_EQ(fitted.exit_code, 0) << kind << ": " << fitted.err;
    const auto read_back = ontime({"fit-strength", instant, "--model", model, "--strengths", "1"});
    EXPECT_EQ(read_back.exit_code, 0) << kind << ": " << read_back.err;
  }
}

TEST(Cli, ABoostedModelWithABrokenTreeIsRefused) {
  const auto dir = scratch("broken-booster");
  const std::string train = (dir / "train.jsonl").string();
  std::string rows;
  for (int i = 0; i < 40; ++i) {
    rows += "{\"action\": \"a\", \"planning_seconds\": " + std::to_string(1 + i % 4) +
            ", \"found\": " + (i % 3 == 0 ? "false" : "true, \"execution_seconds\": 1") +
            ", \"world\": \"t\", \"features\": [" + std::to_string(i % 4) + "]}\n";
  }
  write_probe(train, rows);
  const std::string model = (dir / "model.json").string();
  const auto fitted =
      ontime({"fit", train, "--conditional", "boosted", "--step", "1", "--trees", "2", "--depth", "2", "-o", model});
  ASSERT_EQ(fitted.exit_code, 0) << fitted.err;
  json file = json::parse(read_file(model));
  json booster = json::parse(file["parameters"]["planning_booster"].get<std::string>());
  json& tree = booster["learner"]["gradient_booster"]["model"]["trees"][0];
  ASSERT_GE(tree["left_children"].size(), 3u) << "a tree of one leaf: nothing to break";
  const auto refused = [&](const std::string& name, const std::string& member, const json& value,
                           const std::string& rule) {
    json broken = booster;
    broken["learner"]["gradient_booster"]["model"]["trees"][0][member][0] = value;
    json bad = file;
    bad["parameters"]["planning_booster"] = broken.dump();
    const std::string path = (dir / name).string();
    write_probe(path, bad.dump(2));
    expect_refused_probe(
        {"fit-strength", train, "--model", path, "--strengths", "1"}, path, "parameters.planning_booster",
        "not a booster OnTime reads: at learner.gradient_booster.model.trees[0]." + member + "[0]: " + rule);
  };
  refused("cycle.json", "left_children", 0,
          "a child must be a node from 1 to " + std::to_string(tree["left_children"].size() - 1) +
              ", or -1 for both children of a leaf (got 0)");
  refused("beyond.json", "right_children", 1'000'000,
          "a child must be a node from 1 to " + std::to_string(tree["left_children"].size() - 1) +
              ", or -1 for both children of a leaf (got 1000000)");
  refused("split.json", "split_indices", 5, "must be a feature index below 1 (got 5)");
}

// SIGTERM, SIGINT or SIGHUP while an output is being written — a chain of 4,001 states (64 MB)
// by fit-chain, a log of 1.8 million records (220 MB) by sample-log: the command dies of the
// signal and leaves neither its temporary file nor a partial output. The signal is sent once the
// temporary file is seen.
TEST(Cli, AnOutputInterruptedWhileWrittenLeavesNoTemporaryFile) {
  const auto dir = scratch("interrupted-output");
  const std::string log = (dir / "queue.jsonl").string();
  write_probe(log,
              "{\"sequence\": \"mon\", \"step\": 0, \"state\": 0}\n{\"sequence\": \"mon\", \"step\": 1, "
              "\"state\": 1}\n");
  const auto out = dir / "out";
  std::filesystem::create_directories(out);
  const auto temporary_seen = [&out] {
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(out, error)) {
      if (entry.path().filename().string().find(".tmp-") != std::string::npos) return true;
    }
    return false;
  };
  const std::vector<std::vector<std::string>> writers{
      {ONTIME_CLI, "fit-chain", log, "--kind", "birth-death", "--capacity", "4000", "-o",
       (out / "chain.json").string()},
      {ONTIME_CLI, "sample-log", paper("instance1"), "--attempts", "200000", "-o", (out / "log.jsonl").string()}};
  for (const auto& command : writers) {
    for (const int signal_number : {SIGTERM, SIGINT, SIGHUP}) {
      const auto stopped = testing::run_process(command, temporary_seen, signal_number);
      EXPECT_EQ(stopped.exit_code, 128 + signal_number) << command[1] << ": " << stopped.err;
      EXPECT_TRUE(std::filesystem::is_empty(out)) << command[1] << " " << signal_number;
    }
  }
}

}  // namespace
}  // namespace ontime
