#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "ontime/allocator_registry.hpp"
#include "ontime/allocators/ppo.hpp"
#include "ontime/evaluation.hpp"
#include "support/bad_inputs.hpp"
#include "support/bad_logs.hpp"
#include "support/mini_world.hpp"
#include "support/paper.hpp"
#include "support/process.hpp"

namespace ontime {
namespace {

using nlohmann::json;

testing::ProcessResult ontime(std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), ONTIME_CLI);
  return testing::run_process(arguments);
}

std::string paper(const std::string& name) {
  return testing::source_path("data/instances/paper/" + name + ".json").string();
}

TEST(Cli, SolveReportsTheFigureOneOptimum) {
  const auto result = ontime({"solve", paper("figure1"), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_DOUBLE_EQ(out["optimal_success_probability"].get<double>(), 0.5625);
  EXPECT_EQ(out["first_choice"].get<int>(), 0);
  EXPECT_GT(out["states"].get<int>(), 0);
  EXPECT_TRUE(out.contains("seconds"));
}

TEST(Cli, EvaluateWritesTheDocumentedKeys) {
  const auto result = ontime({"evaluate", paper("instance4"), "--solver", "dp-rerun", "--episodes", "2000", "--seed",
                              "3", "--threads", "2", "--exact", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["solver"], "dp-rerun");
  EXPECT_EQ(out["episodes"], 2000);
  EXPECT_DOUBLE_EQ(out["exact_success_probability"].get<double>(), 0.9);
  const double rate = out["success_rate"].get<double>();
  EXPECT_NEAR(rate, 0.9, 4 * std::sqrt(0.09 / 2000));
  EXPECT_NEAR(out["ci95"].get<double>(), 1.96 * std::sqrt(rate * (1 - rate) / 2000), 1e-12);
  EXPECT_TRUE(out["decision_time_us"].contains("median"));
  EXPECT_TRUE(out["decision_time_us"].contains("p99"));
  EXPECT_GE(out["decision_time_us"]["max"].get<double>(), out["decision_time_us"]["p99"].get<double>());
  EXPECT_GT(out["decision_time_us"]["max"].get<double>(), 0.0);
  // Same seed with one thread: the same successes.
  const auto single = ontime({"evaluate", paper("instance4"), "--solver", "dp-rerun", "--episodes", "2000", "--seed",
                              "3", "--threads", "1", "--json"});
  EXPECT_EQ(json::parse(single.out)["successes"], out["successes"]);
}

TEST(Cli, TablePrintsOneRowPerInstanceAndTheOptimum) {
  const auto result = ontime(
      {"table", paper("instance2"), paper("instance4"), "--episodes", "500", "--exact", "--solvers", "dp,greedy"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("| instance "), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("| instance2 "), std::string::npos);
  EXPECT_NE(result.out.find("| instance4 "), std::string::npos);
  EXPECT_NE(result.out.find("optimum"), std::string::npos);
  EXPECT_NE(result.out.find("(0.9000)"), std::string::npos);  // dp on instance 4, exact
  EXPECT_NE(result.out.find("mean decision time"), std::string::npos);
  const auto as_json = ontime({"table", paper("instance4"), "--episodes", "500", "--exact", "--json"});
  ASSERT_EQ(as_json.exit_code, 0) << as_json.err;
  const json out = json::parse(as_json.out);
  EXPECT_DOUBLE_EQ(out["rows"][0]["optimal_success_probability"].get<double>(), 0.9);
  EXPECT_DOUBLE_EQ(out["rows"][0]["solvers"]["greedy"]["exact_success_probability"].get<double>(), 0.55);
}

TEST(Cli, EveryBadInstanceFailsWithOneLineNamingFilePlaceAndRule) {
  for (const testing::BadInput& bad : testing::kBadInputs) {
    const std::string path = testing::source_path("tests/data/bad/" + bad.file).string();
    for (const std::vector<std::string>& command :
         {std::vector<std::string>{"solve", path}, std::vector<std::string>{"evaluate", path, "--solver", "dp"}}) {
      std::vector<std::string> arguments = command;
      const auto result = ontime(arguments);
      EXPECT_EQ(result.exit_code, 2) << bad.file;
      EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << bad.file << ": " << result.err;
      EXPECT_NE(result.err.find(path + ": " + bad.place + ": "), std::string::npos) << result.err;
      EXPECT_NE(result.err.find(bad.rule), std::string::npos) << result.err;
      EXPECT_TRUE(result.out.empty()) << bad.file;
    }
  }
}

TEST(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(ontime({}).exit_code, 2);
  EXPECT_EQ(ontime({"frobnicate"}).exit_code, 2);
  EXPECT_EQ(ontime({"solve"}).exit_code, 2);
  EXPECT_EQ(ontime({"solve", "/nonexistent.json"}).exit_code, 2);
  const auto unknown = ontime({"evaluate", paper("figure1"), "--solver", "oracle"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown solver 'oracle'"), std::string::npos) << unknown.err;
  EXPECT_EQ(ontime({"evaluate", paper("figure1"), "--solver", "dp", "--episodes", "0"}).exit_code, 2);
  EXPECT_EQ(ontime({"table", paper("figure1"), "--solvers", "dp,nope"}).exit_code, 2);
  const auto capped = ontime({"solve", paper("instance1"), "--max-states", "20"});
  EXPECT_EQ(capped.exit_code, 2);
  EXPECT_NE(capped.err.find("cap of 20 states"), std::string::npos) << capped.err;
}

std::filesystem::path scratch(const std::string& name) {
  const auto directory = std::filesystem::temp_directory_path() / ("ontime_cli_test_" + name);
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  return directory;
}

std::size_t line_count(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  return lines;
}

TEST(Cli, TrainWritesAPolicyThatEvaluateAndTableUse) {
  const auto directory = scratch("train");
  const std::string policy = (directory / "instance4.json").string();
  const auto trained = ontime(
      {"train", paper("instance4"), "--solver", "ppo", "--episodes", "300", "--seed", "2", "--out", policy, "--json"});
  ASSERT_EQ(trained.exit_code, 0) << trained.err;
  const json report = json::parse(trained.out);
  EXPECT_TRUE(std::filesystem::exists(policy));
  EXPECT_GT(line_count(directory / "instance4.curve.csv"), 1U);
  EXPECT_TRUE(std::filesystem::exists(directory / "instance4.curve.png"));

  const auto evaluated = ontime({"evaluate", paper("instance4"), "--solver", "ppo", "--policy", policy, "--episodes",
                                 "500", "--exact", "--json"});
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
  EXPECT_DOUBLE_EQ(json::parse(evaluated.out)["exact_success_probability"].get<double>(),
                   report["exact_success_probability"].get<double>());
  const auto table =
      ontime({"table", paper("instance4"), "--solvers", "ppo,dp", "--policy", policy, "--episodes", "200"});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("| ppo"), std::string::npos) << table.out;

  const auto other = ontime({"evaluate", paper("instance1"), "--solver", "ppo", "--policy", policy});
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("trained for 2 skeletons"), std::string::npos) << other.err;
  const auto missing = ontime({"evaluate", paper("instance4"), "--solver", "ppo"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("needs a trained policy"), std::string::npos) << missing.err;
  const auto bad = ontime({"evaluate", paper("instance4"), "--solver", "ppo", "--policy", paper("instance4")});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find(paper("instance4") + ": format: "), std::string::npos) << bad.err;
}

TEST(Cli, StudiesWriteTheirCsvAndPlot) {
  const auto directory = scratch("study");
  const auto anytime = ontime({"study", "anytime", paper("instance4"), paper("instance5"), "--episodes", "30",
                               "--log10-multipliers", "0,1", "--out", directory.string(), "--threads", "1"});
  ASSERT_EQ(anytime.exit_code, 0) << anytime.err;
  EXPECT_EQ(line_count(directory / "anytime.csv"), 1U + 2 * 2);
  EXPECT_TRUE(std::filesystem::exists(directory / "anytime.png"));
  EXPECT_NE(anytime.out.find((directory / "anytime.png").string()), std::string::npos);
  const auto compute = ontime({"study", "compute-time", paper("instance4"), "--episodes", "20", "--iterations", "200",
                               "--out", directory.string(), "--no-plot"});
  ASSERT_EQ(compute.exit_code, 0) << compute.err;
  EXPECT_EQ(line_count(directory / "compute_time.csv"), 1U + 2);
  EXPECT_FALSE(std::filesystem::exists(directory / "compute_time.png"));
  const auto bad = ontime({"study", "anytime", paper("instance4"), "--log10-multipliers", "0,x"});
  EXPECT_EQ(bad.exit_code, 2);
}

TEST(Cli, KnapsackReductionWritesASolvableInstance) {
  const auto directory = scratch("knapsack");
  const std::string instance = (directory / "example.json").string();
  const auto reduced =
      ontime({"reduce-knapsack", testing::source_path("data/knapsack/example.json").string(), "--out", instance});
  ASSERT_EQ(reduced.exit_code, 0) << reduced.err;
  const auto solved = ontime({"solve", instance, "--json"});
  ASSERT_EQ(solved.exit_code, 0) << solved.err;
  const double epsilon = 1.0 / 2304;
  EXPECT_NEAR(json::parse(solved.out)["optimal_success_probability"].get<double>(),
              1 - (1 - 3 * epsilon) * (1 - 4 * epsilon), 1e-15);
  const auto bad = ontime({"reduce-knapsack", paper("figure1")});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find(paper("figure1") + ": name: unknown key"), std::string::npos) << bad.err;
}

// An interrupted run leaves the previous output file as it was; a complete run replaces it whole.
TEST(Cli, InterruptedTrainingLeavesTheOldFile) {
  const auto directory = scratch("interrupt");
  const auto policy = directory / "policy.json";
  { std::ofstream(policy) << "previous policy"; }
  const auto interrupted = testing::run_process(
      {ONTIME_CLI, "train", paper("instance1"), "--episodes", "10000", "--out", policy.string()}, 300);
  EXPECT_EQ(interrupted.exit_code, 128 + SIGINT);
  std::ifstream old(policy);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(old), {}), "previous policy");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(directory)) ++entries;
  EXPECT_EQ(entries, 1U);  // no partial or temporary file
  const auto complete =
      ontime({"train", paper("instance4"), "--episodes", "100", "--out", policy.string(), "--no-plot"});
  ASSERT_EQ(complete.exit_code, 0) << complete.err;
  EXPECT_NO_THROW(load_ppo_policy(policy));
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

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

TEST(Cli, PlotWritesTheHistogramsAndTheirData) {
  const std::filesystem::path dir = scratch("plot");
  const std::string png = (dir / "figure1.png").string();
  const auto result = ontime({"plot", paper("figure1"), "-o", png});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const std::string csv = read_file(dir / "figure1.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "action,distribution,step,probability");
  EXPECT_NE(csv.find("\"d1\",planning,4,0.5\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"d1\",execution,10,0.5\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"d1\",planning,never,0\n"), std::string::npos) << csv;
  EXPECT_EQ(ontime({"plot", "/nonexistent.json"}).exit_code, 2);
}

// An exact part beyond --max-states is reported in its cell; the rest of the table stands.
TEST(Cli, TableReportsAnExactPartOverTheCapInItsCell) {
  const auto text = ontime({"table", paper("instance1"), "--solvers", "dp,round-robin", "--episodes", "200", "--exact",
                            "--max-states", "100"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("(0.9340)"), std::string::npos) << text.out;                 // dp: 48 states
  EXPECT_NE(text.out.find("(cap reached)"), std::string::npos) << text.out;            // round-robin: 143
  EXPECT_NE(text.out.find("optimum over 100 states"), std::string::npos) << text.out;  // 872 states
  const auto as_json = ontime({"table", paper("instance1"), "--solvers", "dp,round-robin", "--episodes", "200",
                               "--exact", "--max-states", "100", "--json"});
  ASSERT_EQ(as_json.exit_code, 0) << as_json.err;
  const json row = json::parse(as_json.out)["rows"][0];
  EXPECT_EQ(row["solvers"]["dp"]["exact"]["states"].get<int>(), 48);
  EXPECT_FALSE(row["solvers"]["dp"]["exact"]["cap_reached"].get<bool>());
  EXPECT_TRUE(row["solvers"]["round-robin"]["exact"]["cap_reached"].get<bool>());
  EXPECT_FALSE(row["solvers"]["round-robin"].contains("exact_success_probability"));
  EXPECT_TRUE(row["optimum"]["cap_reached"].get<bool>());
  EXPECT_FALSE(row.contains("optimal_success_probability"));
}

TEST(Cli, CollectWritesTheLogAndTheFittedInstance) {
  const std::filesystem::path dir = scratch("collect");
  const std::string log = (dir / "logs" / "navigation.jsonl").string();
  const std::string instance = (dir / "navigation.json").string();
  const auto result = ontime({"collect", "--domain", "navigation", "--trials", "2", "--threads", "2", "--seed", "4",
                              "--log", log, "-o", instance, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["attempts"].get<int>(), 30);
  EXPECT_EQ(out["deadline"].get<int>(), 22);
  EXPECT_EQ(out["effort"], "checks");
  EXPECT_EQ(out["actions"].size(), 15u);
  const std::string lines = read_file(log);
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 30);
  const auto solved = ontime({"solve", instance, "--json"});
  EXPECT_EQ(solved.exit_code, 0) << solved.err;
  // Fitting the written log again gives the same instance.
  const std::string refit = (dir / "refit.json").string();
  ASSERT_EQ(ontime({"fit", log, "--step", "3", "--deadline", "22", "--skeletons",
                    testing::source_path("data/domains/navigation.json").string(), "-o", refit, "--name", "navigation"})
                .exit_code,
            0);
  EXPECT_EQ(json::parse(read_file(refit))["actions"], json::parse(read_file(instance))["actions"]);
}

TEST(Cli, CollectRejectsBadDomainsAndWorlds) {
  const std::filesystem::path dir = scratch("bad-world");
  const auto unknown = ontime({"collect", "--domain", "kitchen", "--trials", "1"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown domain 'kitchen'"), std::string::npos) << unknown.err;
  json world = json::parse(read_file(testing::source_path("data/domains/navigation.json")));
  world["doors"][3]["width"] = 0.5;
  const std::string bad = (dir / "world.json").string();
  std::ofstream(bad) << world.dump(1);
  const auto result = ontime({"collect", "--domain", "navigation", "--world", bad, "--trials", "1", "--log",
                              (dir / "l.jsonl").string(), "-o", (dir / "i.json").string()});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_NE(result.err.find(bad + ": doors[3].width: narrower than the robot"), std::string::npos) << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "l.jsonl"));
  EXPECT_EQ(ontime({"collect", "--domain", "navigation", "--effort", "minutes"}).exit_code, 2);
  // An output that cannot be written stops the command before any planning.
  std::ofstream(dir / "file") << "x";
  const auto unwritable = ontime({"collect", "--domain", "navigation", "--trials", "1", "--log",
                                  (dir / "file" / "l.jsonl").string(), "-o", (dir / "i.json").string()});
  EXPECT_EQ(unwritable.exit_code, 2);
  EXPECT_NE(unwritable.err.find("cannot write into"), std::string::npos) << unwritable.err;
}

// SIGINT in the middle of a collection leaves no output and a checkpoint; --resume finishes it
// with the very files an uninterrupted run writes.
TEST(Cli, AnInterruptedCollectionResumesToTheSameFiles) {
  const std::filesystem::path dir = scratch("resume");
  const std::string world = (dir / "mini.json").string();
  std::ofstream(world) << testing::kMiniWorld;
  const auto collect = [&](const std::string& name, const std::vector<std::string>& extra) {
    std::vector<std::string> arguments{ONTIME_CLI, "collect",
                                       "--domain", "navigation",
                                       "--world",  world,
                                       "--trials", "300",
                                       "--seed",   "8",
                                       "--log",    (dir / (name + ".jsonl")).string(),
                                       "-o",       (dir / (name + ".json")).string()};
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    return arguments;
  };
  ASSERT_EQ(testing::run_process(collect("whole", {})).exit_code, 0);
  const std::filesystem::path checkpoint = dir / "cut.jsonl.checkpoint";
  const auto interrupted = testing::run_process(collect("cut", {"--threads", "2"}), [&] {
    const std::string text = read_file(checkpoint);
    return std::count(text.begin(), text.end(), '\n') >= 20;
  });
  ASSERT_EQ(interrupted.exit_code, 128 + SIGINT) << interrupted.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "cut.jsonl"));
  EXPECT_FALSE(std::filesystem::exists(dir / "cut.json"));
  const std::size_t saved = line_count(checkpoint);
  EXPECT_GE(saved, 20u);
  EXPECT_LT(saved, 601u);  // the settings line and at most 600 trials: the run was cut short
  // Without --resume the checkpoint is not thrown away.
  const auto refused = testing::run_process(collect("cut", {}));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("--resume"), std::string::npos) << refused.err;
  EXPECT_EQ(line_count(checkpoint), saved);
  // Another cut-off is another collection: refused, naming the setting.
  const auto other = testing::run_process(collect("cut", {"--resume", "--budget", "5"}));
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("line 1: the checkpoint of another collection ('budget_steps'"), std::string::npos)
      << other.err;
  const auto resumed = testing::run_process(collect("cut", {"--resume", "--threads", "1", "--json"}));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(json::parse(resumed.out)["resumed_attempts"].get<std::size_t>(), saved - 1);
  EXPECT_EQ(read_file(dir / "cut.jsonl"), read_file(dir / "whole.jsonl"));
  EXPECT_EQ(read_file(dir / "cut.json"), read_file(dir / "whole.json"));
  EXPECT_FALSE(std::filesystem::exists(checkpoint));
}

TEST(Cli, CollectRunsTheManipulationDomain) {
  const std::filesystem::path dir = scratch("collect-kitchen");
  const auto result = ontime({"collect", "--domain", "manipulation", "--trials", "1", "--budget", "1", "--log",
                              (dir / "m.jsonl").string(), "-o", (dir / "m.json").string(), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["attempts"].get<int>(), 36);
  EXPECT_EQ(out["deadline"].get<int>(), 40);
  const json instance = json::parse(read_file(dir / "m.json"));
  EXPECT_EQ(instance["skeletons"].size(), 8u);
  EXPECT_EQ(instance["actions"].size(), 36u);
  EXPECT_EQ(instance["skeletons"][7].size(), 12u);
}

TEST(Cli, MapDrawsTheWorldAndOneMotionPerSkeleton) {
  const std::filesystem::path dir = scratch("map");
  const std::string png = (dir / "map.png").string();
  const auto result = ontime({"map", "--domain", "navigation", "-o", png});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const json drawing = json::parse(read_file(dir / "map.json"));
  EXPECT_EQ(drawing["paths"].size(), 4u);
  EXPECT_GT(drawing["polygons"].size(), 13u);
}

// Without output options, collect writes into the current directory's data/, and run takes its
// model from there once it exists, else the instance that comes with ontime.
TEST(Cli, CollectWritesWhereRunLooksForItsModel) {
  const std::filesystem::path dir = scratch("defaults");
  const std::string world = (dir / "mini.json").string();
  std::ofstream(world) << testing::kMiniWorld;
  const auto in_dir = [&](std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), {"/usr/bin/env", "-C", dir.string(), ONTIME_CLI});
    return testing::run_process(arguments);
  };
  const std::vector<std::string> run{"run",        "--domain", "navigation", "--solver", "dp",
                                     "--episodes", "1",        "--threads",  "1",        "--json"};
  const auto before = in_dir(run);
  ASSERT_EQ(before.exit_code, 0) << before.err;
  EXPECT_EQ(std::filesystem::path(json::parse(before.out)["instance"].get<std::string>()),
            testing::source_path("data/instances/navigation.json"));

  const auto collected = in_dir({"collect", "--domain", "navigation", "--world", world, "--trials", "2", "--json"});
  ASSERT_EQ(collected.exit_code, 0) << collected.err;
  const json out = json::parse(collected.out);
  EXPECT_EQ(out["log"], "data/logs/navigation.jsonl");
  EXPECT_EQ(out["instance"], "data/instances/navigation.json");
  EXPECT_EQ(line_count(dir / "data" / "logs" / "navigation.jsonl"), out["attempts"].get<std::size_t>());
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "data" / "instances" / "navigation.json"));

  std::vector<std::string> on_collected = run;
  on_collected.insert(on_collected.end(), {"--world", world});
  const auto after = in_dir(on_collected);
  ASSERT_EQ(after.exit_code, 0) << after.err;
  EXPECT_EQ(json::parse(after.out)["instance"], "data/instances/navigation.json");
}

TEST(Cli, HelpIsAvailableForEveryCommand) {
  for (const char* command : {"collect", "map", "run"}) {
    const auto result = ontime({command, "--help"});
    EXPECT_EQ(result.exit_code, 0) << command;
    EXPECT_NE(result.out.find("--domain"), std::string::npos) << command;
  }
  for (const char* command : {"fit", "sample-log", "plot"}) {
    const auto result = ontime({command, "--help"});
    EXPECT_EQ(result.exit_code, 0) << command;
    EXPECT_NE(result.out.find("--output"), std::string::npos) << command;
  }
  for (const char* command : {"solve", "evaluate", "table", "train", "reduce-knapsack", "study", "allocators"}) {
    const auto result = ontime({command, "--help"});
    EXPECT_EQ(result.exit_code, 0) << command;
    EXPECT_NE(result.out.find("--help"), std::string::npos) << command;
  }
  EXPECT_EQ(ontime({"--help"}).exit_code, 0);
  EXPECT_EQ(ontime({"--version"}).exit_code, 0);
}

// A one-line message on stderr that names `option`, quotes `written` and prints no run of more
// than 25 digits (numbers are written compactly, never as 309 digits).
void expect_one_line_naming(const testing::ProcessResult& result, const std::string& option,
                            const std::string& written) {
  EXPECT_EQ(result.exit_code, 2) << option << " " << written << ": " << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_NE(result.err.find(option), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("'" + written + "'"), std::string::npos) << result.err;
  std::size_t digits = 0;
  for (const char c : result.err) {
    digits = std::isdigit(static_cast<unsigned char>(c)) != 0 ? digits + 1 : 0;
    EXPECT_LE(digits, 25U) << result.err;
  }
}

TEST(Cli, OutOfRangeNumbersAreRefusedWithTheValueAsWritten) {
  const std::string figure1 = paper("figure1");
  const std::vector<std::string> evaluate{"evaluate", figure1, "--solver", "mcts", "--episodes", "5"};
  struct Case {
    std::vector<std::string> arguments;  // appended to their command
    std::string option;
    std::string written;
  };
  const std::vector<std::pair<std::vector<std::string>, std::vector<Case>>> commands{
      {evaluate,
       {{{"--seed", "-1"}, "--seed", "-1"},
        {{"--seed", "18446744073709551616"}, "--seed", "18446744073709551616"},
        {{"--seed", "-18446744073709551615"}, "--seed", "-18446744073709551615"},
        {{"--seed", "1.5"}, "--seed", "1.5"},
        {{"--seed", "0x10"}, "--seed", "0x10"},
        {{"--threads", "100000"}, "--threads", "100000"},
        {{"--threads", "-1"}, "--threads", "-1"},
        {{"--time-budget", "nan"}, "--time-budget", "nan"},
        {{"--time-budget", "1e400"}, "--time-budget", "1e400"}}},
      {{"evaluate", figure1, "--solver", "dp"},
       {{{"--episodes", "0"}, "--episodes", "0"}, {{"--episodes", "1e400"}, "--episodes", "1e400"}}},
      {{"solve", figure1},
       {{{"--max-states", "18446744073709551616"}, "--max-states", "18446744073709551616"},
        {{"--max-states", "1e400"}, "--max-states", "1e400"},
        {{"--max-states", "0"}, "--max-states", "0"}}},
      {{"table", figure1, "--solvers", "dp"}, {{{"--threads", "4294967296"}, "--threads", "4294967296"}}},
      {{"sample-log", figure1, "-o", "unused.jsonl"},
       {{{"--attempts", "-5"}, "--attempts", "-5"},
        {{"--cutoff", "2147483648"}, "--cutoff", "2147483648"},
        {{"--seed", "inf"}, "--seed", "inf"}}},
      {{"fit", "unused.jsonl", "--skeletons", figure1, "-o", "unused.json"},
       {{{"--step", "nan", "--deadline", "5"}, "--step", "nan"},
        {{"--step", "0", "--deadline", "5"}, "--step", "0"},
        {{"--step", "1", "--deadline", "1e400"}, "--deadline", "1e400"},
        {{"--step", "1", "--deadline", "5", "--laplace", "-1"}, "--laplace", "-1"}}},
      {{"study", "anytime", figure1},
       {{{"--seed", "-1"}, "--seed", "-1"}, {{"--threads", "2000"}, "--threads", "2000"}}},
      {{"train", figure1, "--out", "unused.json"}, {{{"--episodes", "-3"}, "--episodes", "-3"}}},
      {{"collect", "--domain", "navigation"},
       {{{"--trials", "0"}, "--trials", "0"},
        {{"--step", "nan"}, "--step", "nan"},
        {{"--deadline", "10001"}, "--deadline", "10001"},
        {{"--checks-per-second", "-inf"}, "--checks-per-second", "-inf"}}},
      {{"map", "--domain", "navigation"}, {{{"--seed", "18446744073709551616"}, "--seed", "18446744073709551616"}}},
      {{"run", "--domain", "navigation", "--solver", "dp"},
       {{{"--episodes", "-1"}, "--episodes", "-1"}, {{"--threads", "100000"}, "--threads", "100000"}}},
  };
  for (const auto& [command, cases] : commands) {
    for (const Case& bad : cases) {
      std::vector<std::string> arguments = command;
      arguments.insert(arguments.end(), bad.arguments.begin(), bad.arguments.end());
      SCOPED_TRACE(command.front() + " " + bad.option + " " + bad.written);
      expect_one_line_naming(ontime(arguments), bad.option, bad.written);
    }
  }
  // The extremes of the range are accepted and run as written.
  std::vector<std::string> largest = evaluate;
  largest.insert(largest.end(), {"--seed", "18446744073709551615", "--json"});
  const auto accepted = ontime(largest);
  ASSERT_EQ(accepted.exit_code, 0) << accepted.err;
  EXPECT_EQ(json::parse(accepted.out)["seed"].get<std::uint64_t>(), 18446744073709551615ULL);
  // A leading zero is decimal, not octal.
  std::vector<std::string> padded = evaluate;
  padded.insert(padded.end(), {"--seed", "010", "--json"});
  EXPECT_EQ(json::parse(ontime(padded).out)["seed"].get<std::uint64_t>(), 10U);
}

TEST(Cli, TableRefusesEmptyAndRepeatedColumnsAndRepeatedInstances) {
  const std::string figure1 = paper("figure1");
  const auto empty = ontime({"table", figure1, "--episodes", "5", "--solvers", "dp,,greedy"});
  EXPECT_EQ(empty.exit_code, 2);
  EXPECT_NE(empty.err.find("--solvers: name 2 is empty"), std::string::npos) << empty.err;
  EXPECT_EQ(ontime({"table", figure1, "--episodes", "5", "--solvers", "dp,"}).exit_code, 2);
  EXPECT_EQ(ontime({"table", figure1, "--episodes", "5", "--solvers", ""}).exit_code, 2);
  const auto repeated = ontime({"table", figure1, "--episodes", "5", "--solvers", "dp,greedy,dp"});
  EXPECT_EQ(repeated.exit_code, 2);
  EXPECT_NE(repeated.err.find("--solvers: 'dp' is given twice"), std::string::npos) << repeated.err;
  // The same file under another name is the same instance.
  const std::string other_name = (std::filesystem::path(figure1).parent_path() / "." / "figure1.json").string();
  const auto twice = ontime({"table", figure1, other_name, "--episodes", "5", "--solvers", "dp"});
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_NE(twice.err.find("instance given twice (as argument 1 and 2)"), std::string::npos) << twice.err;
  EXPECT_EQ(ontime({"table", figure1, paper("instance1"), "--episodes", "5", "--solvers", "dp,greedy"}).exit_code, 0);
}

TEST(Cli, UsageErrorsTakeOneLine) {
  for (const std::vector<std::string>& arguments :
       {std::vector<std::string>{}, {"frobnicate"}, {"solve"}, {"evaluate", paper("figure1"), "--no-such-option"}}) {
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2);
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_EQ(result.err.rfind("ontime: usage error: ", 0), 0U) << result.err;
  }
}

// "Whichever ends first": a time budget so large that its deadline is out of the clock's range
// leaves the iteration limit in charge (it must not end every search at once).
TEST(Cli, AHugeTimeBudgetLeavesTheIterationLimitInCharge) {
  const Problem problem = testing::paper_instance("instance3");
  const Mdp mdp(problem);
  for (const char* seconds : {"1e10", "1e308"}) {
    const AllocatorFactory factory =
        make_allocator_factory("mcts", mdp, {{"iterations", "1000"}, {"time-budget", seconds}});
    MonteCarloOptions monte_carlo;
    monte_carlo.episodes = 20;
    monte_carlo.threads = 1;
    const MonteCarloResult result = run_monte_carlo(mdp, factory, monte_carlo);
    const double searches = result.statistics.find("searches").value_or(0.0);
    EXPECT_GT(searches, 0.0) << seconds;
    EXPECT_EQ(result.statistics.find("iterations").value_or(0.0), searches * 1000) << seconds;
  }
}

TEST(Cli, AnInstanceDeadlineBeyondItsTypeIsQuotedAsWritten) {
  const auto directory = scratch("huge_deadline");
  const std::string path = (directory / "instance.json").string();
  std::ofstream(path) << R"({"name": "x", "deadline": 18446744073709551615})";
  const auto result = ontime({"solve", path});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("deadline: must be between 1 and 10000 steps (got 18446744073709551615)"),
            std::string::npos)
      << result.err;
}

// A cap the memory cannot hold would end in "out of memory" instead of the cap's clean stop.
TEST(Cli, CapsBeyondTheAvailableMemoryAreRefusedBeforeStarting) {
  const auto states = ontime({"solve", paper("figure1"), "--max-states", "18446744073709551615"});
  EXPECT_EQ(states.exit_code, 2);
  EXPECT_NE(states.err.find("--max-states 18446744073709551615: would need up to"), std::string::npos) << states.err;
  const auto tree = ontime({"evaluate", paper("figure1"), "--solver", "mcts", "--max-tree-mib", "16777216",
                            "--episodes", "5", "--threads", "1"});
  EXPECT_EQ(tree.exit_code, 2);
  EXPECT_NE(tree.err.find("--max-tree-mib 16777216 with 1 thread: would need up to 1.64e+04 GiB"), std::string::npos)
      << tree.err;
  const auto table = ontime({"table", paper("figure1"), "--solvers", "mcts", "--max-tree-mib", "16777216", "--episodes",
                             "5", "--threads", "1"});
  EXPECT_EQ(table.exit_code, 2);
  EXPECT_EQ(ontime({"solve", paper("figure1"), "--max-states", "1000"}).exit_code, 0);
}

}  // namespace
}  // namespace ontime
