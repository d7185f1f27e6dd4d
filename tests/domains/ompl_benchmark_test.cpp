// Reads logs written by OMPL's own benchmarking tool (ompl::tools::Benchmark, from the system's
// OMPL) and checks every attempt against what the Benchmark object recorded: the number of runs,
// the solved flags, the planning times, the path lengths over the speed, and the censoring of the
// runs that found nothing at the experiment's time limit.

#include <gtest/gtest.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/tools/benchmark/Benchmark.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "ontime/learn/fitting.hpp"
#include "ontime/model/ompl_benchmark_log.hpp"

namespace ontime {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
namespace ot = ompl::tools;

std::filesystem::path scratch(const std::string& name) {
  const auto directory = std::filesystem::temp_directory_path() / ("ontime_ompl_benchmark_test_" + name);
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  return directory;
}

// From (0.1, 0.5) to (0.9, 0.5) in the unit square; with `walled`, a wall across the whole square
// at x in [0.45, 0.55] makes the goal unreachable, so that every run ends at the time limit.
struct Experiment {
  std::string name;
  bool walled = false;
  double time_limit = 0;
  unsigned runs = 0;
};

// Runs the benchmark with RRTConnect, writes its log with Benchmark::saveResultsToFile and returns
// what the Benchmark object recorded.
ot::Benchmark::CompleteExperiment run_benchmark(const Experiment& experiment, const std::filesystem::path& log) {
  auto space = std::make_shared<ob::RealVectorStateSpace>(2);
  space->setBounds(0.0, 1.0);
  og::SimpleSetup setup(space);
  const bool walled = experiment.walled;
  setup.setStateValidityChecker([walled](const ob::State* state) {
    const double x = state->as<ob::RealVectorStateSpace::StateType>()->values[0];
    return !(walled && x >= 0.45 && x <= 0.55);
  });
  ob::ScopedState<ob::RealVectorStateSpace> start(space);
  ob::ScopedState<ob::RealVectorStateSpace> goal(space);
  start[0] = 0.1;
  start[1] = 0.5;
  goal[0] = 0.9;
  goal[1] = 0.5;
  setup.setStartAndGoalStates(start, goal);

  ot::Benchmark benchmark(setup, experiment.name);
  benchmark.addPlanner(std::make_shared<og::RRTConnect>(setup.getSpaceInformation()));
  ot::Benchmark::Request request(experiment.time_limit, 4096.0, experiment.runs);
  request.displayProgress = false;
  request.saveConsoleOutput = false;
  benchmark.benchmark(request);
  EXPECT_TRUE(benchmark.saveResultsToFile(log.string().c_str()));
  return benchmark.getRecordedExperimentData();
}

class OmplBenchmark : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
    ompl::RNG::setSeed(7);
  }
};

// Checks each attempt of `runs` against the recorded run it came from.
void expect_attempts_match(const OmplBenchmarkRuns& runs, const ot::Benchmark::CompleteExperiment& recorded,
                           const std::string& action, double speed) {
  ASSERT_EQ(recorded.planners.size(), 1u);
  const auto& planner = recorded.planners[0];
  ASSERT_EQ(runs.attempts.size(), planner.runs.size());
  EXPECT_EQ(runs.experiment, recorded.name);
  EXPECT_EQ(runs.time_limit_seconds, recorded.maxTime);
  for (std::size_t i = 0; i < planner.runs.size(); ++i) {
    const auto& run = planner.runs[i];
    const RefinementAttempt& attempt = runs.attempts[i];
    EXPECT_EQ(attempt.action, action);
    // OMPL records the values as the text it writes: the log holds exactly these numbers.
    const double time = std::stod(run.at("time REAL"));
    const bool solved = run.at("solved BOOLEAN") == "1";
    EXPECT_EQ(attempt.found, solved && time <= recorded.maxTime) << "run " << i;
    if (attempt.found) {
      EXPECT_EQ(attempt.planning_seconds, time) << "run " << i;
      EXPECT_EQ(attempt.execution_seconds, std::stod(run.at("solution length REAL")) / speed) << "run " << i;
    } else {
      EXPECT_EQ(attempt.planning_seconds, recorded.maxTime) << "run " << i;
      EXPECT_EQ(attempt.execution_seconds, 0.0) << "run " << i;
    }
    EXPECT_FALSE(attempt.trial.has_value());
    EXPECT_FALSE(attempt.collision_checks.has_value());
  }
}

TEST_F(OmplBenchmark, SolvedRunsGiveTheirTimesAndPathLengthsOverTheSpeed) {
  const std::filesystem::path dir = scratch("open");
  const auto recorded = run_benchmark({"open", false, 1.0, 5}, dir / "open.log");
  ASSERT_EQ(recorded.planners.at(0).runs.size(), 5u);
  OmplLogReadOptions options;
  options.speed = 0.25;
  options.action = "move(A,B)";
  const OmplBenchmarkRuns runs = load_ompl_benchmark_log(dir / "open.log", options);
  expect_attempts_match(runs, recorded, "move(A,B)", 0.25);
  // An open square: RRTConnect finds every path well within a second, none shorter than the
  // straight line of 0.8.
  for (const RefinementAttempt& attempt : runs.attempts) {
    EXPECT_TRUE(attempt.found);
    EXPECT_GE(attempt.execution_seconds, 0.8 / 0.25 * (1 - 1e-6));
  }
  EXPECT_EQ(recorded.planners[0].name, "geometric_RRTConnect");
  // Without an action or a mapping the planner's name is the action.
  const OmplBenchmarkRuns by_planner = load_ompl_benchmark_log(dir / "open.log", {});
  expect_attempts_match(by_planner, recorded, "geometric_RRTConnect", 1.0);
}

TEST_F(OmplBenchmark, RunsThatFindNothingAreCensoredAtTheTimeLimit) {
  const std::filesystem::path dir = scratch("walled");
  const auto recorded = run_benchmark({"walled", true, 0.05, 3}, dir / "walled.log");
  ASSERT_EQ(recorded.planners.at(0).runs.size(), 3u);
  const OmplBenchmarkRuns runs = load_ompl_benchmark_log(dir / "walled.log", {});
  expect_attempts_match(runs, recorded, "geometric_RRTConnect", 1.0);
  for (std::size_t i = 0; i < runs.attempts.size(); ++i) {
    EXPECT_EQ(recorded.planners[0].runs[i].at("solved BOOLEAN"), "0");
    // The planner searched until it was stopped at the limit.
    EXPECT_GE(std::stod(recorded.planners[0].runs[i].at("time REAL")), 0.05);
    EXPECT_FALSE(runs.attempts[i].found);
    EXPECT_EQ(runs.attempts[i].planning_seconds, 0.05);
  }
}

TEST_F(OmplBenchmark, AMappingNamesTheActionOfEachExperimentAndTheFitUsesBoth) {
  const std::filesystem::path dir = scratch("mapping");
  const auto open = run_benchmark({"open", false, 1.0, 4}, dir / "open.log");
  const auto walled = run_benchmark({"walled", true, 0.05, 2}, dir / "walled.log");
  std::ofstream(dir / "mapping.json") << R"json({"rules": [
    {"experiment": "walled", "planner": "geometric_RRTConnect", "action": "move(B,C)"},
    {"planner": "geometric_RRTConnect", "action": "move(A,B)"}]})json";
  const OmplActionMapping mapping = load_ompl_action_mapping(dir / "mapping.json");
  OmplLogReadOptions options;
  options.mapping = &mapping;
  const OmplBenchmarkRuns open_runs = load_ompl_benchmark_log(dir / "open.log", options);
  const OmplBenchmarkRuns walled_runs = load_ompl_benchmark_log(dir / "walled.log", options);
  expect_attempts_match(open_runs, open, "move(A,B)", 1.0);
  expect_attempts_match(walled_runs, walled, "move(B,C)", 1.0);

  std::vector<RefinementAttempt> attempts = open_runs.attempts;
  attempts.insert(attempts.end(), walled_runs.attempts.begin(), walled_runs.attempts.end());
  FitOptions fit_options;
  fit_options.step_seconds = 1.0;
  fit_options.deadline = 10;
  fit_options.name = "ompl";
  const FitResult fit =
      fit_problem(attempts, "open.log, walled.log", {"skeletons", {{"move(A,B)", "move(B,C)"}}}, fit_options);
  ASSERT_EQ(fit.actions.size(), 2u);
  EXPECT_EQ(fit.actions[0].id, "move(A,B)");
  EXPECT_EQ(fit.actions[0].attempts, 4u);
  EXPECT_EQ(fit.actions[0].found, 4u);
  EXPECT_EQ(fit.actions[1].id, "move(B,C)");
  EXPECT_EQ(fit.actions[1].attempts, 2u);
  EXPECT_EQ(fit.actions[1].censored, 2u);
}

}  // namespace
}  // namespace ontime
