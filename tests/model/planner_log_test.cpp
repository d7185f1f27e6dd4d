#include "ontime/model/planner_log.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "ontime/util/error.hpp"
#include "support/bad_logs.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

TEST(PlannerLog, ReadsEveryFieldAndSkipsBlankLines) {
  const std::vector<RefinementAttempt> log = parse_planner_log(
      "{\"action\": \"move(R1,R5)\", \"planning_seconds\": 1.25, \"found\": true, \"execution_seconds\": 6.5}\n"
      "\n"
      "{\"action\": \"move(R5,R8)\", \"trial\": 7, \"planning_seconds\": 44, \"found\": false, \"collision_checks\": "
      "88000}\n",
      "log");
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log[0].action, "move(R1,R5)");
  EXPECT_DOUBLE_EQ(log[0].planning_seconds, 1.25);
  EXPECT_TRUE(log[0].found);
  EXPECT_DOUBLE_EQ(log[0].execution_seconds, 6.5);
  EXPECT_FALSE(log[0].trial.has_value());
  EXPECT_FALSE(log[1].found);
  EXPECT_DOUBLE_EQ(log[1].planning_seconds, 44.0);
  EXPECT_EQ(log[1].trial, 7u);
  EXPECT_EQ(log[1].collision_checks, 88000u);
}

TEST(PlannerLog, WritesWhatItReads) {
  RefinementAttempt found{"a", 0.1 + 0.2, true, 1.0 / 3.0, 12, 3456, std::nullopt, {}, std::nullopt};
  RefinementAttempt cut_off{"b(x,y)", 44.0, false, 0.0, std::nullopt, std::nullopt, std::nullopt, {}, std::nullopt};
  const std::string text = planner_log_line(found) + planner_log_line(cut_off);
  const std::vector<RefinementAttempt> back = parse_planner_log(text, "log");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0], found);  // doubles round-trip exactly
  EXPECT_EQ(back[1], cut_off);
}

// A corpus across worlds: records name their world and carry the action's features there; a
// log without them (every log before) reads as before.
TEST(PlannerLog, WorldAndFeaturesAreReadAndWrittenBack) {
  const RefinementAttempt found{"move(R1,R2)",        3.5,         true, 6.25, 4, std::nullopt, "building-s7",
                                {0.92, -0.125, 16.0}, std::nullopt};
  const std::string line = planner_log_line(found);
  EXPECT_EQ(line, R"x({"action":"move(R1,R2)","trial":4,"planning_seconds":3.5,"found":true,"execution_seconds":6.25,)x"
                  R"x("world":"building-s7","features":[0.92,-0.125,16.0]})x"
                  "\n");
  const std::vector<RefinementAttempt> back = parse_planner_log(line, "log");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0], found);
  const std::vector<RefinementAttempt> plain =
      parse_planner_log(R"({"action": "a", "planning_seconds": 1.5, "found": false})", "log");
  EXPECT_FALSE(plain[0].world);
  EXPECT_TRUE(plain[0].features.empty());
}

TEST(PlannerLog, EveryBadLogNamesItsLineAndRule) {
  for (const testing::BadInput& bad : testing::kBadLogs) {
    const std::filesystem::path path = testing::source_path("tests/data/bad_logs/" + bad.file);
    try {
      load_planner_log(path);
      ADD_FAILURE() << bad.file << " was accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), path.string()) << bad.file;
      EXPECT_EQ(error.place(), bad.place) << bad.file << ": " << error.what();
      EXPECT_NE(error.rule().find(bad.rule), std::string::npos) << bad.file << ": " << error.what();
    }
  }
}

TEST(PlannerLog, AMissingFileIsAnInputError) { EXPECT_THROW(load_planner_log("/nonexistent/log.jsonl"), InputError); }

// nlohmann reads a NUL byte as the end of the input: a line cut there must not pass.
TEST(PlannerLog, ANulByteInALineIsRefusedWithItsLineAndColumn) {
  using namespace std::string_literals;
  const std::string text =
      "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": false}\n"
      "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": false}\0garbage\n"s;
  try {
    parse_planner_log(text, "log");
    ADD_FAILURE() << "a NUL byte was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "line 2, column 55");
    EXPECT_NE(error.rule().find("NUL byte"), std::string::npos) << error.rule();
  }
}

TEST(PlannerLog, CountsMayBeWrittenWithAZeroFraction) {
  const auto log = parse_planner_log(R"({"action": "a", "planning_seconds": 1, "found": false, "trial": 3.0})", "log");
  ASSERT_TRUE(log.at(0).trial.has_value());
  EXPECT_EQ(*log.at(0).trial, 3U);
  EXPECT_THROW(parse_planner_log(R"({"action": "a", "planning_seconds": 1, "found": false, "trial": 3.5})", "log"),
               InputError);
}

}  // namespace
}  // namespace ontime
