// CLI tests of `train`: a policy that evaluate and table use, the same bytes whichever libm
// glibc picks and on instances where success is impossible, policies of other instances
// refused, and interrupted runs that leave the previous output set whole.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "apps/cli_test_support.hpp"
#include "ontime/allocators/ppo.hpp"

namespace ontime {
namespace {

using namespace cli_test;

// Trained acting while planning (SPEC §10), a policy chooses each start and step: evaluate and
// table take it with --act concurrent (its exact value the one train printed, at most the
// concurrent optimum), and plan-first refuses it, naming the rule.
TEST(Cli, TrainActingWhilePlanningWritesAPolicyOfThatMode) {
  const auto directory = scratch("train-concurrent");
  const std::string policy = (directory / "instance2.json").string();
  const auto trained = ontime({"train", paper("instance2"), "--act", "concurrent", "--episodes", "300", "--seed", "2",
                               "--out", policy, "--no-plot", "--json"});
  ASSERT_EQ(trained.exit_code, 0) << trained.err;
  const json report = json::parse(trained.out);
  EXPECT_EQ(report["acting"], "concurrent");
  std::ifstream file(policy);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find("\"acting\": \"concurrent\""), std::string::npos);

  const auto evaluated = ontime({"evaluate", paper("instance2"), "--act", "concurrent", "--solver", "ppo", "--policy",
                                 policy, "--episodes", "500", "--exact", "--json"});
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
  const json evaluation = json::parse(evaluated.out);
  EXPECT_EQ(evaluation["exact_success_probability"].get<double>(), report["exact_success_probability"].get<double>());
  const auto optimum = ontime({"solve", paper("instance2"), "--act", "concurrent", "--json"});
  ASSERT_EQ(optimum.exit_code, 0) << optimum.err;
  EXPECT_LE(report["exact_success_probability"].get<double>(),
            json::parse(optimum.out)["optimal_success_probability"].get<double>() + 1e-12);
  const auto table = ontime({"table", paper("instance2"), "--act", "concurrent", "--solvers", "ppo,dp-rerun",
                             "--policy", policy, "--episodes", "200", "--json"});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  const double rate = json::parse(table.out)["rows"][0]["solvers"]["ppo"]["success_rate"].get<double>();
  const double exact = report["exact_success_probability"].get<double>();
  EXPECT_NEAR(rate, exact, 4 * std::sqrt(exact * (1 - exact) / 200));

  const auto plan_first =
      ontime({"evaluate", paper("instance2"), "--solver", "ppo", "--policy", policy, "--episodes", "10"});
  EXPECT_EQ(plan_first.exit_code, 2);
  EXPECT_NE(plan_first.err.find("trained acting while planning ('paper-instance-2'), not plan-first (SPEC §10)"),
            std::string::npos)
      << plan_first.err;
  // The plan-first report says so too.
  const auto plain = ontime({"train", paper("instance2"), "--episodes", "20", "--out",
                             (directory / "plain.json").string(), "--no-plot", "--json"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(json::parse(plain.out)["acting"], "plan-first");
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

// On an instance with rewards and chains (SPEC §8, §9) train reports the policy's exact expected
// reward beside its success, the figures evaluate --exact gives for the same policy; without
// rewards, no reward key.
TEST(Cli, TrainReportsTheExpectedRewardWithRewards) {
  const auto directory = scratch("train-rewards");
  const std::string instance = testing::source_path("data/instances/chains/meeting-through-the-queue.json").string();
  const std::string policy = (directory / "meeting.json").string();
  const auto trained = ontime({"train", instance, "--solver", "ppo", "--episodes", "200", "--seed", "1", "--out",
                               policy, "--no-plot", "--json"});
  ASSERT_EQ(trained.exit_code, 0) << trained.err;
  const json report = json::parse(trained.out);
  const auto evaluated =
      ontime({"evaluate", instance, "--solver", "ppo", "--policy", policy, "--episodes", "100", "--exact", "--json"});
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
  const json exact = json::parse(evaluated.out);
  EXPECT_EQ(report["exact_expected_reward"].get<double>(), exact["exact_expected_reward"].get<double>());
  EXPECT_EQ(report["exact_success_probability"].get<double>(), exact["exact_success_probability"].get<double>());
  EXPECT_LT(report["exact_expected_reward"].get<double>(), report["exact_success_probability"].get<double>());
  const auto plain = ontime({"train", paper("instance4"), "--solver", "ppo", "--episodes", "20", "--out",
                             (directory / "plain.json").string(), "--no-plot", "--json"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(json::parse(plain.out).contains("exact_expected_reward"));
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
  ASSERT_EQ(testing::run_process(train("50", true)).exit_code, 0);
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
  const auto staging = testing::run_process(train("100", true), [&] {
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
  testing::run_process(train("150", true), [&] { return read_file(policy) != before[0]; });
  EXPECT_EQ(entries(), expected_names);
  const std::vector<std::string> now{read_file(policy), read_file(csv), read_file(png)};
  if (now[0] == before[0]) {
    EXPECT_TRUE(now == before);
  } else {
    EXPECT_TRUE(now[1] != before[1]) << "a new policy beside the old curve CSV";
    EXPECT_TRUE(now[2] != before[2]) << "a new policy beside the old curve PNG";
  }

  ASSERT_EQ(testing::run_process(train("200", false)).exit_code, 0);
  EXPECT_EQ(entries(), (std::vector<std::string>{"policy.curve.csv", "policy.json"}));
}

}  // namespace
}  // namespace ontime
