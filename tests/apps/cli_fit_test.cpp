// CLI tests of `fit`: planner logs and OMPL benchmark logs fitted back to their instance (through
// a mapping, an action per log or a library of per-action skeletons), and every bad log, option
// and Laplace alpha refused in one line.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli_test_support.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/util/random.hpp"
#include "support/bad_logs.hpp"
#include "support/bad_ompl_logs.hpp"

namespace ontime {
namespace {

using namespace cli_test;

double optimum(const std::string& instance) {
  const auto result = ontime({"solve", instance, "--json"});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  return json::parse(result.out)["optimal_success_probability"].get<double>();
}

TEST(Cli, SampledLogFitsBackToTheOptimumWithinOneHundredth) {
  const std::filesystem::path dir = scratch("round-trip");
  const std::string log = (dir / "instance1.jsonl").string();
  const std::string fitted = (dir / "fitted.json").string();
  const auto sampled = ontime({"sample-log", paper("instance1"), "--attempts", "20000", "--seed", "3", "-o", log});
  ASSERT_EQ(sampled.exit_code, 0) << sampled.err;
  const auto fit = ontime(
      {"fit", log, "--step", "1", "--deadline", "14", "--skeletons", paper("instance1"), "-o", fitted, "--json"});
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const json report = json::parse(fit.out);
  EXPECT_EQ(report["records"].get<int>(), 9 * 20000);  // instance 1 uses 9 actions
  EXPECT_EQ(report["actions"].size(), 9u);
  EXPECT_EQ(report["actions"][0]["attempts"].get<int>(), 20000);
  EXPECT_NEAR(optimum(fitted), optimum(paper("instance1")), 0.01);
  // Same seed, same log.
  const std::string again = (dir / "again.jsonl").string();
  ASSERT_EQ(ontime({"sample-log", paper("instance1"), "--attempts", "20000", "--seed", "3", "-o", again}).exit_code, 0);
  EXPECT_EQ(read_file(log), read_file(again));
}

TEST(Cli, FitRejectsEveryBadLogWithOneLineNamingFileLineAndRule) {
  const std::filesystem::path dir = scratch("bad-logs");
  for (const testing::BadInput& bad : testing::kBadLogs) {
    const std::string path = testing::source_path("tests/data/bad_logs/" + bad.file).string();
    const std::string output = (dir / "never-written.json").string();
    const auto result =
        ontime({"fit", path, "--step", "1", "--deadline", "5", "--skeletons", paper("figure1"), "-o", output});
    EXPECT_EQ(result.exit_code, 2) << bad.file;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << bad.file << ": " << result.err;
    EXPECT_NE(result.err.find(path + ": " + bad.place + ": "), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(bad.rule), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(output)) << bad.file;
  }
}

TEST(Cli, FitNamesTheSkeletonActionMissingFromTheLog) {
  const std::filesystem::path dir = scratch("missing-action");
  const std::string log = (dir / "figure1.jsonl").string();
  ASSERT_EQ(ontime({"sample-log", paper("figure1"), "--attempts", "10", "-o", log}).exit_code, 0);
  const auto result = ontime({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", paper("instance1"), "-o",
                              (dir / "out.json").string()});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find(paper("instance1") + ": skeletons[0][0]: action 'a1_1' has no record in the log " + log),
            std::string::npos)
      << result.err;
  EXPECT_EQ(
      ontime({"fit", log, "--step", "0", "--deadline", "5", "--skeletons", paper("figure1"), "-o", "x.json"}).exit_code,
      2);
  EXPECT_EQ(
      ontime({"fit", log, "--step", "1", "--deadline", "0", "--skeletons", paper("figure1"), "-o", "x.json"}).exit_code,
      2);
  EXPECT_EQ(ontime({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", paper("figure1"), "-o", "x.json",
                    "--laplace", "-1"})
                .exit_code,
            2);
}

std::string kitchen_log() { return testing::source_path("tests/data/ompl_logs/kitchen.log").string(); }

TEST(Cli, FitReadsOmplBenchmarkLogsThroughAMappingOrAnActionPerLog) {
  const std::filesystem::path dir = scratch("ompl-fit");
  const std::string skeletons = (dir / "skeletons.json").string();
  std::ofstream(skeletons) << R"json({"skeletons": [["move(R1,R2)", "pick(cup)"]]})json";
  const std::string mapping = (dir / "mapping.json").string();
  std::ofstream(mapping) << R"json({"rules": [{"planner": "geometric_RRTConnect", "action": "move(R1,R2)"},
                                             {"planner": "geometric_RRTstar", "action": "pick(cup)"}]})json";
  const std::string output = (dir / "kitchen.json").string();
  const auto mapped =
      ontime({"fit", "--format", "ompl-benchmark", kitchen_log(), "--speed", "0.5", "--mapping", mapping, "--step",
              "0.5", "--deadline", "30", "--skeletons", skeletons, "-o", output, "--json"});
  ASSERT_EQ(mapped.exit_code, 0) << mapped.err;
  const json report = json::parse(mapped.out);
  EXPECT_EQ(report["format"], "ompl-benchmark");
  EXPECT_EQ(report["records"].get<int>(), 6);
  ASSERT_EQ(report["actions"].size(), 2u);
  EXPECT_EQ(report["actions"][0]["action"], "move(R1,R2)");
  EXPECT_EQ(report["actions"][0]["found"].get<int>(), 2);
  EXPECT_EQ(report["actions"][0]["cut_off"].get<int>(), 1);
  EXPECT_EQ(report["actions"][1]["action"], "pick(cup)");
  EXPECT_EQ(report["actions"][1]["found"].get<int>(), 1);
  EXPECT_EQ(report["actions"][1]["cut_off"].get<int>(), 2);
  // move(R1,R2): found at 0.125 s (1 step) and 1.75 s (4 steps), cut off at 2 s (4 steps survived).
  const Problem fitted = load_problem(output);
  const Distribution& planning = fitted.action(0).planning;
  EXPECT_DOUBLE_EQ(planning.pmf(1), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(planning.pmf(4), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(planning.never(), 1.0 / 3.0);
  // Execution: 3.25 / 0.5 = 6.5 s (13 steps) and 4.5 / 0.5 = 9 s (18 steps).
  const Distribution& execution = fitted.action(0).execution;
  EXPECT_DOUBLE_EQ(execution.pmf(13), 0.5);
  EXPECT_DOUBLE_EQ(execution.pmf(18), 0.5);

  // One action per log: the same log twice, every run of each given to one action.
  const auto per_log =
      ontime({"fit",      "--format",    "ompl-benchmark", kitchen_log(), kitchen_log(), "--speed", "1",
              "--action", "move(R1,R2)", "--action",       "pick(cup)",   "--step",      "0.5",     "--deadline",
              "30",       "--skeletons", skeletons,        "-o",          output,        "--json"});
  ASSERT_EQ(per_log.exit_code, 0) << per_log.err;
  const json per_log_report = json::parse(per_log.out);
  EXPECT_EQ(per_log_report["records"].get<int>(), 12);
  EXPECT_EQ(per_log_report["actions"][0]["attempts"].get<int>(), 6);
  EXPECT_EQ(per_log_report["actions"][0]["found"].get<int>(), 3);
  EXPECT_EQ(per_log_report["actions"][1]["attempts"].get<int>(), 6);
}

TEST(Cli, FitRefusesOmplOptionsThatDoNotFit) {
  const std::filesystem::path dir = scratch("ompl-usage");
  const std::string output = (dir / "never-written.json").string();
  const auto fit = [&](std::vector<std::string> extra) {
    std::vector<std::string> arguments{"fit",         "--step",         "1",  "--deadline", "5",
                                       "--skeletons", paper("figure1"), "-o", output};
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    return ontime(arguments);
  };
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--format", "ompl-benchmark", kitchen_log()}, "needs --speed"},
      {{"--format", "ompl-benchmark", kitchen_log(), "--speed", "1", "--action", "a", "--action", "b"},
       "--action is given 2 times for 1 LOG files"},
      {{"--format", "ompl-benchmark", kitchen_log(), "--speed", "1", "--action", "a", "--mapping", "m.json"},
       "either --action (one per LOG) or --mapping"},
      {{kitchen_log(), "--speed", "1"}, "options of --format ompl-benchmark"},
      {{kitchen_log(), kitchen_log()}, "--format jsonl reads one LOG"},
      {{"--format", "ompl-benchmark", kitchen_log(), "--speed", "0"}, "--speed"},
      {{"--format", "ompl", kitchen_log()}, "--format"},
  };
  for (const auto& [extra, message] : cases) {
    const auto result = fit(extra);
    EXPECT_EQ(result.exit_code, 2) << message << ": " << result.err;
    EXPECT_NE(result.err.find(message), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(output));
  }
}

TEST(Cli, FitRejectsEveryBadOmplLogWithOneLineNamingFileLineAndRule) {
  const std::filesystem::path dir = scratch("bad-ompl-logs");
  for (const testing::BadInput& bad : testing::kBadOmplLogs) {
    const std::string path = testing::source_path("tests/data/bad_ompl_logs/" + bad.file).string();
    const std::string output = (dir / "never-written.json").string();
    const auto result = ontime({"fit", "--format", "ompl-benchmark", path, "--speed", "1", "--step", "1", "--deadline",
                                "5", "--skeletons", paper("figure1"), "-o", output});
    EXPECT_EQ(result.exit_code, 2) << bad.file;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << bad.file << ": " << result.err;
    EXPECT_NE(result.err.find(path + ": " + bad.place + ": "), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(bad.rule), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(output)) << bad.file;
  }
}

// --library fits every action of a log as a skeleton of its own: a library of per-action
// distributions, e.g. of a collection of every doorway move.
TEST(Cli, FitWithLibraryGivesOneSkeletonPerActionOfTheLog) {
  const std::filesystem::path dir = scratch("fit-library");
  const std::string log = (dir / "instance1.jsonl").string();
  ASSERT_EQ(ontime({"sample-log", paper("instance1"), "--attempts", "50", "-o", log}).exit_code, 0);
  const std::string library = (dir / "library.json").string();
  const auto fit = ontime({"fit", log, "--step", "1", "--deadline", "14", "--library", "-o", library, "--json"});
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const json instance = json::parse(read_file(library));
  ASSERT_EQ(instance["actions"].size(), 9u);  // instance 1 uses 9 actions
  ASSERT_EQ(instance["skeletons"].size(), 9u);
  std::set<std::string> skeleton_actions;
  for (const json& skeleton : instance["skeletons"]) {
    ASSERT_EQ(skeleton.size(), 1u);
    skeleton_actions.insert(skeleton[0].get<std::string>());
  }
  for (const auto& [id, action] : instance["actions"].items()) EXPECT_EQ(skeleton_actions.count(id), 1u) << id;
  // The same distributions as a fit along the instance's own skeletons.
  const std::string along = (dir / "along.json").string();
  ASSERT_EQ(
      ontime({"fit", log, "--step", "1", "--deadline", "14", "--skeletons", paper("instance1"), "-o", along}).exit_code,
      0);
  EXPECT_EQ(instance["actions"], json::parse(read_file(along))["actions"]);
  // Exactly one of --skeletons and --library.
  const auto neither = ontime({"fit", log, "--step", "1", "--deadline", "14", "-o", (dir / "x.json").string()});
  EXPECT_EQ(neither.exit_code, 2);
  EXPECT_EQ(std::count(neither.err.begin(), neither.err.end(), '\n'), 1) << neither.err;
  EXPECT_NE(neither.err.find("--skeletons FILE or --library"), std::string::npos) << neither.err;
  EXPECT_EQ(ontime({"fit", log, "--step", "1", "--deadline", "14", "--library", "--skeletons", paper("instance1"), "-o",
                    (dir / "x.json").string()})
                .exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
}

TEST(Cli, ALaplaceAlphaThatSwampsTheLogIsAUsageError) {
  const auto directory = scratch("laplace");
  const auto sampled = ontime({"sample-log", paper("figure1"), "-o", (directory / "log.jsonl").string()});
  ASSERT_EQ(sampled.exit_code, 0) << sampled.err;
  const auto fitted =
      ontime({"fit", (directory / "log.jsonl").string(), "--step", "1", "--deadline", "5", "--skeletons",
              paper("figure1"), "--laplace", "1e308", "-o", (directory / "fit.json").string()});
  EXPECT_EQ(fitted.exit_code, 2) << fitted.err;
  EXPECT_NE(fitted.err.find("laplace: the Laplace smoothing alpha must be between 0 and 1e+06"), std::string::npos)
      << fitted.err;
  EXPECT_FALSE(std::filesystem::exists(directory / "fit.json"));
}

// A corpus of 3,000 attempts whose planning time and share found depend on three features (one
// of them without effect), cut off after 12 s: `fit --conditional boosted` writes the same model
// file whichever build of libm's exp and log glibc picks for the CPU (with and without FMA and
// AVX2, and SSE2 alone), and sums it up without XGBoost's trees.
TEST(Cli, BoostedFitGivesTheSameBytesWhicheverLibmGlibcPicks) {
  const auto directory = scratch("boosted");
  const std::string log = (directory / "corpus.jsonl").string();
  {
    std::ofstream out(log);
    SplitMix64 random(9);
    for (int i = 0; i < 3000; ++i) {
      const double width = 0.6 + 0.8 * uniform01(random), clutter = uniform01(random), noise = uniform01(random);
      const double hazard = 0.05 + 0.4 * (width - 0.6) * (1 - 0.5 * clutter);
      // Found within the step of `seconds` (a geometric number of steps), unless never or later
      // than 12 s.
      bool found = uniform01(random) > 0.1 + 0.3 * clutter;
      double seconds = 0.5;
      while (found && seconds < 12 && uniform01(random) > hazard) seconds += 1;
      found = found && seconds < 12;
      json record{{"action", "move"},
                  {"world", std::string{'w', static_cast<char>('0' + i % 7)}},
                  {"planning_seconds", found ? seconds : 12.0},
                  {"found", found},
                  {"features", {width, clutter, noise}}};
      const double execution = 2 + 3 * uniform01(random) + 2 * clutter;
      if (found) record["execution_seconds"] = execution;
      out << record.dump() << "\n";
    }
  }
  std::vector<std::string> models;
  for (const char* tunables : {"glibc.cpu.hwcaps=", "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX",
                               "glibc.cpu.hwcaps=-AVX512F,-AVX2,-FMA,-AVX,-SSE4_1,-SSE4_2"}) {
    const auto model = directory / ("model" + std::to_string(models.size()) + ".json");
    const auto fitted = testing::run_process({"/usr/bin/env", std::string("GLIBC_TUNABLES=") + tunables, ONTIME_CLI,
                                              "fit", log, "--conditional", "boosted", "--step", "1",
                                              "--aft-distribution", "logistic", "--json", "-o", model.string()});
    ASSERT_EQ(fitted.exit_code, 0) << tunables << ": " << fitted.err;
    const json summary = json::parse(fitted.out);
    EXPECT_EQ(summary["kind"], "boosted");
    EXPECT_EQ(summary["horizon"], 12);
    EXPECT_EQ(summary["worlds"], 7);
    EXPECT_EQ(summary["parameters"]["trees"], 100);
    EXPECT_FALSE(summary["parameters"].contains("never_booster"));
    models.push_back(read_file(model));
  }
  EXPECT_TRUE(models[1] == models[0]);
  EXPECT_TRUE(models[2] == models[0]);
  // Its text summary, and a law it does not know.
  const auto text = ontime({"fit", log, "--conditional", "boosted", "--step", "1", "--trees", "10", "-o",
                            (directory / "ten.json").string()});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("Planning log-likelihood per record after 10 rounds of trees: -"), std::string::npos)
      << text.out;
  const auto refused = ontime({"fit", log, "--conditional", "boosted", "--step", "1", "--aft-distribution", "weibull",
                               "-o", (directory / "refused.json").string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(directory / "refused.json"));
}

}  // namespace
}  // namespace ontime

namespace ontime {
namespace {

using namespace cli_test;

// `fit-chain`: a queue read once per step, fitted as a birth-death chain and as a free markov
// one; bad logs and options exit 2, naming the file, the line or the step, and write nothing.
TEST(Cli, FitChainWritesTheChainOfAQueuesObservations) {
  const std::filesystem::path dir = scratch("fit-chain");
  const std::string log = (dir / "queue.jsonl").string();
  {
    std::ofstream out(log);
    const std::vector<int> lengths{0, 0, 1, 2, 2, 1, 1, 0, 1, 2, 3, 3, 2};
    for (std::size_t t = 0; t < lengths.size(); ++t) {
      out << "{\"sequence\": \"mon\", \"step\": " << t << ", \"state\": " << lengths[t] << "}\n";
    }
  }
  const std::string chain = (dir / "queue.chain.json").string();
  const auto fitted = ontime(
      {"fit-chain", log, "--kind", "birth-death", "--name", "coffee-queue", "--capacity", "4", "-o", chain, "--json"});
  ASSERT_EQ(fitted.exit_code, 0) << fitted.err;
  const json out = json::parse(fitted.out);
  EXPECT_EQ(out["kind"], "birth-death");
  EXPECT_EQ(out["states"].size(), 5u);
  EXPECT_EQ(out["transitions_counted"].get<int>(), 12);
  // No stay at the capacity: the closed form, up 5 over 5 + 1 + 3 + 3 (ups, stays at 0, downs,
  // stays in between).
  EXPECT_DOUBLE_EQ(out["arrival"].get<double>(), 5.0 / 12);
  const json file = json::parse(read_file(chain));
  EXPECT_EQ(file["format"], "ontime-chain");
  EXPECT_EQ(file["name"], "coffee-queue");
  EXPECT_EQ(file["start"], "0");
  EXPECT_EQ(file["transitions"], out["transitions"]);

  const auto markov = ontime({"fit-chain", log, "-o", (dir / "markov.json").string()});
  ASSERT_EQ(markov.exit_code, 0) << markov.err;
  EXPECT_NE(markov.out.find("Fitted a markov chain 'chain' of 4 states to 12 transitions"), std::string::npos)
      << markov.out;

  const auto refused = [&dir](const std::vector<std::string>& arguments, const std::string& message) {
    const std::string output = (dir / "refused.json").string();
    std::vector<std::string> command{"fit-chain"};
    command.insert(command.end(), arguments.begin(), arguments.end());
    command.push_back("-o");
    command.push_back(output);
    const auto result = ontime(command);
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_NE(result.err.find(message), std::string::npos) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_FALSE(std::filesystem::exists(output));
  };
  const std::string jump = (dir / "jump.jsonl").string();
  std::ofstream(jump) << "{\"step\": 0, \"state\": 0}\n{\"step\": 1, \"state\": 2}\n";
  refused({jump, "--kind", "birth-death"}, "jump.jsonl: sequence '', step 1: the queue goes from 0 to 2 in one step");
  const std::string backwards = (dir / "backwards.jsonl").string();
  std::ofstream(backwards) << "{\"step\": 4, \"state\": 0}\n{\"step\": 2, \"state\": 1}\n";
  refused({backwards}, "backwards.jsonl: line 2: step: must be after the sequence's previous step, 4 (got 2)");
  refused({log, "--kind", "poisson"}, "unknown chain kind 'poisson'");
  refused({log, "--kind", "birth-death", "--states", "0,1"}, "give the capacity, not states");
  refused({log, "--states", "0,1"}, "queue.jsonl: sequence 'mon', step 3: state '2' is not among the states listed");
}

}  // namespace
}  // namespace ontime
