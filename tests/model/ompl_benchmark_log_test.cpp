#include "ontime/model/ompl_benchmark_log.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>

#include "ontime/learn/fitting.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/util/error.hpp"
#include "support/bad_ompl_logs.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

std::filesystem::path kitchen() { return testing::source_path("tests/data/ompl_logs/kitchen.log"); }

RefinementAttempt found(std::string action, double planning, double execution) {
  return {std::move(action), planning, true, execution, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt};
}
RefinementAttempt cut_off(std::string action, double planning) {
  return {std::move(action), planning, false, 0.0, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt};
}

TEST(OmplBenchmarkLog, ReadsEveryRunOfEveryPlannerAndCensorsAtTheTimeLimit) {
  OmplLogReadOptions options;
  options.speed = 0.5;
  const OmplBenchmarkRuns runs = load_ompl_benchmark_log(kitchen(), options);
  EXPECT_EQ(runs.experiment, "kitchen");
  EXPECT_EQ(runs.time_limit_seconds, 2.0);
  const std::vector<RefinementAttempt> expected{
      found("geometric_RRTConnect", 0.125, 6.5), cut_off("geometric_RRTConnect", 2.0),  // not solved (after 2.00031 s)
      found("geometric_RRTConnect", 1.75, 9.0),  found("geometric_RRTstar", 0.5, 10.0),
      cut_off("geometric_RRTstar", 2.0),  // an approximate solution is not solved
      cut_off("geometric_RRTstar", 2.0),  // solved, but after 2.25 s: beyond the limit
  };
  EXPECT_EQ(runs.attempts, expected);
}

TEST(OmplBenchmarkLog, AFixedActionNamesEveryRun) {
  OmplLogReadOptions options;
  options.action = "move(R1,R2)";
  const OmplBenchmarkRuns runs = load_ompl_benchmark_log(kitchen(), options);
  ASSERT_EQ(runs.attempts.size(), 6u);
  for (const RefinementAttempt& attempt : runs.attempts) EXPECT_EQ(attempt.action, "move(R1,R2)");
  EXPECT_EQ(runs.attempts[0].execution_seconds, 3.25);  // speed 1: the solution length
}

TEST(OmplBenchmarkLog, TheFirstMatchingRuleOfAMappingNamesAPlannersAction) {
  const OmplActionMapping mapping = parse_ompl_action_mapping(R"json({"rules": [
      {"experiment": "hallway", "action": "never"},
      {"experiment": "kitchen", "planner": "geometric_RRTstar", "action": "pick(cup)"},
      {"experiment": "kitchen", "action": "move(R1,R2)"},
      {"planner": "geometric_RRTstar", "action": "also never"}]})json",
                                                              "mapping.json");
  ASSERT_EQ(mapping.rules.size(), 4u);
  EXPECT_EQ(mapping.rules[1], (OmplActionRule{"kitchen", "geometric_RRTstar", "pick(cup)"}));
  OmplLogReadOptions options;
  options.mapping = &mapping;
  const OmplBenchmarkRuns runs = load_ompl_benchmark_log(kitchen(), options);
  ASSERT_EQ(runs.attempts.size(), 6u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(runs.attempts[i].action, "move(R1,R2)");
  for (std::size_t i = 3; i < 6; ++i) EXPECT_EQ(runs.attempts[i].action, "pick(cup)");
}

TEST(OmplBenchmarkLog, APlannerNoRuleMatchesIsRefusedAtItsLine) {
  const OmplActionMapping mapping =
      parse_ompl_action_mapping(R"({"rules": [{"planner": "geometric_RRTConnect", "action": "a"}]})", "map.json");
  OmplLogReadOptions options;
  options.mapping = &mapping;
  try {
    load_ompl_benchmark_log(kitchen(), options);
    ADD_FAILURE() << "a planner without an action was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), kitchen().string());
    EXPECT_EQ(error.place(), "line 37");
    EXPECT_EQ(error.rule(),
              "no rule of the mapping map.json matches experiment 'kitchen', planner 'geometric_RRTstar'");
  }
}

TEST(OmplBenchmarkLog, BadMappingsNameTheirPlaceAndRule) {
  const auto expect_refused = [](const std::string& text, const std::string& place, const std::string& rule) {
    try {
      parse_ompl_action_mapping(text, "map.json");
      ADD_FAILURE() << text << " was accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), "map.json");
      EXPECT_EQ(error.place(), place) << error.what();
      EXPECT_NE(error.rule().find(rule), std::string::npos) << error.what();
    }
  };
  expect_refused(R"([])", "top level", "must be a JSON object");
  expect_refused(R"({})", "top level", "missing required key 'rules'");
  expect_refused(R"({"rules": []})", "rules", "at least one rule");
  expect_refused(R"({"rules": [{"action": "a"}]})", "rules[0]", "name an 'experiment', a 'planner' or both");
  expect_refused(R"({"rules": [{"planner": "p"}]})", "rules[0]", "missing required key 'action'");
  expect_refused(R"({"rules": [{"planner": "p", "action": ""}]})", "rules[0].action", "must not be empty");
  expect_refused(R"({"rules": [{"planner": 3, "action": "a"}]})", "rules[0].planner", "must be a string");
  expect_refused(R"({"rules": [{"planer": "p", "action": "a"}]})", "rules[0].planer", "unknown key");
}

TEST(OmplBenchmarkLog, EveryBadLogNamesItsLineAndRule) {
  for (const testing::BadInput& bad : testing::kBadOmplLogs) {
    const std::filesystem::path path = testing::source_path("tests/data/bad_ompl_logs/" + bad.file);
    try {
      load_ompl_benchmark_log(path, {});
      ADD_FAILURE() << bad.file << " was accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), path.string()) << bad.file;
      EXPECT_EQ(error.place(), bad.place) << bad.file << ": " << error.what();
      EXPECT_NE(error.rule().find(bad.rule), std::string::npos) << bad.file << ": " << error.what();
      EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << bad.file << ": " << error.what();
    }
  }
}

TEST(OmplBenchmarkLog, ASpeedThatIsNotPositiveIsAUsageError) {
  for (const double speed : {0.0, -1.0, std::numeric_limits<double>::infinity()}) {
    OmplLogReadOptions options;
    options.speed = speed;
    EXPECT_THROW(load_ompl_benchmark_log(kitchen(), options), UsageError) << speed;
  }
}

TEST(OmplBenchmarkLog, WhatItWritesReadsBackAsTheSameAttempts) {
  const std::vector<RefinementAttempt> attempts{
      {"move(R1,R2)", 0.1 + 0.2, true, 1.0 / 3.0, 0, 1234, std::nullopt, {}, std::nullopt},
      {"move(R2,R3)", 6.0, false, 0.0, 0, 5000, std::nullopt, {}, std::nullopt},
      {"move(R1,R2)", 6.0, false, 0.0, 1, std::nullopt, std::nullopt, {}, std::nullopt},
      {"move(R2,R3)", 6.0, true, 2.5e-7, std::nullopt, 77, std::nullopt, {}, std::nullopt},  // found at exactly the
                                                                                             // limit: within it
  };
  OmplLogWriteOptions options;
  options.experiment = "navigation";
  options.time_limit_seconds = 6.0;
  options.setup = "two lines\nof setup";
  const std::string text = ompl_benchmark_log_text(attempts, options);
  const OmplBenchmarkRuns back = parse_ompl_benchmark_log(text, "written.log", {});
  EXPECT_EQ(back.experiment, "navigation");
  EXPECT_EQ(back.time_limit_seconds, 6.0);
  // Planner by planner: the runs of move(R1,R2), then those of move(R2,R3).
  const std::vector<RefinementAttempt> expected{attempts[0], attempts[2], attempts[1], attempts[3]};
  EXPECT_EQ(back.attempts, expected);
  EXPECT_NE(text.find("2 planners\nmove(R1,R2)\n0 common properties\n5 properties for each run\n"
                      "collision checks INTEGER\nsolution length REAL\nsolved BOOLEAN\ntime REAL\ntrial INTEGER\n"
                      "2 runs\n1234; 0.3333333333333333; 1; 0.30000000000000004; 0; \n; ; 0; 6; 1; \n.\n"),
            std::string::npos)
      << text;
}

// A collection's cut-off attempts stop at the first check past the cut-off; read back, they are
// censored at exactly the cut-off, which fits the same instance.
TEST(OmplBenchmarkLog, ACollectionLogReadBackFitsTheSameInstance) {
  const std::vector<RefinementAttempt> attempts{
      {"a", 1.5, true, 4.0, 0, std::nullopt, std::nullopt, {}, std::nullopt},
      {"a", 5.000013, false, 0.0, 1, std::nullopt, std::nullopt, {}, std::nullopt},
      {"a", 2.9, true, 3.1, 2, std::nullopt, std::nullopt, {}, std::nullopt},
      {"b", 5.2, false, 0.0, 0, std::nullopt, std::nullopt, {}, std::nullopt},
      {"b", 0.25, true, 7.5, 1, std::nullopt, std::nullopt, {}, std::nullopt},
      {"b", 4.0, true, 1.0, 2, std::nullopt, std::nullopt, {}, std::nullopt},
  };
  OmplLogWriteOptions write;
  write.time_limit_seconds = 5.0;
  const OmplBenchmarkRuns back = parse_ompl_benchmark_log(ompl_benchmark_log_text(attempts, write), "log", {});
  ASSERT_EQ(back.attempts.size(), attempts.size());
  EXPECT_EQ(back.attempts[1].planning_seconds, 5.0);
  EXPECT_EQ(back.attempts[3].planning_seconds, 5.0);
  FitOptions fit;
  fit.step_seconds = 1.0;
  fit.deadline = 5;
  fit.laplace = 0.5;
  fit.name = "x";
  const SkeletonList skeletons{"skeletons", {{"a", "b"}}};
  EXPECT_EQ(problem_to_json(fit_problem(back.attempts, "log", skeletons, fit).problem),
            problem_to_json(fit_problem(attempts, "log", skeletons, fit).problem));
}

TEST(OmplBenchmarkLog, TheWriterRefusesWhatCannotBeOneLine) {
  OmplLogWriteOptions options;
  options.time_limit_seconds = 1.0;
  EXPECT_THROW(ompl_benchmark_log_text(std::vector{cut_off("a\nb", 1.0)}, options), UsageError);
  EXPECT_THROW(ompl_benchmark_log_text(std::vector{cut_off("a\r", 1.0)}, options), UsageError);
  options.experiment = "";
  EXPECT_THROW(ompl_benchmark_log_text(std::vector{cut_off("a", 1.0)}, options), UsageError);
  options.experiment = "x";
  options.time_limit_seconds = 0;
  EXPECT_THROW(ompl_benchmark_log_text(std::vector{cut_off("a", 1.0)}, options), UsageError);
}

}  // namespace
}  // namespace ontime
