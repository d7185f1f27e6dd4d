#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/ppo.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "support/bad_inputs.hpp"
#include "support/bad_logs.hpp"
#include "support/bad_ompl_logs.hpp"
#include "support/mini_world.hpp"
#include "support/paper.hpp"
#include "support/process.hpp"
#include "support/random_instances.hpp"

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

// Without the measured times, the output depends only on the inputs: the same bytes for any
// thread count, with the successes of a timed run.
TEST(Cli, EvaluateWithoutTimingPrintsTheSameBytesForAnyThreadCount) {
  const std::vector<std::string> command{"evaluate", paper("instance3"), "--solver", "mcts",   "--iterations",
                                         "100",      "--episodes",       "300",      "--seed", "5",
                                         "--json",   "--no-timing"};
  auto with_threads = [&](const char* threads) {
    std::vector<std::string> arguments = command;
    arguments.insert(arguments.end(), {"--threads", threads});
    return ontime(arguments);
  };
  const auto one = with_threads("1");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_EQ(with_threads("3").out, one.out);
  const json out = json::parse(one.out);
  EXPECT_FALSE(out.contains("decision_time_us"));
  EXPECT_FALSE(out.contains("seconds"));
  std::vector<std::string> timed(command.begin(), command.end() - 1);
  const auto with_timing = ontime(timed);
  ASSERT_EQ(with_timing.exit_code, 0) << with_timing.err;
  EXPECT_EQ(json::parse(with_timing.out)["successes"], out["successes"]);
  EXPECT_TRUE(json::parse(with_timing.out).contains("decision_time_us"));
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
  const auto capped = ontime({"solve", paper("instance1"), "--max-states", "20", "--method", "memoised"});
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

// An instance of 300 skeletons: sampled evaluation by the approximate allocators, and a one-line
// refusal naming the file and the limit from everything exact, before any work.
TEST(Cli, ThreeHundredSkeletonsAreEvaluatedAndRefusedByTheExactSolver) {
  const auto directory = scratch("wide");
  const std::string path = (directory / "wide.json").string();
  save_problem(testing::wide_instance(8, 300, 4, 80), path);
  for (const char* solver : {"dp-rerun", "thompson", "greedy"}) {
    const auto result =
        ontime({"evaluate", path, "--solver", solver, "--episodes", "400", "--seed", "2", "--threads", "2", "--json"});
    ASSERT_EQ(result.exit_code, 0) << solver << ": " << result.err;
    const json out = json::parse(result.out);
    EXPECT_EQ(out["episodes"], 400) << solver;
    EXPECT_GT(out["success_rate"].get<double>(), 0.0) << solver;
    EXPECT_FALSE(out.contains("exact_success_probability")) << solver;
  }
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"solve", path},
        std::vector<std::string>{"evaluate", path, "--solver", "dp", "--exact"},
        std::vector<std::string>{"table", path, "--solvers", "dp-rerun,optimal", "--episodes", "10"}}) {
    const auto result = ontime(command);
    EXPECT_EQ(result.exit_code, 2) << command[0] << ": " << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_NE(result.err.find(path + ": skeletons: 300 skeletons; exact solving and exact evaluation take at most 16"),
              std::string::npos)
        << result.err;
    EXPECT_TRUE(result.out.empty()) << result.out;
  }
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

// glibc picks one of several builds of exp, log and pow by the CPU's features (FMA, AVX2), and
// they differ in some last bits; GLIBC_TUNABLES masks features as a CPU without them would.
// Training must give the same policy file under every pick.
TEST(Cli, TrainingGivesTheSameBytesWhicheverLibmGlibcPicks) {
  const auto directory = scratch("libm");
  std::vector<std::string> policies;
  for (const char* tunables : {"glibc.cpu.hwcaps=", "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX",
                               "glibc.cpu.hwcaps=-AVX512F,-AVX2,-FMA,-AVX,-SSE4_1,-SSE4_2"}) {
    const auto policy = directory / ("policy" + std::to_string(policies.size()) + ".json");
    const auto trained = testing::run_process({"/usr/bin/env", std::string("GLIBC_TUNABLES=") + tunables, ONTIME_CLI,
                                               "train", paper("instance2"), "--episodes", "1500", "--seed", "3",
                                               "--out", policy.string(), "--no-plot"});
    ASSERT_EQ(trained.exit_code, 0) << tunables << ": " << trained.err;
    std::ifstream in(policy, std::ios::binary);
    policies.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    ASSERT_GT(policies.back().size(), 1000U);
  }
  EXPECT_TRUE(policies[1] == policies[0]);
  EXPECT_TRUE(policies[2] == policies[0]);
}

// Standard error is not a terminal here (a pipe, as in a log or CI): progress comes as plain
// lines, here one per update (ONTIME_PROGRESS_SECONDS=0), and --quiet silences them.
TEST(Cli, ProgressLinesInALogAndNoneWhenQuiet) {
  const auto directory = scratch("progress");
  const std::string policy = (directory / "policy.json").string();
  const std::vector<std::string> train = {ONTIME_CLI, "train", paper("instance4"), "--episodes", "3000",
                                          "--out",    policy,  "--no-plot"};
  std::vector<std::string> logged = {"/usr/bin/env", "ONTIME_PROGRESS_SECONDS=0"};
  logged.insert(logged.end(), train.begin(), train.end());
  const auto result = testing::run_process(logged);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::regex line(R"(ontime train ppo: (\d+)/3000 \((\d+)%\), \d+s elapsed, about \d+s left)");
  std::istringstream err(result.err);
  std::vector<std::uint64_t> done;
  for (std::string text; std::getline(err, text);) {
    std::smatch match;
    ASSERT_TRUE(std::regex_match(text, match, line)) << text;
    done.push_back(std::stoull(match[1]));
    EXPECT_EQ(std::stoull(match[2]), done.back() * 100 / 3000);
  }
  // One line per epoch of at least 4,000 steps (instance 4's episodes are one or two steps long).
  ASSERT_GE(done.size(), 2U);
  EXPECT_TRUE(std::is_sorted(done.begin(), done.end()));
  EXPECT_EQ(done.back(), 3000U);

  logged.push_back("--quiet");
  const auto quiet = testing::run_process(logged);
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");

  const auto bad = testing::run_process({"/usr/bin/env", "ONTIME_PROGRESS_SECONDS=soon", ONTIME_CLI, "train",
                                         paper("instance4"), "--episodes", "30", "--out", policy, "--no-plot"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("ONTIME_PROGRESS_SECONDS: must be a number of seconds"), std::string::npos) << bad.err;
}

// A solve stopped by SIGINT, SIGTERM or SIGHUP removes its scratch, says so in one line and dies
// of the signal; after SIGKILL (nothing can run), the next solve over the folder removes what was
// left and says so.
TEST(Cli, AStoppedOrKilledSolveLeavesNoScratchBehind) {
  const auto folder = scratch("solve-scratch");
  const std::string navigation = std::string(ONTIME_SOURCE_DIR) + "/data/instances/navigation.json";
  const std::vector<std::string> solve = {ONTIME_CLI, "solve", navigation, "--scratch", folder.string(), "--quiet"};
  const auto layer_files_written = [&folder] {
    std::error_code error;
    for (const auto& directory : std::filesystem::directory_iterator(folder, error)) {
      for ([[maybe_unused]] const auto& file : std::filesystem::directory_iterator(directory.path(), error))
        return true;
    }
    return false;
  };
  const auto entries = [&folder] {
    std::vector<std::filesystem::path> found;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) found.push_back(entry.path());
    return found;
  };
  for (const auto& [signal_number, name] : {std::pair{SIGTERM, "SIGTERM"}, {SIGINT, "SIGINT"}, {SIGHUP, "SIGHUP"}}) {
    const auto stopped = testing::run_process(solve, layer_files_written, signal_number);
    EXPECT_EQ(stopped.exit_code, 128 + signal_number) << stopped.err;
    const std::regex line("ontime: " + std::string(name) + ": stopped; removed the scratch directory " +
                          folder.string() + "/ontime-layers-[^/\\n]+-rank0-[^/\\n]{6}\n");
    EXPECT_TRUE(std::regex_match(stopped.err, line)) << stopped.err;
    EXPECT_TRUE(entries().empty()) << name;
  }
  const auto killed = testing::run_process(solve, layer_files_written, SIGKILL);
  EXPECT_EQ(killed.exit_code, 128 + SIGKILL);
  const auto left = entries();
  ASSERT_EQ(left.size(), 1U);
  const auto next = ontime({"solve", paper("instance1"), "--scratch", folder.string()});
  ASSERT_EQ(next.exit_code, 0) << next.err;
  EXPECT_NE(next.err.find("ontime: removed " + left[0].string() + " ("), std::string::npos) << next.err;
  EXPECT_NE(next.err.find("the scratch of a run on this host whose process is gone"), std::string::npos) << next.err;
  EXPECT_TRUE(entries().empty());
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
  EXPECT_NE(text.out.find("(0.9340)"), std::string::npos) << text.out;       // dp: 48 states
  EXPECT_NE(text.out.find("(cap reached)"), std::string::npos) << text.out;  // round-robin: 143
  // The optimum (872 states) past the cap: the whole tree's interval after 49 states (5 layers),
  // then a split's (skeletons 1-3 enumerated, 58 states), the tighter end of each.
  EXPECT_NE(text.out.find("optimum over 107 states (certified interval)"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("[0.9360, 0.9939]"), std::string::npos) << text.out;
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
  EXPECT_LE(row["optimum"]["lower_bound"].get<double>(), 0.942);
  EXPECT_GE(row["optimum"]["upper_bound"].get<double>(), 0.942);
  // An exact cell above the layered lower bound (dp-rerun, 0.9400 > 0.9360) raises it: every
  // policy's exact value is at most the optimum.
  const auto raised = ontime(
      {"table", paper("instance1"), "--solvers", "dp,dp-rerun", "--episodes", "200", "--exact", "--max-states", "100"});
  ASSERT_EQ(raised.exit_code, 0) << raised.err;
  EXPECT_NE(raised.out.find("[0.9400, 0.9939]"), std::string::npos) << raised.out;
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

// The OMPL benchmark log of a collection fits (speed 1, planners named by their actions) the same
// instance as the collection.
TEST(Cli, CollectWritesAnOmplBenchmarkLogThatFitsTheSameInstance) {
  const std::filesystem::path dir = scratch("collect-ompl");
  const std::string log = (dir / "navigation.log").string();
  const std::string instance = (dir / "navigation.json").string();
  const auto result = ontime({"collect", "--domain", "navigation", "--trials", "2", "--threads", "2", "--seed", "4",
                              "--log", log, "--log-format", "ompl-benchmark", "-o", instance, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string text = read_file(log);
  EXPECT_EQ(text.substr(0, text.find('\n')), "Experiment navigation");
  EXPECT_NE(text.find("\n66 seconds per run\n"), std::string::npos) << text;  // 22 steps of 3 s
  EXPECT_NE(text.find("\n15 planners\n"), std::string::npos);
  const std::string refit = (dir / "refit.json").string();
  const auto fit = ontime({"fit", "--format", "ompl-benchmark", log, "--speed", "1", "--step", "3", "--deadline", "22",
                           "--skeletons", testing::source_path("data/domains/navigation.json").string(), "-o", refit,
                           "--name", "navigation", "--json"});
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_EQ(json::parse(fit.out)["records"].get<int>(), 30);
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

TEST(Cli, GenerateWorldWritesTheSameBuildingForTheSameSeed) {
  const std::filesystem::path dir = scratch("generate-world");
  const std::string first = (dir / "first.json").string();
  const auto result = ontime({"generate-world", "--seed", "1", "-o", first});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("30 rooms, 39 doors"), std::string::npos) << result.out;
  // The committed building is seed 1 with the defaults.
  EXPECT_EQ(read_file(first), read_file(testing::source_path("data/domains/building-6x5.json")));
  const std::string other = (dir / "other.json").string();
  ASSERT_EQ(ontime({"generate-world", "--rows", "3", "--cols", "4", "--room-size", "5", "--door-density", "1", "--seed",
                    "2", "-o", other})
                .exit_code,
            0);
  const json world = json::parse(read_file(other));
  EXPECT_EQ(world["name"], "building-3x4");
  EXPECT_EQ(world["rooms"].size(), 12u);
  EXPECT_EQ(world["doors"].size(), 17u);  // every neighbour pair: 3 x 3 + 2 x 4
  EXPECT_FALSE(world.contains("skeletons"));
  EXPECT_EQ(world["rooms"]["R12"]["max"], json::array({20, 15}));
  // Bad options: exit 2, one line, nothing written.
  const std::string never = (dir / "never.json").string();
  for (const std::vector<std::string>& bad : std::vector<std::vector<std::string>>{
           {"--rows", "0"},
           {"--cols", "51"},
           {"--rows", "1", "--cols", "1"},
           {"--room-size", "2"},
           {"--door-density", "1.5"},
           {"--narrow-doors", "-0.1"},
           {"--seed", "-1"},
       }) {
    std::vector<std::string> arguments{"generate-world", "-o", never};
    arguments.insert(arguments.end(), bad.begin(), bad.end());
    const auto refused = ontime(arguments);
    EXPECT_EQ(refused.exit_code, 2) << bad[0];
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(never)) << bad[0];
  }
  EXPECT_EQ(ontime({"generate-world"}).exit_code, 2);  // -o is required
  const auto missing = ontime({"generate-world", "-o", (dir / "no" / "such" / "folder.json").string()});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
}

TEST(Cli, MapDrawsAGeneratedBuildingWithoutSkeletons) {
  const std::filesystem::path dir = scratch("map-building");
  const std::string png = (dir / "building.png").string();
  const auto result = ontime({"map", "--domain", "navigation", "--world",
                              testing::source_path("data/domains/building-6x5.json").string(), "-o", png});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const json drawing = json::parse(read_file(dir / "building.json"));
  EXPECT_EQ(drawing["paths"].size(), 0u);
  std::size_t rooms = 0;
  for (const json& polygon : drawing["polygons"]) rooms += polygon["kind"] == "room" ? 1 : 0;
  EXPECT_EQ(rooms, 30u);
}

// --every-action refines every doorway move in both directions, whatever the skeletons, and
// fits an instance with one skeleton per move.
TEST(Cli, CollectEveryActionCoversEveryDirectedDoor) {
  const std::filesystem::path dir = scratch("collect-every-action");
  const std::string world_file = (dir / "small.json").string();
  ASSERT_EQ(ontime({"generate-world", "--rows", "2", "--cols", "2", "--seed", "3", "-o", world_file}).exit_code, 0);
  const std::size_t doors = json::parse(read_file(world_file))["doors"].size();
  const std::string log = (dir / "small.jsonl").string();
  const std::string instance = (dir / "small-moves.json").string();
  const auto result = ontime({"collect", "--domain", "navigation", "--world", world_file, "--every-action", "--trials",
                              "2", "--threads", "2", "--log", log, "-o", instance, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["attempts"].get<std::size_t>(), 2 * 2 * doors);
  EXPECT_TRUE(out["every_action"].get<bool>());
  const json fitted = json::parse(read_file(instance));
  ASSERT_EQ(fitted["skeletons"].size(), 2 * doors);
  std::set<std::string> moves;
  for (const json& skeleton : fitted["skeletons"]) {
    ASSERT_EQ(skeleton.size(), 1u);
    moves.insert(skeleton[0].get<std::string>());
  }
  const json world = json::parse(read_file(world_file));  // kept: the loop reads inside it
  for (const json& door : world["doors"]) {
    const std::string a = door["rooms"][0], b = door["rooms"][1];
    EXPECT_EQ(moves.count("move(" + a + "," + b + ")"), 1u);
    EXPECT_EQ(moves.count("move(" + b + "," + a + ")"), 1u);
  }
  // fit --library gives the collection's instance back.
  const std::string refit = (dir / "refit.json").string();
  ASSERT_EQ(ontime({"fit", log, "--step", "3", "--deadline", "22", "--library", "-o", refit, "--name", "navigation"})
                .exit_code,
            0);
  EXPECT_EQ(json::parse(read_file(refit))["actions"], fitted["actions"]);
  EXPECT_EQ(json::parse(read_file(refit))["skeletons"], fitted["skeletons"]);
  // Without skeletons and without --every-action there is nothing to collect.
  const auto nothing = ontime({"collect", "--domain", "navigation", "--world", world_file, "--trials", "1", "--log",
                               (dir / "n.jsonl").string(), "-o", (dir / "n.json").string()});
  EXPECT_EQ(nothing.exit_code, 2);
  EXPECT_EQ(std::count(nothing.err.begin(), nothing.err.end(), '\n'), 1) << nothing.err;
  EXPECT_NE(nothing.err.find("has no skeletons"), std::string::npos) << nothing.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "n.jsonl.checkpoint"));
  // A domain that cannot list its actions refuses --every-action.
  const auto kitchen = ontime({"collect", "--domain", "manipulation", "--every-action", "--trials", "1", "--log",
                               (dir / "k.jsonl").string(), "-o", (dir / "k.json").string()});
  EXPECT_EQ(kitchen.exit_code, 2);
  EXPECT_NE(kitchen.err.find("cannot list every action"), std::string::npos) << kitchen.err;
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

// The whole TAMP loop: skeletons streamed by the room-path planner, refined by the real planner,
// every search charged; its picture's data; bad deadlines and libraries refused before any work.
TEST(Cli, TampStreamsSkeletonsIntoLiveEpisodes) {
  const std::filesystem::path dir = scratch("tamp");
  const std::string world = testing::source_path("data/domains/navigation.json").string();
  const std::string library = testing::source_path("data/instances/navigation.json").string();
  const auto result = ontime({"tamp",
                              "--world",
                              world,
                              "--library",
                              library,
                              "--deadline",
                              "45",
                              "--solver",
                              "dp-rerun",
                              "--episodes",
                              "6",
                              "--threads",
                              "1",
                              "--max-skeletons",
                              "3",
                              "--task-seconds",
                              "0.5",
                              "--json",
                              "--picture",
                              (dir / "episode.png").string(),
                              "--picture-episode",
                              "1",
                              "--no-plot"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["deadline_steps"].get<int>(), 15);
  ASSERT_EQ(out["episode_results"].size(), 6u);
  std::uint64_t successes = 0;
  for (const json& episode : out["episode_results"]) {
    successes += episode["status"] == "success" ? 1 : 0;
    const int found = episode["skeletons_found"].get<int>();
    EXPECT_GE(found, 1);
    EXPECT_LE(found, 3);
    // Every skeleton found was charged its half second of search.
    EXPECT_GE(episode["outside_seconds"].get<double>(), 0.5 * found - 1e-9);
    EXPECT_LE(episode["elapsed_seconds"].get<double>(), 45.0 + 1e-6);
  }
  EXPECT_EQ(out["successes"].get<std::uint64_t>(), successes);
  const json drawing = json::parse(read_file(dir / "episode.json"));
  EXPECT_FALSE(drawing["skeletons"].empty());
  for (const json& skeleton : drawing["skeletons"]) EXPECT_GE(skeleton["points"].size(), 3u);
  EXPECT_TRUE(std::filesystem::exists(dir / "episode-timeline.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "episode.png"));

  const auto too_short = ontime({"tamp", "--world", world, "--library", library, "--deadline", "2", "--solver", "dp"});
  EXPECT_EQ(too_short.exit_code, 2);
  EXPECT_NE(too_short.err.find("--deadline 2"), std::string::npos) << too_short.err;
  // A library without the moves of the room paths: named, with the action missing.
  const auto missing =
      ontime({"tamp", "--world", world, "--library", paper("instance1"), "--deadline", "45", "--solver", "dp"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("instance1.json: actions: no action 'move(R1,"), std::string::npos) << missing.err;
}

// A building whose goal room has no door: every command that reads the world refuses it with
// the rule, before any work, and no library's raw warning reaches standard error.
TEST(Cli, AWorldWhoseGoalCannotBeReachedIsRefused) {
  const std::filesystem::path dir = scratch("unreachable");
  json building = json::parse(read_file(testing::source_path("data/domains/building-6x5.json")));
  json doors = json::array();
  for (const json& door : building["doors"]) {
    if (door["rooms"][0] != "R30" && door["rooms"][1] != "R30") doors.push_back(door);
  }
  ASSERT_LT(doors.size(), building["doors"].size());
  building["doors"] = doors;
  const std::string world = (dir / "walled-in.json").string();
  std::ofstream(world) << building.dump(2);
  const std::string library = testing::source_path("data/instances/building-6x5-moves.json").string();
  const std::string expected = world + ": goal_room: R30 cannot be reached from the start room R1";
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"tamp", "--world", world, "--library", library, "--deadline", "60", "--solver",
                                 "dp-rerun", "--episodes", "2"},
        std::vector<std::string>{"collect", "--domain", "navigation", "--world", world, "--every-action", "--trials",
                                 "2", "--log", (dir / "log.jsonl").string(), "-o", (dir / "instance.json").string()},
        std::vector<std::string>{"map", "--domain", "navigation", "--world", world, "-o",
                                 (dir / "map.png").string()}}) {
    const auto result = ontime(command);
    EXPECT_EQ(result.exit_code, 2) << command[0] << ": " << result.err;
    EXPECT_NE(result.err.find(expected), std::string::npos) << command[0] << ": " << result.err;
    EXPECT_EQ(result.err.find("Warning"), std::string::npos) << command[0] << ": " << result.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "log.jsonl"));
  EXPECT_FALSE(std::filesystem::exists(dir / "map.png"));
}

// With --clock model nothing real is on the clock: each decision is charged the model's seconds
// (here dp-rerun, which does not search: 10 us), the allocator's handling of an outcome nothing,
// and the episodes are the same, to every charge, for any thread count.
TEST(Cli, TampOnTheModelledClockReproducesToTheEpisode) {
  const std::string world = testing::source_path("data/domains/navigation.json").string();
  const std::string library = testing::source_path("data/instances/navigation.json").string();
  const auto run = [&](const std::string& threads, const std::string& solver) {
    std::vector<std::string> command = {"tamp",  "--world",         world,  "--library",  library, "--deadline",
                                        "45",    "--solver",        solver, "--episodes", "6",     "--threads",
                                        threads, "--max-skeletons", "3",    "--clock",    "model", "--json"};
    if (solver == "mcts") command.insert(command.end(), {"--iterations", "40"});
    const auto result = ontime(command);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    json out = json::parse(result.out);
    out.erase("seconds");  // the run's own duration
    return out;
  };
  const json one = run("1", "dp-rerun");
  EXPECT_EQ(one, run("2", "dp-rerun"));
  EXPECT_EQ(one["clock"], "model");
  std::size_t steps = 0;
  for (const json& episode : one["episode_results"]) {
    for (const json& step : episode["timeline"]) {
      EXPECT_NEAR(step["decision_seconds"].get<double>(), 1e-5, 1e-12);
      EXPECT_EQ(step["observe_seconds"].get<double>(), 0.0);
      ++steps;
    }
  }
  EXPECT_GT(steps, 6U);
  // A searching allocator: 10 us + 2 us for each of its 40 iterations when it searches (not
  // where one choice is all there is).
  const json searched = run("2", "mcts");
  EXPECT_EQ(searched, run("1", "mcts"));
  std::size_t searches = 0;
  for (const json& episode : searched["episode_results"]) {
    for (const json& step : episode["timeline"]) {
      const double seconds = step["decision_seconds"].get<double>();
      const bool searched_here = std::abs(seconds - (1e-5 + 40 * 2e-6)) < 1e-12;
      EXPECT_TRUE(searched_here || std::abs(seconds - 1e-5) < 1e-12) << seconds;
      searches += searched_here ? 1 : 0;
    }
  }
  EXPECT_GT(searches, 0U);

  const auto real_with_model_options = ontime({"tamp", "--world", world, "--library", library, "--deadline", "45",
                                               "--solver", "dp-rerun", "--decision-seconds", "0.001"});
  EXPECT_EQ(real_with_model_options.exit_code, 2);
  EXPECT_NE(real_with_model_options.err.find("need --clock model"), std::string::npos) << real_with_model_options.err;
  const auto wall = ontime({"tamp", "--world", world, "--library", library, "--deadline", "45", "--solver", "dp-rerun",
                            "--clock", "model", "--effort", "wall"});
  EXPECT_EQ(wall.exit_code, 2);
  EXPECT_NE(wall.err.find("--clock model needs --effort checks"), std::string::npos) << wall.err;
}

// Live episodes against the real planner: every episode's charges and timeline in the JSON, one
// episode's timeline as CSV; the live options need a live run.
TEST(Cli, RunLiveReportsEveryEpisodesChargesAndTimeline) {
  const std::filesystem::path dir = scratch("live");
  const auto result =
      ontime({"run", "--domain", "navigation", "--solver", "dp-rerun", "--live", "--episodes", "3", "--threads", "1",
              "--json", "--timeline", (dir / "timeline.png").string(), "--timeline-episode", "2", "--no-plot"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_TRUE(out["live"].get<bool>());
  EXPECT_EQ(out["effort"], "checks");
  ASSERT_EQ(out["episode_results"].size(), 3u);
  std::uint64_t successes = 0;
  for (const json& episode : out["episode_results"]) {
    successes += episode["status"] == "success" ? 1 : 0;
    ASSERT_FALSE(episode["timeline"].empty());
    double planning = 0;
    for (const json& step : episode["timeline"]) planning += step["planning_seconds"].get<double>();
    EXPECT_NEAR(episode["planning_seconds"].get<double>(), planning, 1e-9);
    // Planner calls count their nominal seconds: at least a little effort each.
    EXPECT_GT(planning, 0.0);
    EXPECT_LE(episode["elapsed_seconds"].get<double>(), 66.0 + 1e-6);
  }
  EXPECT_EQ(out["successes"].get<std::uint64_t>(), successes);
  EXPECT_LE(out["step_clock_successes"].get<std::uint64_t>() + out["step_clock_undecided"].get<std::uint64_t>(), 3u);
  EXPECT_EQ(line_count(dir / "timeline.csv"), out["episode_results"][2]["timeline"].size() + 1);
  EXPECT_FALSE(std::filesystem::exists(dir / "timeline.png"));

  const auto not_live = ontime({"run", "--domain", "navigation", "--solver", "dp", "--decision-share", "0.3"});
  EXPECT_EQ(not_live.exit_code, 2);
  EXPECT_NE(not_live.err.find("--decision-share needs live episodes"), std::string::npos) << not_live.err;
}

// Every file a command writes is checked before its work starts: a missing or unusable folder,
// a directory in the way and an output that is one of the inputs (by identity: a hard link or
// a symbolic link to it too) are usage errors, exit 2, one line naming the option and the path,
// and nothing is written.
class OutputPaths : public ::testing::Test {
 protected:
  void SetUp() override {
    // A folder per test: ctest runs the tests of this fixture in parallel.
    dir = scratch(std::string("outputs_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    instance = (dir / "instance.json").string();
    std::filesystem::copy_file(paper("figure1"), instance);
    log = (dir / "figure1.jsonl").string();
    ASSERT_EQ(ontime({"sample-log", instance, "--attempts", "10", "-o", log}).exit_code, 0);
    std::filesystem::create_directory(dir / "folder");
    std::ofstream(dir / "file") << "not a folder";
  }

  // Runs the command, which must fail at once with the option and the path named, and checks
  // that the scratch folder holds what it held before (no output, no temporary file).
  void expect_refused(const std::vector<std::string>& arguments, const std::string& option, const std::string& path,
                      const std::string& reason) {
    const std::vector<std::filesystem::path> before = entries();
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2) << arguments[0] << " " << option << " " << path << ": " << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_NE(result.err.find("usage error: " + option + ": " + path + ": "), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(reason), std::string::npos) << result.err;
    EXPECT_EQ(entries(), before) << result.err;
  }

  std::vector<std::filesystem::path> entries() const {
    std::vector<std::filesystem::path> found;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    return found;
  }

  std::filesystem::path dir;
  std::string instance;
  std::string log;
};

TEST_F(OutputPaths, AnOutputInAMissingFolderIsRefused) {
  const std::string missing = (dir / "missing" / "out.json").string();
  const std::string folder = "cannot write into " + (dir / "missing").string() + " (no such folder)";
  expect_refused({"sample-log", instance, "-o", missing}, "--output", missing, folder);
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", missing}, "--output",
                 missing, folder);
  expect_refused({"plot", instance, "-o", missing}, "--output", missing, folder);
  expect_refused({"reduce-knapsack", testing::source_path("data/knapsack/example.json").string(), "--out", missing},
                 "--out", missing, folder);
  expect_refused({"map", "--domain", "navigation", "-o", missing}, "--output", missing, folder);
  // train, study and collect create missing folders; one that cannot be created is refused.
  const std::string under_a_file = (dir / "file" / "out.json").string();
  const std::string not_a_folder = "cannot write into " + (dir / "file").string();
  expect_refused({"train", instance, "--out", under_a_file}, "--out", under_a_file, not_a_folder);
  expect_refused({"study", "anytime", instance, "--out", (dir / "file").string()}, "--out",
                 (dir / "file" / "anytime.csv").string(), not_a_folder);
  expect_refused(
      {"collect", "--domain", "navigation", "--trials", "1", "--log", (dir / "log.jsonl").string(), "-o", under_a_file},
      "--instance", under_a_file, not_a_folder);
}

TEST_F(OutputPaths, AnOutputOntoADirectoryIsRefused) {
  const std::string folder = (dir / "folder").string();
  expect_refused({"sample-log", instance, "-o", folder}, "--output", folder, "is a directory");
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", folder}, "--output",
                 folder, "is a directory");
  expect_refused({"plot", instance, "-o", folder}, "--output", folder, "is a directory");
  expect_refused({"train", instance, "--out", folder}, "--out", folder, "is a directory");
  expect_refused(
      {"collect", "--domain", "navigation", "--trials", "1", "--log", folder, "-o", (dir / "out.json").string()},
      "--log", folder, "is a directory");
  std::filesystem::create_directory(dir / "study");
  std::filesystem::create_directory(dir / "study" / "anytime.csv");
  const std::string csv = (dir / "study" / "anytime.csv").string();
  expect_refused({"study", "anytime", instance, "--out", (dir / "study").string()}, "--out", csv, "is a directory");
}

TEST_F(OutputPaths, AnOutputThatIsAnInputIsRefused) {
  const std::string destroys = "writing it would destroy it";
  expect_refused({"sample-log", instance, "-o", instance}, "--output", instance, destroys);
  expect_refused({"train", instance, "--out", instance}, "--out", instance, destroys);
  expect_refused({"plot", instance, "-o", instance}, "--output", instance, destroys);
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", log}, "--output", log,
                 destroys);
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", instance}, "--output",
                 instance, destroys);
  // Another name for the same file: a hard link and a symbolic link.
  const std::string hard = (dir / "hard.json").string();
  std::filesystem::create_hard_link(instance, hard);
  expect_refused({"sample-log", instance, "-o", hard}, "--output", hard, destroys);
  const std::string symbolic = (dir / "symbolic.json").string();
  std::filesystem::create_symlink(instance, symbolic);
  expect_refused({"train", symbolic, "--out", instance}, "--out", instance, destroys);
  // A file written beside the one named, and the plotted data beside a PNG named .csv.
  const std::string curve = (dir / "policy.curve.csv").string();
  std::filesystem::copy_file(instance, curve);
  expect_refused({"train", curve, "--out", (dir / "policy.json").string()}, "--out (learning curve)", curve, destroys);
  const std::string data = (dir / "data.csv").string();
  expect_refused({"plot", instance, "-o", data}, "--output (plotted data)", data, "is also the output of --output");
  // study: an output inside --out that is one of the instances.
  std::filesystem::create_directory(dir / "study");
  const std::string csv = (dir / "study" / "anytime.csv").string();
  std::filesystem::create_symlink(instance, csv);
  expect_refused({"study", "anytime", instance, "--out", (dir / "study").string()}, "--out", csv, destroys);
  const std::string world = (dir / "world.json").string();
  std::filesystem::copy_file(testing::source_path("data/domains/navigation.json"), world);
  expect_refused({"collect", "--domain", "navigation", "--world", world, "--trials", "1", "--log", world, "-o",
                  (dir / "out.json").string()},
                 "--log", world, destroys);
}

// The check comes before the training: a training far too long to finish in the test's time
// returns at once with the early message, having written nothing.
TEST_F(OutputPaths, TrainingIsRefusedBeforeItStarts) {
  const std::string under_a_file = (dir / "file" / "policy.json").string();
  const std::vector<std::filesystem::path> before = entries();
  const auto result =
      testing::run_process({ONTIME_CLI, "train", instance, "--episodes", "1000000000", "--out", under_a_file}, 60'000);
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(result.err, "ontime: usage error: --out: " + under_a_file + ": cannot write into " +
                            (dir / "file").string() + " (not a folder)\n");
  EXPECT_EQ(entries(), before);
}

TEST_F(OutputPaths, SpecialFilesAreWrittenDirectlyAndLinksAreFollowed) {
  // A FIFO stays a FIFO and its reader gets the log. The read end is open before the command
  // runs (so that its open does not wait) and is read once it has finished (the log fits in
  // the pipe's buffer).
  const std::filesystem::path fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  const auto result = ontime({"sample-log", instance, "--attempts", "10", "-o", fifo.string()});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  std::string received;
  char buffer[4096];
  for (ssize_t n; (n = ::read(reader, buffer, sizeof buffer)) > 0;)
    received.append(buffer, static_cast<std::size_t>(n));
  ::close(reader);
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_EQ(received, read_file(log));
  // A symbolic link is followed: the file it points to is replaced, the link stays a link.
  const std::filesystem::path target = dir / "target.jsonl";
  const std::filesystem::path link = dir / "link.jsonl";
  std::ofstream(target) << "old";
  std::filesystem::create_symlink(target, link);
  ASSERT_EQ(ontime({"sample-log", instance, "--attempts", "10", "-o", link.string()}).exit_code, 0);
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(read_file(target), read_file(log));
  // A link to nothing is refused.
  const std::filesystem::path dangling = dir / "dangling.jsonl";
  std::filesystem::create_symlink(dir / "nothing.jsonl", dangling);
  expect_refused({"sample-log", instance, "-o", dangling.string()}, "--output", dangling.string(),
                 "is a symbolic link to a missing file");
}

// A thread count no system can start is refused by name before any work (collect aborted and
// study failed as an internal error in the middle of their work).
TEST(Cli, ThreadCountsBeyondTheLimitAreUsageErrors) {
  const std::filesystem::path dir = scratch("threads");
  const auto collect = ontime({"collect", "--domain", "navigation", "--trials", "1", "--threads", "100000", "--log",
                               (dir / "l.jsonl").string(), "-o", (dir / "i.json").string()});
  EXPECT_EQ(collect.exit_code, 2) << collect.err;
  EXPECT_NE(collect.err.find("--threads"), std::string::npos) << collect.err;
  const auto study = ontime({"study", "compute-time", paper("instance4"), "--episodes", "100000", "--threads", "100000",
                             "--no-plot", "--out", dir.string()});
  EXPECT_EQ(study.exit_code, 2) << study.err;
  EXPECT_NE(study.err.find("--threads"), std::string::npos) << study.err;
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(Cli, HelpIsAvailableForEveryCommand) {
  for (const char* command : {"collect", "map", "run"}) {
    const auto result = ontime({command, "--help"});
    EXPECT_EQ(result.exit_code, 0) << command;
    EXPECT_NE(result.out.find("--domain"), std::string::npos) << command;
  }
  for (const char* command : {"fit", "sample-log", "plot", "generate-world"}) {
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

// Instance 4 with its first action renamed to `id` and the instance renamed to `name`.
std::string instance4_renamed(const std::string& id, const std::string& name) {
  json instance = json::parse(read_file(paper("instance4")));
  instance["name"] = name;
  if (id != "a1_1") {
    instance["actions"][id] = instance["actions"]["a1_1"];
    instance["actions"].erase("a1_1");
    instance["skeletons"][0][0] = id;
  }
  return instance.dump();
}

// Valid instances whatever their ids and name: the labels are shortened for drawing (and their dollar
// signs escaped: matplotlib reads $...$ as mathematical notation), the data CSV keeps them whole.
TEST(Cli, PlotDrawsInstancesWithHugeIdsAndNames) {
  const std::filesystem::path dir = scratch("plot_long");
  const std::vector<std::pair<std::string, std::string>> cases{{std::string(65'536, 'a'), std::string(1'000'000, 'n')},
                                                               {std::string(1'000'000, 'b'), "short"},
                                                               {"a1_1", std::string(10'000'000, 'm')},
                                                               {"a$\\foo$", "cost $5 $\\nope$"}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string instance = (dir / ("long" + std::to_string(i) + ".json")).string();
    std::ofstream(instance) << instance4_renamed(cases[i].first, cases[i].second);
    const std::filesystem::path png = dir / ("long" + std::to_string(i) + ".png");
    const auto result = ontime({"plot", instance, "-o", png.string()});
    ASSERT_EQ(result.exit_code, 0) << result.err.substr(0, 2000);
    EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    const std::string csv = read_file(std::filesystem::path(png).replace_extension(".csv"));
    EXPECT_NE(csv.find("\"" + cases[i].first + "\",planning,1,0.29999999999999999\n"), std::string::npos);
  }
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 3 * cases.size());  // instance, CSV and PNG: no temporary file left
}

// The pid of the process whose parent is `parent` and whose command line contains `word` (0 if none),
// with that command line (NUL-separated arguments).
std::pair<pid_t, std::vector<std::string>> child_running(pid_t parent, const std::string& word) {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = read_file(entry.path() / "stat");
    const std::size_t end_of_command = stat.rfind(')');
    if (end_of_command == std::string::npos) continue;
    std::istringstream fields(stat.substr(end_of_command + 1));
    std::string state;
    pid_t parent_pid = 0;
    fields >> state >> parent_pid;
    if (parent_pid != parent) continue;
    const std::string command_line = read_file(entry.path() / "cmdline");
    if (command_line.find(word) == std::string::npos) continue;
    std::vector<std::string> arguments;
    for (std::size_t start = 0; start < command_line.size();) {
      const std::size_t nul = std::min(command_line.find('\0', start), command_line.size());
      arguments.push_back(command_line.substr(start, nul - start));
      start = nul + 1;
    }
    return {static_cast<pid_t>(std::stol(name)), arguments};
  }
  return {0, {}};
}

// A signal sent to `ontime plot` while its Python child draws: the child is stopped and waited for,
// ontime dies of the same signal, and no figure appears, not even seconds later.
void expect_interrupted_plot_leaves_nothing(int signal_number) {
  const std::filesystem::path dir = scratch("plot_signal_" + std::to_string(signal_number));
  // 48 actions whose planning PMFs spread over 2,000 steps: seconds of drawing.
  json instance = json::parse(read_file(paper("instance4")));
  json pmf = json::object();
  for (int step = 1; step <= 2000; ++step) pmf[std::to_string(step)] = 1.0 / 2000;
  json actions = json::object();
  json skeletons = json::array();
  std::vector<std::string> ids;
  for (int k = 0; k < 48; ++k) {
    // Built with += : GCC 12 warns falsely (-Wrestrict) on "a" + std::string.
    std::string id(1, 'a');
    id += std::to_string(k);
    ids.push_back(id);
    actions[id] = {{"planning", {{"pmf", pmf}}}, {"execution", {{"pmf", {{"1", 1}}}}}};
    if (k < 16) skeletons.push_back(json::array({id}));
  }
  for (int k = 16; k < 48; ++k) skeletons[k % 16].push_back(ids[k]);
  instance["deadline"] = 2000;
  instance["actions"] = actions;
  instance["skeletons"] = skeletons;
  const std::string path = (dir / "slow.json").string();
  std::ofstream(path) << instance.dump();
  const std::filesystem::path png = dir / "slow.png";

  const pid_t ontime_pid = ::fork();
  ASSERT_GE(ontime_pid, 0);
  if (ontime_pid == 0) {
    const int nothing = ::open("/dev/null", O_WRONLY);
    ::dup2(nothing, STDOUT_FILENO);
    ::dup2(nothing, STDERR_FILENO);
    ::execl(ONTIME_CLI, ONTIME_CLI, "plot", path.c_str(), "-o", png.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::pair<pid_t, std::vector<std::string>> script{0, {}};
  int status = 0;
  bool exited = false;
  while (script.first == 0 && !exited) {
    script = child_running(ontime_pid, "plot_histograms.py");
    exited = ::waitpid(ontime_pid, &status, WNOHANG) == ontime_pid;
    if (script.first == 0 && !exited) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_FALSE(exited) << "ontime plot ended before its Python child was seen";
  ASSERT_EQ(::kill(ontime_pid, signal_number), 0);
  ASSERT_EQ(::waitpid(ontime_pid, &status, 0), ontime_pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << "status " << status;
  EXPECT_EQ(::kill(script.first, 0), -1) << "the Python child outlived ontime";
  EXPECT_EQ(errno, ESRCH);
  const auto output = std::find(script.second.begin(), script.second.end(), "--output");
  ASSERT_NE(output, script.second.end());
  ASSERT_NE(output + 1, script.second.end());
  const std::filesystem::path drawing(*(output + 1));
  std::this_thread::sleep_for(std::chrono::seconds(3));  // an orphaned child would have drawn by now
  EXPECT_FALSE(std::filesystem::exists(png));
  EXPECT_FALSE(std::filesystem::exists(drawing));
  EXPECT_FALSE(std::filesystem::exists(drawing.parent_path())) << "temporary directory left";
  if (::kill(script.first, 0) == 0) ::kill(script.first, SIGKILL);  // an orphan from a failed run
}

TEST(Cli, SigtermDuringAPlotStopsThePythonChildAndLeavesNoFigure) { expect_interrupted_plot_leaves_nothing(SIGTERM); }

TEST(Cli, SigintDuringAPlotStopsThePythonChildAndLeavesNoFigure) { expect_interrupted_plot_leaves_nothing(SIGINT); }

// A failing script is reported in one line, its last: exit 2 when it says the data is bad, 1 otherwise.
TEST(Cli, AFailingPlotScriptIsReportedInOneLine) {
  const std::filesystem::path dir = scratch("plot_failure");
  const auto plot_with = [&](const std::string& script) {
    const std::filesystem::path scripts = dir / "scripts";
    std::filesystem::create_directories(scripts);
    std::ofstream(scripts / "plot_histograms.py") << script;
    return testing::run_process({"/usr/bin/env", "ONTIME_PYTHON_DIR=" + scripts.string(), ONTIME_CLI, "plot",
                                 paper("figure1"), "-o", (dir / "figure1.png").string()});
  };
  const auto crashed = plot_with("import sys\nprint('drawing')\nraise RuntimeError('the drawing broke')\n");
  EXPECT_EQ(crashed.exit_code, 1);
  EXPECT_EQ(std::count(crashed.err.begin(), crashed.err.end(), '\n'), 1) << crashed.err;
  EXPECT_NE(crashed.err.find("RuntimeError: the drawing broke"), std::string::npos) << crashed.err;
  const auto refused = plot_with(
      "import sys\nsys.stderr.write('a warning\\nplot_histograms.py: the data is bad\\n')\n"
      "sys.exit(65)\n");
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_NE(refused.err.find("plot_histograms.py: the data is bad"), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "figure1.png"));

  // The real script on bad data: one line, the bad-input status, no traceback.
  std::ofstream(dir / "bad.csv") << "action,distribution,step,probability\nx,planning,1,abc\n";
  const auto direct =
      testing::run_process({"/usr/bin/python3", testing::source_path("python/plot_histograms.py").string(), "--data",
                            (dir / "bad.csv").string(), "--output", (dir / "bad.png").string(), "--deadline", "4"});
  EXPECT_EQ(direct.exit_code, 65);
  EXPECT_EQ(direct.err, "plot_histograms.py: " + (dir / "bad.csv").string() +
                            ": row 1, column probability: 'abc' is not a number\n");
}

// The figure is drawn in a folder of $TMPDIR: without one, a usage error naming it, and no figure.
TEST(Cli, PlotWithoutATemporaryFolderIsAUsageError) {
  const std::filesystem::path dir = scratch("plot_tmpdir");
  for (const std::string& temporary : {std::string("/nonexistent"), (dir / "file").string()}) {
    std::ofstream(dir / "file") << "not a folder";
    const auto result = testing::run_process({"/usr/bin/env", "TMPDIR=" + temporary, ONTIME_CLI, "plot",
                                              paper("figure1"), "-o", (dir / "figure1.png").string()});
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_NE(result.err.find("($TMPDIR)"), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "figure1.png"));
  }
}

// Input files are read through one bounded reader: a device without end is read up to the
// limit (256 MiB by default, ONTIME_MAX_INPUT_BYTES overrides it) and refused with exit 2.
TEST(Cli, AnInputWithoutEndIsRefusedAtTheSizeLimit) {
  const auto instance = ontime({"solve", "/dev/zero"});
  EXPECT_EQ(instance.exit_code, 2) << instance.err;
  EXPECT_NE(instance.err.find("/dev/zero: file: the instance file is larger than the input size limit of 268435456 "
                              "bytes (256 MiB)"),
            std::string::npos)
      << instance.err;

  ASSERT_EQ(::setenv("ONTIME_MAX_INPUT_BYTES", "65536", 1), 0);
  const auto log = ontime({"fit", "/dev/urandom", "--step", "1", "--deadline", "5", "--skeletons", paper("figure1"),
                           "-o", (scratch("urandom") / "fit.json").string()});
  const auto policy = ontime({"evaluate", paper("figure1"), "--solver", "ppo", "--policy", "/dev/zero"});
  ASSERT_EQ(::unsetenv("ONTIME_MAX_INPUT_BYTES"), 0);
  EXPECT_EQ(log.exit_code, 2) << log.err;
  EXPECT_NE(log.err.find("/dev/urandom: file: the planner log file is larger than the input size limit of 65536 bytes"),
            std::string::npos)
      << log.err;
  EXPECT_EQ(policy.exit_code, 2) << policy.err;
  EXPECT_NE(policy.err.find("/dev/zero: file: the policy file is larger than the input size limit of 65536 bytes"),
            std::string::npos)
      << policy.err;
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

// `train` on valid instances where success is impossible (no useful choice from the start)
// exits 0 with a policy, the same bytes in repeated runs, and the policy evaluates to 0.
TEST(Cli, TrainsTheSamePolicyOnInstancesWhereSuccessIsImpossible) {
  const auto directory = scratch("impossible");
  for (const std::string name : {"never_planning", "deadline_one", "never_execution"}) {
    SCOPED_TRACE(name);
    const std::string instance = testing::source_path("tests/data/impossible/" + name + ".json").string();
    std::vector<std::string> policies;
    for (const std::string run : {"first", "second"}) {
      const std::string policy = (directory / (name + "-" + run + ".json")).string();
      const auto trained = ontime({"train", instance, "--episodes", "200", "--out", policy, "--no-plot", "--json"});
      ASSERT_EQ(trained.exit_code, 0) << trained.err;
      EXPECT_EQ(json::parse(trained.out)["exact_success_probability"].get<double>(), 0.0);
      policies.push_back(read_file(policy));
      // One epoch of 200 episodes that all ended before a choice: no step, no gradient step.
      std::ifstream curve(directory / (name + "-" + run + ".curve.csv"));
      std::string header, epoch;
      std::getline(curve, header);
      std::getline(curve, epoch);
      EXPECT_EQ(epoch.rfind("1,200,0,0,0,0,", 0), 0U) << epoch;
    }
    EXPECT_FALSE(policies[0].empty());
    EXPECT_EQ(policies[0], policies[1]);
    const auto evaluated = ontime({"evaluate", instance, "--solver", "ppo", "--policy",
                                   (directory / (name + "-first.json")).string(), "--episodes", "100", "--json"});
    ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
    EXPECT_EQ(json::parse(evaluated.out)["successes"].get<int>(), 0);
  }
}

// A policy is used only on the instance it was trained on (its digest), unless --policy-check
// shape; unknown keys in policy files are refused by name. Both exit 2 with one line.
TEST(Cli, APolicyOfAnotherInstanceIsRefusedUnlessTheShapeSuffices) {
  const auto directory = scratch("digest");
  const std::string policy = (directory / "instance4.json").string();
  const auto trained = ontime({"train", paper("instance4"), "--episodes", "100", "--out", policy, "--no-plot"});
  ASSERT_EQ(trained.exit_code, 0) << trained.err;
  std::string other_text = read_file(paper("instance4"));
  other_text.replace(other_text.find("\"1\": 0.3"), 8, "\"1\": 0.2");
  const std::string other = (directory / "other.json").string();
  std::ofstream(other) << other_text;
  const auto evaluate = [&](const std::string& instance, const std::string& policy_file, const std::string& check) {
    std::vector<std::string> arguments{"evaluate", instance,    "--solver",   "ppo",
                                       "--policy", policy_file, "--episodes", "10"};
    if (!check.empty()) arguments.insert(arguments.end(), {"--policy-check", check});
    return ontime(arguments);
  };
  EXPECT_EQ(evaluate(paper("instance4"), policy, "").exit_code, 0);
  const auto refused = evaluate(other, policy, "");
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find(policy + " was trained on another instance ('paper-instance-4', fnv1a64:"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_EQ(evaluate(other, policy, "shape").exit_code, 0);

  std::string with_unknown_key = read_file(policy);
  with_unknown_key.insert(with_unknown_key.find('{') + 1, "\"trained_on\": \"elsewhere\",");
  const std::string tampered = (directory / "tampered.json").string();
  std::ofstream(tampered) << with_unknown_key;
  const auto unknown = evaluate(paper("instance4"), tampered, "shape");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find(tampered + ": trained_on: unknown key"), std::string::npos) << unknown.err;
}

// The policy, its curve CSV and its curve PNG are one output: an interrupted `train` leaves the
// previous three files, byte for byte, and nothing else; a run cut off just as the new policy
// appears leaves the new three or the old three, never a mix; a run without a plot removes the
// previous PNG, which belonged to another training.
TEST(Cli, InterruptedTrainingLeavesTheOldSetOrTheNewSetNeverAMix) {
  const auto directory = scratch("output_set");
  const auto policy = directory / "policy.json";
  const auto csv = directory / "policy.curve.csv";
  const auto png = directory / "policy.curve.png";
  const auto train = [&](const std::string& episodes, bool plot) {
    std::vector<std::string> arguments{ONTIME_CLI, "train", paper("instance4"), "--episodes", episodes, "--seed",
                                       "5",        "--out", policy.string()};
    if (!plot) arguments.push_back("--no-plot");
    return arguments;
  };
  ASSERT_EQ(testing::run_process(train("100", true)).exit_code, 0);
  const std::vector<std::string> old_set{read_file(policy), read_file(csv), read_file(png)};
  const auto entries = [&directory] {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(directory)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  };
  const std::vector<std::string> expected_names{"policy.curve.csv", "policy.curve.png", "policy.json"};
  ASSERT_EQ(entries(), expected_names);

  // Cut off while the new files are being written (the plot is drawn last).
  const auto staging = testing::run_process(train("200", true), [&] {
    for (const std::string& name : entries()) {
      if (name.rfind(".ontime-output-", 0) == 0) return true;
    }
    return false;
  });
  EXPECT_EQ(entries(), expected_names);
  // The signal lands while the set is staged (the old set stays), or, rarely, while it is being
  // renamed with signals held (the whole new set is in place): never a mix. (Compared as
  // booleans: a failure would print whole files.)
  if (read_file(policy) == old_set[0]) {
    EXPECT_EQ(staging.exit_code, 128 + SIGINT) << staging.err;
    EXPECT_TRUE(read_file(csv) == old_set[1]);
    EXPECT_TRUE(read_file(png) == old_set[2]);
  } else {
    EXPECT_TRUE(staging.exit_code == 128 + SIGINT || staging.exit_code == 0) << staging.err;
    EXPECT_TRUE(read_file(csv) != old_set[1]) << "a new policy beside the old curve CSV";
    EXPECT_TRUE(read_file(png) != old_set[2]) << "a new policy beside the old curve PNG";
  }

  // Cut off as soon as a new policy shows: the curve beside it is new too.
  const std::vector<std::string> before{read_file(policy), read_file(csv), read_file(png)};
  testing::run_process(train("300", true), [&] { return read_file(policy) != before[0]; });
  EXPECT_EQ(entries(), expected_names);
  const std::vector<std::string> now{read_file(policy), read_file(csv), read_file(png)};
  if (now[0] == before[0]) {
    EXPECT_TRUE(now == before);
  } else {
    EXPECT_TRUE(now[1] != before[1]) << "a new policy beside the old curve CSV";
    EXPECT_TRUE(now[2] != before[2]) << "a new policy beside the old curve PNG";
  }

  ASSERT_EQ(testing::run_process(train("400", false)).exit_code, 0);
  EXPECT_EQ(entries(), (std::vector<std::string>{"policy.curve.csv", "policy.json"}));
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
  const auto states =
      ontime({"solve", paper("figure1"), "--max-states", "18446744073709551615", "--method", "memoised"});
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
  const auto memory = ontime({"solve", paper("figure1"), "--max-memory-mib", "1099511627776"});
  EXPECT_EQ(memory.exit_code, 2);
  EXPECT_NE(memory.err.find("--max-memory-mib: would need up to"), std::string::npos) << memory.err;
}

TEST(Cli, SolveGivesTheOptimumOrACertifiedIntervalWithItsLayers) {
  const auto exact = ontime({"solve", paper("instance1"), "--json", "--stats"});
  ASSERT_EQ(exact.exit_code, 0) << exact.err;
  const json solved = json::parse(exact.out);
  EXPECT_EQ(solved["optimal_success_probability"].get<double>(), 0.942);
  EXPECT_EQ(solved["lower_bound"].get<double>(), 0.942);
  EXPECT_EQ(solved["upper_bound"].get<double>(), 0.942);
  EXPECT_TRUE(solved["exact"].get<bool>());
  EXPECT_EQ(solved["states"].get<int>(), 872);
  int states = 0;
  for (const json& layer : solved["layers"]) states += layer["states"].get<int>();
  EXPECT_EQ(states, 872);
  EXPECT_EQ(solved["layers"][0]["states"].get<int>(), 1);

  const auto capped = ontime({"solve", paper("instance1"), "--json", "--max-states", "100"});
  ASSERT_EQ(capped.exit_code, 0) << capped.err;
  const json bounded = json::parse(capped.out);
  EXPECT_TRUE(bounded["optimal_success_probability"].is_null());
  EXPECT_FALSE(bounded["exact"].get<bool>());
  EXPECT_LE(bounded["lower_bound"].get<double>(), 0.942);
  EXPECT_GE(bounded["upper_bound"].get<double>(), 0.942);
  // The cap holds for each part: the whole tree, then a split of it (instance1's skeletons begin
  // with two different actions).
  EXPECT_LE(bounded["states"].get<int>() - bounded["split"]["states"].get<int>(), 100);
  EXPECT_LE(bounded["split"]["states"].get<int>(), 100);
  EXPECT_NE(bounded["stopped_by"].get<std::string>().find("cap of 100 states"), std::string::npos);
  EXPECT_NE(bounded["split"]["stopped_by"].get<std::string>().find("cap of 100 states"), std::string::npos);
  EXPECT_EQ(bounded["split"]["enumerated_skeletons"], json({1, 2, 3}));
  EXPECT_LE(bounded["split"]["lower_bound"].get<double>(), 0.942);
  EXPECT_GE(bounded["split"]["upper_bound"].get<double>(), 0.942);
  EXPECT_LE(bounded["upper_bound"].get<double>(), bounded["split"]["upper_bound"].get<double>());

  const auto directory = scratch("solve_policy");
  const std::string policy = (directory / "policy.jsonl").string();
  const auto written = ontime({"solve", paper("instance1"), "--policy", policy, "--policy-layers", "2"});
  ASSERT_EQ(written.exit_code, 0) << written.err;
  std::ifstream in(policy);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) {
    const json entry = json::parse(line);
    EXPECT_LE(entry["time"].get<int>(), 1);
    EXPECT_EQ(entry["refined"].size(), 4U);
    ++lines;
  }
  EXPECT_EQ(lines, 1 + solved["layers"][1]["states"].get<int>());
}

TEST(Cli, SolveNoTimingPrintsTheSameBytesForAnyThreadCount) {
  const std::vector<std::string> args{"solve",       paper("instance1"), "--json", "--stats",
                                      "--no-timing", "--max-states",     "300"};
  auto one = args, two = args;
  one.insert(one.end(), {"--threads", "1"});
  two.insert(two.end(), {"--threads", "2"});
  const auto first = ontime(one);
  const auto second = ontime(two);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_EQ(first.out, second.out);
  const json solved = json::parse(first.out);
  EXPECT_FALSE(solved.contains("seconds"));
  EXPECT_FALSE(solved.contains("peak_memory_bytes"));
  EXPECT_FALSE(solved["layers"][0].contains("forward_seconds"));
  EXPECT_FALSE(solved["exact"].get<bool>());
  EXPECT_LT(solved["lower_bound"].get<double>(), solved["upper_bound"].get<double>());
}

}  // namespace
}  // namespace ontime

namespace ontime {
namespace {

// The exact parts of evaluate, table and study, and the search trees of a study, are checked
// against the memory available before any work, as solve's cap is.
TEST(Cli, ExactPartsAndStudyTreesBeyondTheAvailableMemoryAreRefusedBeforeStarting) {
  const std::string huge = "1000000000000";  // 10^12 states: terabytes
  for (const std::vector<std::string>& arguments :
       {std::vector<std::string>{"evaluate", paper("instance1"), "--solver", "dp", "--exact", "--max-states", huge},
        std::vector<std::string>{"table", paper("instance1"), "--solvers", "dp", "--exact", "--max-states", huge},
        std::vector<std::string>{"study", "anytime", paper("instance1"), "--no-plot", "--out",
                                 scratch("memory_study").string(), "--max-states", huge}}) {
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2) << arguments[0] << ": " << result.err;
    EXPECT_NE(result.err.find("--max-states " + huge + ": would need up to"), std::string::npos) << result.err;
  }
  const auto trees = ontime({"study", "compute-time", paper("instance1"), "--no-plot", "--out",
                             scratch("memory_trees").string(), "--threads", "2", "--max-tree-mib", "16777216"});
  EXPECT_EQ(trees.exit_code, 2) << trees.err;
  EXPECT_NE(trees.err.find("--max-tree-mib 16777216 with 2 threads: would need up to"), std::string::npos) << trees.err;
}

}  // namespace
}  // namespace ontime
