// CLI tests of what every command shares: usage errors in one line with exit 2, bad instances
// named by file, place and rule, numbers out of range quoted as written, thread counts beyond
// the limit, inputs without end, help for every command, and progress lines in a log.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli_test_support.hpp"
#include "support/bad_inputs.hpp"

namespace ontime {
namespace {

using namespace cli_test;

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

// Standard error is not a terminal here (a pipe, as in a log or CI): progress comes as plain
// lines, here one per update (ONTIME_PROGRESS_SECONDS=0), and --quiet silences them. The lines'
// form and order on a Monte Carlo run (one line per 256 episodes), and on training (one line per
// epoch of at least 4,000 steps: instance 4's episodes are one or two steps long, so 300 episodes
// are one epoch; 3,000 took two minutes under the sanitizers).
std::vector<std::uint64_t> progress_counts(const std::string& err, const std::string& what, std::uint64_t total) {
  // Durations as the bar writes them: 42s, 1m07s, 1h21m (a slow build passes a minute).
  const std::regex line("ontime " + what + R"(: (\d+)/)" + std::to_string(total) +
                        R"( \((\d+)%\), \d+[hms](\d+[ms])? elapsed, about \d+[hms](\d+[ms])? left)");
  std::istringstream in(err);
  std::vector<std::uint64_t> done;
  for (std::string text; std::getline(in, text);) {
    std::smatch match;
    EXPECT_TRUE(std::regex_match(text, match, line)) << text;
    if (match.empty()) continue;
    done.push_back(std::stoull(match[1]));
    EXPECT_EQ(std::stoull(match[2]), done.back() * 100 / total);
  }
  return done;
}

TEST(Cli, ProgressLinesInALogAndNoneWhenQuiet) {
  const auto directory = scratch("progress");
  const std::string policy = (directory / "policy.json").string();
  const auto evaluated = testing::run_process({"/usr/bin/env", "ONTIME_PROGRESS_SECONDS=0", ONTIME_CLI, "evaluate",
                                               paper("instance4"), "--solver", "dp-rerun", "--episodes", "3000"});
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
  const std::vector<std::uint64_t> episodes = progress_counts(evaluated.err, "evaluate dp-rerun", 3000);
  ASSERT_GE(episodes.size(), 11U);  // 256, 512, ..., 2816, 3000
  EXPECT_TRUE(std::is_sorted(episodes.begin(), episodes.end()));
  EXPECT_EQ(episodes.back(), 3000U);

  const auto trained = testing::run_process({"/usr/bin/env", "ONTIME_PROGRESS_SECONDS=0", ONTIME_CLI, "train",
                                             paper("instance4"), "--episodes", "300", "--out", policy, "--no-plot"});
  ASSERT_EQ(trained.exit_code, 0) << trained.err;
  EXPECT_EQ(progress_counts(trained.err, "train ppo", 300), std::vector<std::uint64_t>{300});

  // Quiet: nothing at all. 30 episodes suffice to show it: the same run without --quiet writes a
  // progress line (its one epoch), and training 3,000 twice took minutes under the sanitizers.
  std::vector<std::string> quieted = {"/usr/bin/env",
                                      "ONTIME_PROGRESS_SECONDS=0",
                                      ONTIME_CLI,
                                      "train",
                                      paper("instance4"),
                                      "--episodes",
                                      "30",
                                      "--out",
                                      policy,
                                      "--no-plot",
                                      "--quiet"};
  const auto quiet = testing::run_process(quieted);
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");

  const auto bad = testing::run_process({"/usr/bin/env", "ONTIME_PROGRESS_SECONDS=soon", ONTIME_CLI, "train",
                                         paper("instance4"), "--episodes", "30", "--out", policy, "--no-plot"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("ONTIME_PROGRESS_SECONDS: must be a number of seconds"), std::string::npos) << bad.err;
}

// table: an mcts episode costs thousands of dp-rerun ones, so the time left is estimated from each
// column's own episodes, and not at all while a column with episodes left has run none (the
// share done alone said "about 0s left" a second into a table of minutes).
TEST(Cli, TheTablesTimeLeftWaitsForEveryColumnsCost) {
  const auto result =
      testing::run_process({"/usr/bin/env", "ONTIME_PROGRESS_SECONDS=0", ONTIME_CLI, "table", paper("instance1"),
                            paper("instance2"), "--solvers", "dp-rerun,mcts", "--episodes", "100", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::regex line(
      R"(ontime table: (\d+)/400 \(\d+%\), \d+[hms](\d+[ms])? elapsed(, about \d+[hms](\d+[ms])? left)?)");
  std::istringstream in(result.err);
  std::size_t without = 0, with = 0;
  for (std::string text; std::getline(in, text);) {
    std::smatch match;
    ASSERT_TRUE(std::regex_match(text, match, line)) << text;
    const std::uint64_t done = std::stoull(match[1]);
    const bool estimated = match[3].matched;
    // Through the first row's dp-rerun column (episodes 1 to 100) mcts has run nothing.
    EXPECT_EQ(estimated, done > 100) << text;
    ++(estimated ? with : without);
  }
  EXPECT_GT(without, 0U);
  EXPECT_GT(with, 0U);
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

TEST(Cli, UsageErrorsTakeOneLine) {
  for (const std::vector<std::string>& arguments :
       {std::vector<std::string>{}, {"frobnicate"}, {"solve"}, {"evaluate", paper("figure1"), "--no-such-option"}}) {
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2);
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_EQ(result.err.rfind("ontime: usage error: ", 0), 0U) << result.err;
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

}  // namespace
}  // namespace ontime
