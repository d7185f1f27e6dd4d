// CLI tests of `solve` (the optimum, or a certified interval with its layers; the same bytes for
// any thread count; caps refused before starting; no scratch left behind when stopped or killed)
// and of `reduce-knapsack`.

#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli_test_support.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

using namespace cli_test;

// The lines `ontime solve INSTANCE --policy FILE --policy-layers LAYERS` writes, parsed.
std::vector<json> solve_policy(const std::string& instance, const std::string& name, int layers) {
  const std::string policy = (scratch(name) / "policy.jsonl").string();
  const auto written = ontime({"solve", instance, "--policy", policy, "--policy-layers", std::to_string(layers)});
  EXPECT_EQ(written.exit_code, 0) << written.err;
  std::ifstream in(policy);
  std::vector<json> entries;
  for (std::string line; std::getline(in, line);) entries.push_back(json::parse(line));
  return entries;
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

// Acting while planning (SPEC §10): --act concurrent, or the instance's "acting", solves its MDP;
// what does not take that mode yet refuses it with exit 2, naming the rule.
TEST(Cli, SolveActsWhilePlanningWhenAsked) {
  const auto plan_first = ontime({"solve", paper("instance1"), "--json", "--act", "plan-first"});
  ASSERT_EQ(plan_first.exit_code, 0) << plan_first.err;
  EXPECT_NEAR(json::parse(plan_first.out)["optimal_success_probability"].get<double>(), 0.942, 1e-12);
  const auto concurrent = ontime({"solve", paper("instance1"), "--json", "--act", "concurrent"});
  ASSERT_EQ(concurrent.exit_code, 0) << concurrent.err;
  const json out = json::parse(concurrent.out);
  EXPECT_EQ(out["acting"], "concurrent");
  EXPECT_EQ(out["method"], "memoised");
  EXPECT_NEAR(out["optimal_success_probability"].get<double>(), 1.0, 1e-12);
  EXPECT_TRUE(out["exact"].get<bool>());
  EXPECT_GT(out["states"].get<int>(), 0);

  // The same from the instance's own field.
  const std::string instance = (scratch("acting") / "instance1.json").string();
  {
    std::ifstream in(paper("instance1"));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.insert(text.find('{') + 1, R"("acting": "concurrent",)");
    std::ofstream(instance) << text;
  }
  const auto from_file = ontime({"solve", instance, "--json", "--no-timing"});
  ASSERT_EQ(from_file.exit_code, 0) << from_file.err;
  EXPECT_EQ(json::parse(from_file.out)["optimal_success_probability"], out["optimal_success_probability"]);
  const auto overridden = ontime({"solve", instance, "--json", "--act", "plan-first"});
  ASSERT_EQ(overridden.exit_code, 0) << overridden.err;
  EXPECT_NEAR(json::parse(overridden.out)["optimal_success_probability"].get<double>(), 0.942, 1e-12);

  const std::vector<std::pair<std::vector<std::string>, std::string>> refused{
      {{"solve", instance, "--method", "split"}, "solved by --method memoised, search or layered"},
      {{"solve", instance, "--tolerance", "0.1"}, "--tolerance is for the plan-first layered solver"},
      {{"solve", instance, "--max-seconds", "5"}, "takes it with --method search or layered"},
      {{"solve", instance, "--gap", "0.1"}, "--gap is for --method search"},
      {{"evaluate", instance, "--solver", "ppo", "--episodes", "10"}, "ppo needs a trained policy"},
      {{"table", instance, "--episodes", "10", "--solvers", "ppo"}, "ppo needs a trained policy"},
      {{"solve", paper("instance1"), "--act", "interleaved"}, "--act"},
  };
  for (const auto& [arguments, message] : refused) {
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2) << arguments[1] << " " << arguments.back() << ": " << result.err;
    EXPECT_NE(result.err.find(message), std::string::npos) << result.err;
  }
}

// Acting while planning, `--method search` gives the memoised solver's optimum to the bit (JSON's
// shortest round trip of the same double), its first choice, and an interval when cut short.
TEST(Cli, SolveSearchesActingWhilePlanning) {
  const std::string navigation = testing::source_path("data/instances/navigation.json").string();
  const std::string meeting = testing::source_path("data/instances/chains/meeting-through-the-queue.json").string();
  // With backtracking (SPEC §7): the kitchen whose placements may blame their grasps.
  const std::string kitchen = testing::source_path("data/instances/kitchen-grasps.json").string();
  for (const std::string& name : {paper("instance2"), paper("instance4"), meeting, kitchen}) {
    const auto memoised = ontime({"solve", name, "--json", "--act", "concurrent"});
    const auto search = ontime({"solve", name, "--json", "--act", "concurrent", "--method", "search"});
    ASSERT_EQ(memoised.exit_code, 0) << memoised.err;
    ASSERT_EQ(search.exit_code, 0) << search.err;
    const json by_memo = json::parse(memoised.out);
    const json by_search = json::parse(search.out);
    EXPECT_EQ(by_search["method"], "search");
    EXPECT_TRUE(by_search["exact"].get<bool>());
    const std::string key =
        by_memo.contains("optimal_success_probability") ? "optimal_success_probability" : "optimal_expected_reward";
    EXPECT_EQ(by_search[key].get<double>(), by_memo[key].get<double>()) << name;
    EXPECT_EQ(by_search["first_choice"], by_memo["first_choice"]);
    EXPECT_LT(by_search["states"].get<int>(), by_memo["states"].get<int>());
  }
  const auto cut = ontime({"solve", navigation, "--json", "--act", "concurrent", "--method", "search", "--gap", "0.2"});
  ASSERT_EQ(cut.exit_code, 0) << cut.err;
  const json interval = json::parse(cut.out);
  EXPECT_FALSE(interval["exact"].get<bool>());
  EXPECT_EQ(interval["stopped_by"], "the gap");
  EXPECT_TRUE(interval["optimal_success_probability"].is_null());
  // Navigation's optimum at its own deadline (0.876693, `solve --method search`, 18 s) lies inside.
  EXPECT_LE(interval["lower_bound"].get<double>(), 0.8766933308900258);
  EXPECT_GE(interval["upper_bound"].get<double>(), 0.8766933308900258);
  EXPECT_LE(interval["upper_bound"].get<double>() - interval["lower_bound"].get<double>(), 0.2);
}

// Acting while planning, `--method layered` gives the memoised solver's optimum to the bit and its
// first choice, the same on any thread count; cut by a cap, an interval around it naming the
// frontier level; the plan-first layered solver's options it does not take are refused.
TEST(Cli, SolveActingWhilePlanningByLevels) {
  const std::string meeting = testing::source_path("data/instances/chains/meeting-through-the-queue.json").string();
  const std::string kitchen = testing::source_path("data/instances/kitchen-grasps.json").string();
  for (const std::string& name : {paper("instance4"), meeting, kitchen}) {
    const auto memoised = ontime({"solve", name, "--json", "--act", "concurrent"});
    ASSERT_EQ(memoised.exit_code, 0) << memoised.err;
    const json by_memo = json::parse(memoised.out);
    const std::string key =
        by_memo.contains("optimal_success_probability") ? "optimal_success_probability" : "optimal_expected_reward";
    std::string first_output;
    for (const char* threads : {"1", "2"}) {
      const auto layered = ontime({"solve", name, "--json", "--act", "concurrent", "--method", "layered", "--threads",
                                   threads, "--no-timing", "--stats"});
      ASSERT_EQ(layered.exit_code, 0) << layered.err;
      const json by_levels = json::parse(layered.out);
      EXPECT_EQ(by_levels["method"], "layered");
      EXPECT_TRUE(by_levels["exact"].get<bool>());
      EXPECT_EQ(by_levels[key].get<double>(), by_memo[key].get<double>()) << name;
      EXPECT_EQ(by_levels["first_choice"], by_memo["first_choice"]);
      EXPECT_EQ(by_levels["level_figures"].size(), by_levels["levels"].get<std::size_t>());
      if (first_output.empty()) first_output = layered.out;
      EXPECT_EQ(layered.out, first_output) << name << ", " << threads << " threads";
    }
  }
  const auto cut = ontime({"solve", kitchen, "--json", "--act", "concurrent", "--method", "layered", "--max-states",
                           "2000", "--no-timing"});
  ASSERT_EQ(cut.exit_code, 0) << cut.err;
  const json interval = json::parse(cut.out);
  EXPECT_FALSE(interval["exact"].get<bool>());
  EXPECT_EQ(interval["stopped_by"], "the state cap");
  EXPECT_GE(interval["frontier_level"].get<int>(), 1);
  EXPECT_TRUE(interval["optimal_success_probability"].is_null());
  const double optimum =
      json::parse(ontime({"solve", kitchen, "--json", "--act", "concurrent"}).out)["optimal_success_probability"];
  EXPECT_LE(interval["lower_bound"].get<double>(), optimum);
  EXPECT_GE(interval["upper_bound"].get<double>(), optimum);
  for (const std::vector<std::string>& refused : {std::vector<std::string>{"--method", "layered", "--tolerance", "0.1"},
                                                  {"--method", "layered", "--policy", "policy.jsonl"},
                                                  {"--scratch", "."},
                                                  {"--method", "split"},
                                                  {"--threads", "2"},
                                                  {"--method", "search", "--max-memory-mib", "100"},
                                                  {"--max-seconds", "5"}}) {
    std::vector<std::string> arguments{"solve", paper("instance1"), "--act", "concurrent"};
    arguments.insert(arguments.end(), refused.begin(), refused.end());
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2) << refused.front() << ": " << result.out;
    EXPECT_NE(result.err.find("concurrent, SPEC §10"), std::string::npos) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  }
}

// `ontime solve INSTANCE --json` plan-first (memoised) and acting while planning: the two optima
// (JSON field `key`), the second checked to be ConcurrentSolver's to the bit.
std::pair<double, double> both_optima(const std::string& instance, const std::string& key) {
  const auto plan_first = ontime({"solve", instance, "--json", "--method", "memoised"});
  EXPECT_EQ(plan_first.exit_code, 0) << plan_first.err;
  const auto concurrent = ontime({"solve", instance, "--json", "--act", "concurrent"});
  EXPECT_EQ(concurrent.exit_code, 0) << concurrent.err;
  const double acting = json::parse(concurrent.out)[key].get<double>();
  const ConcurrentMdp mdp(load_problem(instance));
  ConcurrentSolver solver(mdp);
  EXPECT_EQ(acting, solver.solve(mdp.start()));
  return {json::parse(plan_first.out)[key].get<double>(), acting};
}

// Backtracking with acting while planning (SPEC §7, §10): the kitchen whose placements may blame
// their grasps is solved in the mode, and gains by it; dp and dp-rerun take it (Eq. (1) with its
// give-up term), at most the optimum, and with chains (SPEC §9) too (the devoted policy's exact
// value); an aggregation other than self with chains is refused naming the rule; the searches take
// the cup through the door (give-ups with chains), the search to the memoised bit.
TEST(Cli, SolveActsWhilePlanningWithBacktracking) {
  const std::string kitchen = testing::source_path("data/instances/kitchen-grasps.json").string();
  const auto [plan_first, acting] = both_optima(kitchen, "optimal_success_probability");
  EXPECT_GT(acting, plan_first + 0.01);
  const auto optimal = ontime({"evaluate", kitchen, "--act", "concurrent", "--solver", "optimal", "--exact", "--json"});
  ASSERT_EQ(optimal.exit_code, 0) << optimal.err;
  EXPECT_EQ(json::parse(optimal.out)["exact_success_probability"].get<double>(), acting);

  const std::string cup = testing::source_path("data/instances/chains/cup-through-the-door.json").string();
  const std::vector<std::pair<std::vector<std::string>, std::string>> refused{
      {{"evaluate", cup, "--act", "concurrent", "--solver", "dp-rerun", "--aggregation", "sum", "--episodes", "10"},
       "aggregation 'sum' has no form with chains or expiry (SPEC §9) in Eq. (1) acting while planning (SPEC §10)"},
  };
  for (const std::vector<std::string>& arguments : std::vector<std::vector<std::string>>{
           {"evaluate", cup, "--act", "concurrent", "--solver", "mcts", "--iterations", "100", "--episodes", "10"},
           {"evaluate", cup, "--act", "concurrent", "--solver", "mcts", "--iterations", "100", "--backup", "bellman",
            "--leaf", "upper", "--episodes", "10"},
           {"evaluate", cup, "--act", "concurrent", "--solver", "branch-and-bound", "--iterations", "100", "--episodes",
            "10"}}) {
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 0) << arguments[4] << ": " << result.err;
  }
  const auto memoised = ontime({"solve", cup, "--json", "--act", "concurrent"});
  const auto search = ontime({"solve", cup, "--json", "--act", "concurrent", "--method", "search"});
  ASSERT_EQ(search.exit_code, 0) << search.err;
  EXPECT_EQ(json::parse(search.out)["optimal_expected_reward"].get<double>(),
            json::parse(memoised.out)["optimal_expected_reward"].get<double>());
  for (const std::string solver : {"dp", "dp-rerun"}) {
    const auto result = ontime({"evaluate", kitchen, "--act", "concurrent", "--solver", solver, "--exact", "--json"});
    ASSERT_EQ(result.exit_code, 0) << solver << ": " << result.err;
    const double value = json::parse(result.out)["exact_success_probability"].get<double>();
    EXPECT_GT(value, 0.0) << solver;
    EXPECT_LE(value, acting + 1e-12) << solver;
  }
  // With chains and give-ups (the cup): exact values at most the optimum.
  const auto cup_optimum = ontime({"evaluate", cup, "--act", "concurrent", "--solver", "optimal", "--exact", "--json"});
  ASSERT_EQ(cup_optimum.exit_code, 0) << cup_optimum.err;
  const double optimum = json::parse(cup_optimum.out)["exact_expected_reward"].get<double>();
  for (const std::string solver : {"dp", "dp-rerun"}) {
    const auto result = ontime({"evaluate", cup, "--act", "concurrent", "--solver", solver, "--exact", "--json"});
    ASSERT_EQ(result.exit_code, 0) << solver << ": " << result.err;
    const double value = json::parse(result.out)["exact_expected_reward"].get<double>();
    EXPECT_LE(value, optimum + 1e-12) << solver;
    EXPECT_GT(value, 0.5 * optimum) << solver;
  }
  for (const auto& [arguments, message] : refused) {
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2) << arguments[1] << ": " << result.err;
    EXPECT_NE(result.err.find(message), std::string::npos) << result.err;
  }
}

// Chains with acting while planning (SPEC §9, §10): the cup carried through a door that locks at
// random is solved exactly in the mode, and the robot that may wait at the door earns more.
TEST(Cli, SolveActsWhilePlanningWithChains) {
  const std::string cup = testing::source_path("data/instances/chains/cup-through-the-door.json").string();
  const auto [plan_first, acting] = both_optima(cup, "optimal_expected_reward");
  EXPECT_GT(acting, plan_first + 0.1);
  // Its episodes (the session simulates the door) earn the optimum within 4 standard errors, and
  // the same seed gives the same bytes on one thread and two.
  const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(20'000));
  std::vector<std::string> evaluate{
      "evaluate", cup, "--act",  "concurrent",  "--solver",  "optimal", "--episodes", std::to_string(episodes),
      "--seed",   "7", "--json", "--no-timing", "--threads", "1"};
  const auto one = ontime(evaluate);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const double mean = json::parse(one.out)["mean_reward"].get<double>();
  EXPECT_NEAR(mean, acting, 4 * std::sqrt(acting * (1 - acting) / static_cast<double>(episodes)));
  evaluate.back() = "2";
  const auto two = ontime(evaluate);
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_EQ(one.out, two.out);
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

  const std::vector<json> entries = solve_policy(paper("instance1"), "solve_policy", 2);
  for (const json& entry : entries) {
    EXPECT_LE(entry["time"].get<int>(), 1);
    EXPECT_EQ(entry["refined"].size(), 4U);
    EXPECT_FALSE(entry.contains("restore"));
  }
  EXPECT_EQ(entries.size(), 1 + solved["layers"][1]["states"].get<std::size_t>());
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

// The branch-and-bound search: the layered solver's value to the bit with fewer states solved; a
// cap gives an interval around it; over MPI ranks it is refused.
TEST(Cli, SolveBySearchGivesTheLayeredBits) {
  const auto layered = ontime({"solve", paper("instance1"), "--json"});
  const auto search = ontime({"solve", paper("instance1"), "--json", "--method", "search", "--no-timing"});
  const auto capped = ontime({"solve", paper("instance1"), "--json", "--method", "search", "--max-states", "10"});
  ASSERT_EQ(layered.exit_code, 0) << layered.err;
  ASSERT_EQ(search.exit_code, 0) << search.err;
  ASSERT_EQ(capped.exit_code, 0) << capped.err;
  const json by_layers = json::parse(layered.out), by_search = json::parse(search.out), cut = json::parse(capped.out);
  EXPECT_EQ(by_search["method"], "search");
  EXPECT_EQ(by_search["optimal_success_probability"].get<double>(),
            by_layers["optimal_success_probability"].get<double>());
  EXPECT_EQ(by_search["first_choice"].get<int>(), by_layers["first_choice"].get<int>());
  EXPECT_LT(by_search["states"].get<int>(), by_layers["states"].get<int>());
  EXPECT_FALSE(by_search.contains("seconds"));
  EXPECT_FALSE(cut["exact"].get<bool>());
  EXPECT_TRUE(cut["optimal_success_probability"].is_null());
  EXPECT_EQ(cut["stopped_by"], "the cap of 10 states");
  EXPECT_LE(cut["lower_bound"].get<double>(), by_layers["optimal_success_probability"].get<double>());
  EXPECT_GE(cut["upper_bound"].get<double>(), by_layers["optimal_success_probability"].get<double>());
  EXPECT_LE(cut["states"].get<int>(), 10);  // the cap counts the states held: solved and refined
  EXPECT_EQ(cut["states"].get<int>() + cut["refined_states"].get<int>(), 10);
}

// --gap: trials until the certified interval is that narrow, no exact solve; only with search.
TEST(Cli, SolveBySearchWithAGapGivesANarrowInterval) {
  const auto narrow = ontime({"solve", paper("instance1"), "--json", "--method", "search", "--gap", "0.001"});
  ASSERT_EQ(narrow.exit_code, 0) << narrow.err;
  const json out = json::parse(narrow.out);
  EXPECT_FALSE(out["exact"].get<bool>());
  EXPECT_EQ(out["stopped_by"], "the gap");
  EXPECT_LE(out["upper_bound"].get<double>() - out["lower_bound"].get<double>(), 0.001);
  EXPECT_LE(out["lower_bound"].get<double>(), 0.942 + 1e-12);
  EXPECT_GE(out["upper_bound"].get<double>(), 0.942);
  EXPECT_EQ(out["states"], 0);
  const auto layered = ontime({"solve", paper("instance1"), "--gap", "0.001"});
  EXPECT_EQ(layered.exit_code, 2);
  EXPECT_NE(layered.err.find("--gap is for --method search"), std::string::npos) << layered.err;
  // Finer than the trials certify: refused at once rather than stopped wider than asked.
  const auto too_fine = ontime({"solve", paper("instance1"), "--method", "search", "--gap", "1e-12"});
  EXPECT_EQ(too_fine.exit_code, 2);
  EXPECT_NE(too_fine.err.find("--gap: 0 for the exact search, or at least 1e-09"), std::string::npos) << too_fine.err;
  EXPECT_TRUE(too_fine.out.empty());
}

// An instance with backtracking: the layered solver by default, the memoised solver's value to
// the bit, a policy whose states hold what a backtrack restores, an interval under a cap; a split
// or a tolerance exits with 2 naming the rule.
TEST(Cli, SolveTakesAnInstanceWithBacktracking) {
  const std::string kitchen = testing::source_path("data/instances/kitchen-grasps.json").string();
  const auto layered = ontime({"solve", kitchen, "--json"});
  const auto memoised = ontime({"solve", kitchen, "--json", "--method", "memoised"});
  ASSERT_EQ(layered.exit_code, 0) << layered.err;
  ASSERT_EQ(memoised.exit_code, 0) << memoised.err;
  const json by_layers = json::parse(layered.out), by_memo = json::parse(memoised.out);
  EXPECT_EQ(by_layers["optimal_success_probability"].get<double>(),
            by_memo["optimal_success_probability"].get<double>());
  EXPECT_NEAR(by_layers["optimal_success_probability"].get<double>(), 0.824085, 5e-7);
  EXPECT_EQ(by_layers["states"].get<int>(), by_memo["states"].get<int>());
  EXPECT_EQ(by_layers["first_choice"].get<int>(), by_memo["first_choice"].get<int>());

  const std::vector<json> entries = solve_policy(kitchen, "solve_backtracking_policy", 4);
  for (const json& entry : entries) {
    // The kitchen's blamable actions: the first grasp and the regrasp.
    ASSERT_TRUE(entry.contains("restore")) << entry.dump();
    EXPECT_EQ(entry["restore"].size(), 2U) << entry.dump();
  }
  EXPECT_GT(entries.size(), 4U);

  const auto capped = ontime({"solve", kitchen, "--json", "--max-states", "20000"});
  ASSERT_EQ(capped.exit_code, 0) << capped.err;
  const json bounded = json::parse(capped.out);
  EXPECT_FALSE(bounded["exact"].get<bool>());
  EXPECT_LE(bounded["lower_bound"].get<double>(), by_memo["optimal_success_probability"].get<double>());
  EXPECT_GE(bounded["upper_bound"].get<double>(), by_memo["optimal_success_probability"].get<double>());
  EXPECT_FALSE(bounded.contains("split"));

  const auto split = ontime({"solve", kitchen, "--method", "split"});
  EXPECT_EQ(split.exit_code, 2);
  EXPECT_NE(split.err.find("a split does not apply to an instance with backtracking"), std::string::npos) << split.err;
  const auto tolerance = ontime({"solve", kitchen, "--tolerance", "0.01"});
  EXPECT_EQ(tolerance.exit_code, 2);
  EXPECT_NE(tolerance.err.find("a tolerance does not apply"), std::string::npos) << tolerance.err;
}

// Backtracking with chains and expiry (the cup carried through a door that locks): the three
// exact methods give the same expected reward to the bit, over the same states for the layered
// and memoised solvers; a policy line names the chains' state and both kinds of restore values.
TEST(Cli, SolveTakesAnInstanceWithBacktrackingAndChains) {
  const std::string cup = testing::source_path("data/instances/chains/cup-through-the-door.json").string();
  json by_method[3];
  const char* methods[3] = {"layered", "memoised", "search"};
  for (int m = 0; m < 3; ++m) {
    const auto solved = ontime({"solve", cup, "--json", "--method", methods[m]});
    ASSERT_EQ(solved.exit_code, 0) << methods[m] << ": " << solved.err;
    by_method[m] = json::parse(solved.out);
  }
  const double optimum = by_method[0]["optimal_expected_reward"].get<double>();
  EXPECT_NEAR(optimum, 0.620783, 5e-7);
  EXPECT_EQ(by_method[1]["optimal_expected_reward"].get<double>(), optimum);
  EXPECT_EQ(by_method[2]["optimal_expected_reward"].get<double>(), optimum);
  EXPECT_EQ(by_method[0]["states"].get<int>(), by_method[1]["states"].get<int>());
  EXPECT_EQ(by_method[2]["first_choice"].get<int>(), by_method[0]["first_choice"].get<int>());

  const std::vector<json> entries = solve_policy(cup, "solve_backtracking_chains_policy", 4);
  ASSERT_GT(entries.size(), 4U);
  EXPECT_EQ(entries.front()["chains"], json({{"door", "open"}}));
  bool recorded = false;
  for (const json& entry : entries) {
    ASSERT_EQ(entry["restore"].size(), 1U) << entry.dump();  // grasp(cup), which placing may blame
    ASSERT_EQ(entry["before"].size(), 1U) << entry.dump();   // through(door), which may expire
    recorded |= entry["before"]["through(door)"].get<int>() > 0;
  }
  EXPECT_TRUE(recorded);  // the grasp's execution, once the door's move is refined
}

}  // namespace
}  // namespace ontime
