#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "support/bad_inputs.hpp"
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
  const auto result = ontime({"evaluate", paper("instance4"), "--solver", "dp-rerun", "--episodes", "2000",
                              "--seed", "3", "--threads", "2", "--exact", "--json"});
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
  // Same seed with one thread: the same successes.
  const auto single = ontime({"evaluate", paper("instance4"), "--solver", "dp-rerun", "--episodes", "2000",
                              "--seed", "3", "--threads", "1", "--json"});
  EXPECT_EQ(json::parse(single.out)["successes"], out["successes"]);
}

TEST(Cli, TablePrintsOneRowPerInstanceAndTheOptimum) {
  const auto result = ontime({"table", paper("instance2"), paper("instance4"), "--episodes", "500", "--exact",
                              "--solvers", "dp,greedy"});
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

TEST(Cli, HelpIsAvailableForEveryCommand) {
  for (const char* command : {"solve", "evaluate", "table"}) {
    const auto result = ontime({command, "--help"});
    EXPECT_EQ(result.exit_code, 0) << command;
    EXPECT_NE(result.out.find("--json"), std::string::npos) << command;
  }
  EXPECT_EQ(ontime({"--help"}).exit_code, 0);
  EXPECT_EQ(ontime({"--version"}).exit_code, 0);
}

}  // namespace
}  // namespace ontime
