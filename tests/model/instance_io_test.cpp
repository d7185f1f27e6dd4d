#include "ontime/model/instance_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"
#include "support/bad_inputs.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

TEST(InstanceIo, LoadsFigureOne) {
  const Problem problem = testing::paper_instance("figure1");
  EXPECT_EQ(problem.name(), "paper-figure-1");
  EXPECT_EQ(problem.deadline(), 5);
  EXPECT_DOUBLE_EQ(problem.step_seconds(), 1.0);  // default when absent
  EXPECT_EQ(problem.action_count(), 4);
  const Action& d1 = problem.action(problem.find_action("d1"));
  EXPECT_DOUBLE_EQ(d1.planning.pmf(1), 0.5);
  EXPECT_DOUBLE_EQ(d1.planning.pmf(4), 0.5);
  EXPECT_DOUBLE_EQ(d1.execution.pmf(10), 0.5);
}

TEST(InstanceIo, LoadsEveryPaperInstanceWithItsDeadline) {
  const std::map<std::string, Steps> deadlines{
      {"instance1", 14}, {"instance2", 9}, {"instance3", 20}, {"instance4", 4}, {"instance5", 14}};
  for (const auto& [name, deadline] : deadlines) {
    EXPECT_EQ(testing::paper_instance(name).deadline(), deadline) << name;
  }
}

TEST(InstanceIo, ReadsTheCdfFormOfTheSpecExample) {
  const Problem problem = parse_problem(R"({
    "name": "paper-instance-4", "deadline": 4, "step_seconds": 1.0,
    "actions": {
      "a1": {"planning": {"pmf": {"1": 0.3, "2": 0.15, "3": 0.1, "4": 0.15, "5": 0.3}}, "execution": {"pmf": {"1": 1.0}}},
      "a2": {"planning": {"cdf": {"2": 0.1, "3": 0.9, "4": 1.0}}, "execution": {"pmf": {"1": 1.0}}}
    },
    "skeletons": [["a1"], ["a2"]]})",
                                        "spec-example");
  const Distribution& planning = problem.action(problem.find_action("a2")).planning;
  EXPECT_DOUBLE_EQ(planning.pmf(2), 0.1);
  EXPECT_DOUBLE_EQ(planning.pmf(3), 0.8);
  EXPECT_NEAR(planning.pmf(4), 0.1, 1e-15);
  EXPECT_NEAR(planning.never(), 0.0, 1e-15);
}

TEST(InstanceIo, MissingMassIsNever) {
  const Problem problem = parse_problem(
      R"({"deadline": 3, "actions": {"a": {"planning": {"pmf": {"2": 0.6}}, "execution": {"pmf": {}}}}, "skeletons": [["a"]]})",
      "never.json");
  EXPECT_DOUBLE_EQ(problem.action(0).planning.never(), 0.4);
  EXPECT_DOUBLE_EQ(problem.action(0).execution.never(), 1.0);
  EXPECT_EQ(problem.name(), "never");  // defaults to the file's stem
}

TEST(InstanceIo, WritesWhatItReads) {
  for (const char* name : {"figure1", "instance1", "instance3"}) {
    const Problem original = testing::paper_instance(name);
    const Problem copy = parse_problem(problem_to_json(original), "copy");
    ASSERT_EQ(copy.action_count(), original.action_count());
    ASSERT_EQ(copy.skeleton_count(), original.skeleton_count());
    EXPECT_EQ(copy.deadline(), original.deadline());
    EXPECT_EQ(copy.name(), original.name());
    for (int a = 0; a < original.action_count(); ++a) {
      EXPECT_EQ(copy.action(a).id, original.action(a).id);
      EXPECT_EQ(copy.action(a).planning, original.action(a).planning);
      EXPECT_EQ(copy.action(a).execution, original.action(a).execution);
    }
    for (int k = 0; k < original.skeleton_count(); ++k) {
      EXPECT_TRUE(std::ranges::equal(copy.skeleton(k), original.skeleton(k)));
    }
  }
}

TEST(InstanceIo, SaveReplacesTheFileWhole) {
  const auto directory = std::filesystem::temp_directory_path() / "ontime_instance_io_test";
  std::filesystem::create_directories(directory);
  const auto path = directory / "saved.json";
  std::ofstream(path) << "old content";
  const Problem problem = testing::paper_instance("instance2");
  save_problem(problem, path);
  EXPECT_EQ(load_problem(path).deadline(), 9);
  std::size_t leftovers = 0;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) leftovers += entry.path() != path;
  EXPECT_EQ(leftovers, 0U);
  std::filesystem::remove_all(directory);
}

TEST(InstanceIo, MissingFileIsAnInputError) {
  try {
    load_problem("/nonexistent/instance.json");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "/nonexistent/instance.json");
    EXPECT_NE(error.rule().find("cannot be opened"), std::string::npos);
  }
}

// Inputs that once crashed the instance fuzzer: each must now load or fail with InputError.
TEST(InstanceIo, FuzzRegressionsAreHandled) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(testing::source_path("tests/data/fuzz_regressions"))) {
    if (entry.path().filename().string().rfind("instance_", 0) != 0) continue;
    ++files;
    try {
      load_problem(entry.path());
    } catch (const InputError& error) {
      EXPECT_FALSE(error.place().empty()) << entry.path();
    }
  }
  EXPECT_GT(files, 0);
}

// Every file of tests/data/bad is rejected with its expected place and rule.
TEST(InstanceIo, EveryBadFileNamesItsPlaceAndRule) {
  std::set<std::string> covered;
  for (const testing::BadInput& bad : testing::kBadInputs) {
    covered.insert(bad.file);
    const auto path = testing::source_path("tests/data/bad/" + bad.file);
    try {
      load_problem(path);
      ADD_FAILURE() << bad.file << " was accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), path.string()) << bad.file;
      EXPECT_EQ(error.place(), bad.place) << bad.file;
      EXPECT_NE(error.rule().find(bad.rule), std::string::npos) << bad.file << ": " << error.rule();
    }
  }
  for (const auto& entry : std::filesystem::directory_iterator(testing::source_path("tests/data/bad"))) {
    EXPECT_TRUE(covered.contains(entry.path().filename().string()))
        << entry.path().filename() << " has no expectation in support/bad_inputs.hpp";
  }
}

// Skeleton indices are 16-bit: one more skeleton than that is refused by the reader, before the
// skeletons themselves are read. Hundreds load (wide_problem_test.cpp).
TEST(InstanceIo, MoreSkeletonsThanIndicesCanNameAreRefused) {
  std::string text = R"({"deadline": 4, "step_seconds": 1.0, "actions": {"x": {"planning": {"pmf": {"1": 1.0}},
      "execution": {"pmf": {"1": 1.0}}}}, "skeletons": [)";
  for (int k = 0; k <= Problem::kMaxSkeletons; ++k) text += k == 0 ? R"(["x"])" : R"(,["x"])";
  text += "]}";
  try {
    parse_problem(text, "many.json");
    ADD_FAILURE() << "65,536 skeletons were accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "skeletons");
    EXPECT_NE(error.rule().find("at most 65535 skeletons"), std::string::npos) << error.rule();
  }
}

// Restores the process-wide input size limit when a test ends.
struct InputLimitGuard {
  explicit InputLimitGuard(std::uint64_t bytes) { set_max_input_bytes(bytes); }
  ~InputLimitGuard() { set_max_input_bytes(std::nullopt); }
  InputLimitGuard(const InputLimitGuard&) = delete;
  InputLimitGuard& operator=(const InputLimitGuard&) = delete;
};

TEST(InputFile, ADeviceWithoutEndIsReadOnlyUpToTheLimit) {
  const InputLimitGuard limit(std::uint64_t{1} << 20);
  try {
    load_problem("/dev/zero");
    ADD_FAILURE() << "/dev/zero was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "/dev/zero");
    EXPECT_EQ(error.place(), "file");
    EXPECT_EQ(error.rule(),
              "the instance file is larger than the input size limit of 1048576 bytes (1 MiB) (set "
              "ONTIME_MAX_INPUT_BYTES to raise it)");
  }
}

TEST(InputFile, ARegularFileAboveTheLimitIsRefusedAndOneAtTheLimitIsRead) {
  const auto path = std::filesystem::temp_directory_path() / "ontime_input_limit_test.json";
  const std::string text = read_input_file(testing::source_path("data/instances/paper/figure1.json"), "instance");
  {
    std::ofstream out(path, std::ios::binary);
    out << text;
  }
  {
    const InputLimitGuard limit(text.size());
    EXPECT_EQ(read_input_file(path, "instance"), text);
    EXPECT_EQ(load_problem(path).name(), "paper-figure-1");
  }
  {
    const InputLimitGuard limit(text.size() - 1);
    EXPECT_THROW(load_problem(path), InputError);
  }
  std::filesystem::remove(path);
}

TEST(InputFile, TheLimitComesFromTheEnvironmentWhenNotSet) {
  ASSERT_EQ(::setenv("ONTIME_MAX_INPUT_BYTES", "4096", 1), 0);
  EXPECT_EQ(max_input_bytes(), 4096U);
  ASSERT_EQ(::setenv("ONTIME_MAX_INPUT_BYTES", "4k", 1), 0);
  EXPECT_THROW(max_input_bytes(), UsageError);
  ASSERT_EQ(::setenv("ONTIME_MAX_INPUT_BYTES", "0", 1), 0);
  EXPECT_THROW(max_input_bytes(), UsageError);
  ASSERT_EQ(::unsetenv("ONTIME_MAX_INPUT_BYTES"), 0);
  EXPECT_EQ(max_input_bytes(), kDefaultMaxInputBytes);
}

constexpr const char* kOneAction = R"("a": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}}})";

TEST(InstanceIo, ANulByteAfterTheInstanceIsRefusedWithItsPlace) {
  using namespace std::string_literals;
  const std::string text =
      "{\"deadline\": 3, \"actions\": {"s + kOneAction + "}, \"skeletons\": [[\"a\"]]}\n\0garbage"s;
  try {
    parse_problem(text, "nul.json");
    ADD_FAILURE() << "trailing NUL and garbage were accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "line 2, column 1");
    EXPECT_NE(error.rule().find("NUL byte"), std::string::npos) << error.rule();
  }
}

TEST(InstanceIo, AControlByteInAKeyIsShownEscapedAndTheRuleKept) {
  const std::string text = R"({"dead\u0000line": 3})";
  try {
    parse_problem(text, "key.json");
    ADD_FAILURE() << "an unknown key was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), R"("dead\u0000line")");
    const std::string message = error.what();
    EXPECT_EQ(message.find('\0'), std::string::npos);
    EXPECT_NE(message.find(R"(key.json: "dead\u0000line": unknown key (expected 'name')"), std::string::npos)
        << message;
  }
}

// Loading is linear in the size of the file (bench/ontime_bench.cpp measures it); here: a large
// object is read whole, in order, and a duplicate at its end is still found with its path.
TEST(InstanceIo, AnObjectOfManyKeysIsReadInOrderAndDuplicatesAreFound) {
  const int unused = testing::repetitions_to_check(100000);
  std::string actions = kOneAction;
  for (int i = 0; i < unused; ++i) {
    actions +=
        ", \"u" + std::to_string(i) + R"(": {"planning": {"pmf": {"2": 0.5}}, "execution": {"pmf": {"1": 1.0}}})";
  }
  const std::string text = R"({"deadline": 3, "actions": {)" + actions + R"(}, "skeletons": [["a"]]})";
  const Problem problem = parse_problem(text, "many.json");
  ASSERT_EQ(problem.action_count(), unused + 1);
  EXPECT_EQ(problem.action(0).id, "a");
  EXPECT_EQ(problem.action(unused).id, "u" + std::to_string(unused - 1));
  EXPECT_DOUBLE_EQ(problem.action(unused).planning.pmf(2), 0.5);

  const std::string duplicated = R"({"deadline": 3, "actions": {)" + actions + ", " + kOneAction + "}}";
  try {
    parse_problem(duplicated, "many.json");
    ADD_FAILURE() << "a duplicate key was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "actions.a");
    EXPECT_NE(error.rule().find("duplicate key"), std::string::npos) << error.rule();
  }
}

std::string instance_with(const std::string& members) {
  return "{" + members + R"(, "actions": {)" + kOneAction + R"(}, "skeletons": [["a"]]})";
}

std::string rule_for(const std::string& text) {
  try {
    parse_problem(text, "x.json");
  } catch (const InputError& error) {
    return error.place() + ": " + error.rule();
  }
  return "accepted";
}

TEST(InstanceIo, AWholeNumberWrittenWithAZeroFractionIsAnInteger) {
  EXPECT_EQ(parse_problem(instance_with(R"("deadline": 4.0)"), "x.json").deadline(), 4);
  EXPECT_EQ(parse_problem(instance_with(R"("deadline": 4e0)"), "x.json").deadline(), 4);
  EXPECT_EQ(rule_for(instance_with(R"("deadline": 4.5)")), "deadline: must be a whole number of steps (got 4.5)");
  EXPECT_EQ(rule_for(instance_with(R"("deadline": 1e300)")),
            "deadline: must be between 1 and 10000 steps (got 1e+300)");
  EXPECT_EQ(rule_for(instance_with(R"("deadline": 18446744073709551615)")),
            "deadline: must be between 1 and 10000 steps (got 18446744073709551615)");
}

TEST(InstanceIo, StepSecondsKeepEveryTimeFinite) {
  EXPECT_EQ(rule_for(instance_with(R"("deadline": 3, "step_seconds": 1e308)")),
            "step_seconds: must be a positive number of seconds, at most 1e300 so that times in seconds stay finite "
            "(got 1e+308)");
  EXPECT_DOUBLE_EQ(parse_problem(instance_with(R"("deadline": 3, "step_seconds": 1e300)"), "x.json").step_seconds(),
                   1e300);
}

}  // namespace
}  // namespace ontime

namespace ontime {
namespace {

// Rewards (SPEC §8): a number or {"value", "per_step"} per skeleton; written back as read, and not
// written at all when every skeleton is worth 1.
TEST(InstanceIo, TheActingModeReadsAndWritesBack) {
  const Problem plan_first = testing::paper_instance("instance4");
  EXPECT_EQ(plan_first.acting(), Acting::plan_first);
  // The default is not written, so that a plan-first instance writes as it did before the field.
  EXPECT_EQ(problem_to_json(plan_first).find("acting"), std::string::npos);
  const Problem concurrent = plan_first.with_acting(Acting::concurrent);
  const std::string text = problem_to_json(concurrent);
  EXPECT_NE(text.find(R"("acting": "concurrent")"), std::string::npos) << text;
  EXPECT_EQ(parse_problem(text, "written").acting(), Acting::concurrent);
  EXPECT_EQ(problem_to_json(parse_problem(text, "written")), text);
  std::string spelled = problem_to_json(plan_first);
  spelled.insert(1, R"("acting": "plan-first",)");
  EXPECT_EQ(parse_problem(spelled, "spelled").acting(), Acting::plan_first);
}

TEST(InstanceIo, RewardsReadAndWriteBack) {
  const std::string text = R"({"deadline": 6, "actions": {
      "a": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}}},
      "b": {"planning": {"pmf": {"2": 1.0}}, "execution": {"pmf": {"0": 1.0}}}},
      "skeletons": [["a"], ["b"]], "rewards": [0.7, {"value": 1.0, "per_step": 0.125}]})";
  const Problem problem = parse_problem(text, "coffee.json");
  ASSERT_TRUE(problem.has_rewards());
  EXPECT_EQ(problem.reward(0), (SkeletonReward{0.7, 0.0}));
  EXPECT_EQ(problem.reward(1), (SkeletonReward{1.0, 0.125}));
  EXPECT_EQ(problem.reward_at(1, 4), 0.5);
  EXPECT_EQ(problem.reward_at(0, 6), 0.7);
  EXPECT_EQ(problem.max_reward(), 1.0);
  const Problem again = parse_problem(problem_to_json(problem), "again.json");
  EXPECT_EQ(std::vector<SkeletonReward>(again.rewards().begin(), again.rewards().end()),
            std::vector<SkeletonReward>(problem.rewards().begin(), problem.rewards().end()));
  const std::string plain = R"({"deadline": 6, "actions": {
      "a": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}}}}, "skeletons": [["a"]],
      "rewards": [1]})";
  const Problem unit = parse_problem(plain, "unit.json");
  EXPECT_FALSE(unit.has_rewards());
  EXPECT_EQ(problem_to_json(unit).find("rewards"), std::string::npos);
}

}  // namespace
}  // namespace ontime
