// CLI tests of `evaluate`, `table` and `study`: the documented keys, the same bytes for any
// thread count without timing, one row per instance, exact parts over their cap, instances too
// large for the exact solver, and memory checked before any work.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli_test_support.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

using namespace cli_test;

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

// --regret: the estimate of V* - V from every decision's exact loss. dp-rerun on instance 1 is
// exactly 0.002 below the optimum (0.940 against 0.942); the estimate's interval holds that, is far narrower
// than the sampled rate's, and the text names the optimum.
TEST(Cli, EvaluateEstimatesTheRegretFromExactLosses) {
  const auto result = ontime({"evaluate", paper("instance1"), "--solver", "dp-rerun", "--episodes", "4000", "--seed",
                              "5", "--threads", "2", "--exact", "--regret", "--json", "--no-timing"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  const json& regret = out["regret"];
  EXPECT_DOUBLE_EQ(regret["optimum"].get<double>(), 0.942);
  EXPECT_EQ(regret["episodes"], 4000);
  const double truth = regret["optimum"].get<double>() - out["exact_success_probability"].get<double>();
  EXPECT_NEAR(truth, 0.002, 1e-9);
  EXPECT_NEAR(regret["mean"].get<double>(), truth, regret["ci95"].get<double>());
  EXPECT_LT(4 * regret["ci95"].get<double>(), out["ci95"].get<double>());
  const auto text = ontime({"evaluate", paper("instance1"), "--solver", "optimal", "--episodes", "300", "--regret"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("regret          0.000000 ± 0.000000  (optimum 0.942000: success probability 0.942000, "
                          "100.00% of it)"),
            std::string::npos)
      << text.out;
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

TEST(Cli, EvaluateActsWhilePlanningByEachAllocatorsCommitRule) {
  // Instance 1: acting while planning is certain for the optimum (0.942 plan-first) and for
  // dp-rerun's eager rule; round-robin's eager rule is valued exactly too.
  const auto optimal = ontime({"evaluate", paper("instance1"), "--act", "concurrent", "--solver", "optimal",
                               "--episodes", "2000", "--exact", "--json", "--no-timing"});
  ASSERT_EQ(optimal.exit_code, 0) << optimal.err;
  const json out = json::parse(optimal.out);
  EXPECT_EQ(out["acting"], "concurrent");
  EXPECT_EQ(out["commit_rule"], allocator_registry().find("optimal").commit_rule);
  EXPECT_EQ(out["successes"], 2000);
  EXPECT_NEAR(out["exact_success_probability"].get<double>(), 1.0, 1e-12);

  const auto text = ontime({"evaluate", paper("instance2"), "--act", "concurrent", "--solver", "round-robin",
                            "--episodes", "4000", "--exact"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("acting          concurrent (SPEC §10); commit rule: eager"), std::string::npos) << text.out;
  const auto round_robin = ontime({"evaluate", paper("instance2"), "--act", "concurrent", "--solver", "round-robin",
                                   "--episodes", "4000", "--exact", "--json"});
  const json values = json::parse(round_robin.out);
  const double exact = values["exact_success_probability"].get<double>();
  EXPECT_NEAR(exact, 0.58, 1e-12);  // 0.51 plan-first
  EXPECT_NEAR(values["success_rate"].get<double>(), exact, 4 * std::sqrt(exact * (1 - exact) / 4000));

  // --regret acting while planning: the concurrent optimum's loss per move; the exact regret of
  // round-robin (stationary) lies within twice the 95% half-width (3.92 standard errors).
  const auto with_regret = ontime({"evaluate", paper("instance2"), "--act", "concurrent", "--solver", "round-robin",
                                   "--episodes", "4000", "--exact", "--regret", "--json", "--no-timing"});
  ASSERT_EQ(with_regret.exit_code, 0) << with_regret.err;
  const json regret = json::parse(with_regret.out)["regret"];
  const double truth =
      regret["optimum"].get<double>() - json::parse(with_regret.out)["exact_success_probability"].get<double>();
  EXPECT_GT(truth, 0.0);
  EXPECT_NEAR(regret["mean"].get<double>(), truth, 2 * regret["ci95"].get<double>() + 1e-9);
  EXPECT_EQ(regret["episodes"].get<std::uint64_t>(), 4000U);

  // Plan-first stays as it was: no acting keys.
  const auto plan_first =
      ontime({"evaluate", paper("instance1"), "--solver", "optimal", "--episodes", "100", "--json", "--no-timing"});
  ASSERT_EQ(plan_first.exit_code, 0) << plan_first.err;
  EXPECT_FALSE(json::parse(plan_first.out).contains("acting"));

  for (const auto& [arguments, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--solver", "ppo"}, "ppo needs a trained policy"},
           {{"--solver", "thompson", "--exact"}, "exact evaluation needs an allocator whose move depends only on"},
           {{"--solver", "dp-rerun", "--act", "sometimes"}, "--act"}}) {
    std::vector<std::string> command{"evaluate", paper("instance1"), "--act", "concurrent", "--episodes", "10"};
    command.insert(command.end(), arguments.begin(), arguments.end());
    const auto result = ontime(command);
    EXPECT_EQ(result.exit_code, 2) << message << ": " << result.err;
    EXPECT_NE(result.err.find(message), std::string::npos) << result.err;
  }
}

TEST(Cli, TableSetsPlanFirstBesideActingWhilePlanning) {
  const auto result = ontime({"table", paper("instance1"), "--act", "plan-first,concurrent", "--solvers",
                              "dp-rerun,optimal", "--episodes", "500", "--exact", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json rows = json::parse(result.out)["rows"];
  ASSERT_EQ(rows.size(), 2U);
  EXPECT_FALSE(rows[0].contains("acting"));
  EXPECT_EQ(rows[1]["acting"], "concurrent");
  EXPECT_NEAR(rows[0]["optimal_success_probability"].get<double>(), 0.942, 1e-12);
  EXPECT_NEAR(rows[1]["optimal_success_probability"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(rows[0]["solvers"]["dp-rerun"]["exact_success_probability"].get<double>(), 0.94, 1e-12);
  EXPECT_NEAR(rows[1]["solvers"]["dp-rerun"]["exact_success_probability"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(rows[1]["solvers"]["dp-rerun"]["success_rate"], 1.0);

  // The default columns acting while planning are the kinds with a commit rule.
  const auto defaults = ontime({"table", paper("instance2"), "--act", "concurrent", "--episodes", "50", "--json"});
  ASSERT_EQ(defaults.exit_code, 0) << defaults.err;
  const auto columns = json::parse(defaults.out)["solvers"].get<std::vector<std::string>>();
  EXPECT_EQ(columns, (std::vector<std::string>{"mcts", "dp", "dp-rerun", "round-robin", "greedy", "thompson",
                                               "first-found", "found-order-round-robin", "averaged"}));
  const auto markdown = ontime({"table", paper("instance2"), "--act", "concurrent", "--episodes", "50"});
  EXPECT_NE(markdown.out.find("| instance2 (concurrent)  |"), std::string::npos) << markdown.out;

  for (const auto& [arguments, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--act", "concurrent", "--solvers", "dp-rerun,ppo"}, "ppo needs a trained policy"},
           {{"--act", "concurrent,concurrent"}, "instance given twice"},
           {{"--act", "plan-first,sometimes"}, "--act"}}) {
    std::vector<std::string> command{"table", paper("instance1"), "--episodes", "10"};
    command.insert(command.end(), arguments.begin(), arguments.end());
    const auto refused = ontime(command);
    EXPECT_EQ(refused.exit_code, 2) << message << ": " << refused.err;
    EXPECT_NE(refused.err.find(message), std::string::npos) << refused.err;
  }
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

// An instance with rewards (SPEC §8): solve, evaluate and table report the expected reward beside
// the success probability, and the exact figures agree across the three.
TEST(Cli, RewardsAreReportedBySolveEvaluateAndTable) {
  const std::string coffee = testing::source_path("data/instances/rewards/meeting-with-coffee.json").string();
  const auto solved = ontime({"solve", coffee, "--json"});
  ASSERT_EQ(solved.exit_code, 0) << solved.err;
  const json solve = json::parse(solved.out);
  EXPECT_FALSE(solve.contains("optimal_success_probability"));
  const double optimum = solve["optimal_expected_reward"].get<double>();
  const auto evaluated = ontime({"evaluate", coffee, "--solver", "optimal", "--episodes", "500", "--exact", "--json"});
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
  const json evaluation = json::parse(evaluated.out);
  EXPECT_EQ(evaluation["exact_expected_reward"].get<double>(), optimum);
  EXPECT_GT(evaluation["exact_success_probability"].get<double>(), optimum);
  EXPECT_LT(evaluation["mean_reward"].get<double>(), evaluation["success_rate"].get<double>());
  const auto tabled = ontime({"table", coffee, "--solvers", "dp-rerun", "--episodes", "500", "--exact", "--json"});
  ASSERT_EQ(tabled.exit_code, 0) << tabled.err;
  const json table = json::parse(tabled.out);
  EXPECT_EQ(table["rows"][0]["optimal_expected_reward"].get<double>(), optimum);
  EXPECT_LT(table["rows"][0]["solvers"]["dp-rerun"]["exact_expected_reward"].get<double>(), optimum);
  EXPECT_TRUE(table["rows"][0]["solvers"]["dp-rerun"].contains("mean_reward"));
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
