// CLI tests of `score` (an instance's log and Brier scores on a planner log) and of `evaluate
// --belief` (an allocator planning with other distributions, scored in the true instance), `adapt`
// (episodes with the online update) and `fit-strength` (the prior strength on unseen logs).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/cli_test_support.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/learn/online_adaptation.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

using namespace cli_test;
using json = nlohmann::json;

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// `truth` with the planning times of its skeletons' first actions a1_1 and a2_1 swapped.
Problem misleading_belief(const Problem& truth) {
  std::vector<Action> actions(truth.actions().begin(), truth.actions().end());
  std::swap(actions[static_cast<std::size_t>(truth.find_action("a1_1"))].planning,
            actions[static_cast<std::size_t>(truth.find_action("a2_1"))].planning);
  std::vector<std::vector<int>> skeletons;
  skeletons.reserve(static_cast<std::size_t>(truth.skeleton_count()));
  for (int k = 0; k < truth.skeleton_count(); ++k) {
    skeletons.emplace_back(truth.skeleton(k).begin(), truth.skeleton(k).end());
  }
  return {"belief", truth.deadline(), truth.step_seconds(), std::move(actions), std::move(skeletons)};
}

TEST(Cli, ScorePrintsTheLogAndBrierScoresOfAnInstance) {
  const auto folder = scratch("score");
  // One action: found at step 1 with 0.6, at 2 with 0.2, never with 0.2; executes in 0 or 1 step.
  const Action action{"a", Distribution::from_pmf({0.0, 0.6, 0.2}), Distribution::from_pmf({0.5, 0.5})};
  save_problem(Problem("one", 3, 1.0, {action}, {{0}}), folder / "one.json");
  write_text(folder / "log.jsonl",
             "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1}\n"
             "{\"action\": \"a\", \"planning_seconds\": 2, \"found\": true, \"execution_seconds\": 0}\n"
             "{\"action\": \"a\", \"planning_seconds\": 1.5, \"found\": false}\n"
             "{\"action\": \"a\", \"planning_seconds\": 5, \"found\": true, \"execution_seconds\": 0.5}\n");
  const auto result = ontime({"score", (folder / "one.json").string(), (folder / "log.jsonl").string(), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["attempts"], 4);
  EXPECT_EQ(out["found"], 2);
  EXPECT_EQ(out["censored"], 2);
  EXPECT_EQ(out["horizon"], 3);
  EXPECT_NEAR(out["planning_nll"].get<double>(), -(std::log(0.6) + std::log(0.2) + std::log(0.4) + std::log(0.2)) / 4,
              1e-15);
  EXPECT_NEAR(out["integrated_brier"].get<double>(), 0.28, 1e-15);  // tests/learn/attempt_scores_test.cpp
  EXPECT_NEAR(out["execution_nll"].get<double>(), std::log(2.0), 1e-15);

  // An attempt of an action the instance lacks: refused, or skipped when asked.
  write_text(folder / "other.jsonl", "{\"action\": \"b\", \"planning_seconds\": 1, \"found\": false}\n");
  const auto refused = ontime(
      {"score", (folder / "one.json").string(), (folder / "log.jsonl").string(), (folder / "other.jsonl").string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("no action b"), std::string::npos) << refused.err;
  const auto skipped = ontime({"score", (folder / "one.json").string(), (folder / "log.jsonl").string(),
                               (folder / "other.jsonl").string(), "--skip-unknown", "--json"});
  ASSERT_EQ(skipped.exit_code, 0) << skipped.err;
  EXPECT_EQ(json::parse(skipped.out)["skipped"], 1);
  EXPECT_EQ(
      ontime({"score", (folder / "one.json").string(), (folder / "log.jsonl").string(), "--horizon", "4"}).exit_code,
      2);  // beyond the deadline
}

TEST(Cli, EvaluateWithABeliefPlansWithItAndScoresInTheInstance) {
  const auto folder = scratch("evaluate_belief");
  const Problem truth = testing::paper_instance("instance4");
  const Problem belief = misleading_belief(truth);
  save_problem(belief, folder / "belief.json");

  const auto plain = ontime({"evaluate", paper("instance4"), "--solver", "dp-rerun", "--exact", "--episodes", "500",
                             "--no-timing", "--json"});
  const auto believing = ontime({"evaluate", paper("instance4"), "--belief", (folder / "belief.json").string(),
                                 "--solver", "dp-rerun", "--exact", "--episodes", "500", "--no-timing", "--json"});
  ASSERT_EQ(believing.exit_code, 0) << believing.err;
  const json out = json::parse(believing.out);
  EXPECT_EQ(out["belief"], (folder / "belief.json").string());
  // The exact value of dp-rerun deciding with the belief, in the true instance.
  const Mdp truth_mdp(truth);
  const Problem planned = with_distributions_of(truth, belief);
  const Mdp planned_mdp(planned);
  DpRerunAllocator allocator(planned_mdp);
  const double expected = evaluate_exactly(truth_mdp, allocator).success_probability;
  EXPECT_EQ(out["exact_success_probability"].get<double>(), expected);
  EXPECT_LT(expected, json::parse(plain.out)["exact_success_probability"].get<double>());

  // The instance itself as the belief: the same numbers as without one.
  const auto same = ontime({"evaluate", paper("instance4"), "--belief", paper("instance4"), "--solver", "dp-rerun",
                            "--exact", "--episodes", "500", "--no-timing", "--json"});
  json same_out = json::parse(same.out);
  same_out.erase("belief");
  EXPECT_EQ(same_out, json::parse(plain.out));

  // A belief without one of the instance's actions: exit 2 naming the belief.
  save_problem(Problem("lacking", truth.deadline(), truth.step_seconds(), {truth.action(0)}, {{0}}),
               folder / "lacking.json");
  const auto lacking = ontime({"evaluate", paper("instance4"), "--belief", (folder / "lacking.json").string(),
                               "--solver", "dp-rerun", "--episodes", "10"});
  EXPECT_EQ(lacking.exit_code, 2);
  EXPECT_NE(lacking.err.find("lacking.json: no distributions for the action"), std::string::npos) << lacking.err;
}

TEST(Cli, EvaluateWithABeliefActingWhilePlanningDecidesOnTheBeliefsModel) {
  const auto folder = scratch("evaluate_belief_concurrent");
  const Problem truth = testing::paper_instance("instance4").with_acting(Acting::concurrent);
  save_problem(misleading_belief(truth), folder / "belief.json");
  const std::vector<std::string> common{"--act", "concurrent", "--solver", "dp-rerun",    "--exact", "--seed",
                                        "3",     "--episodes", "500",      "--no-timing", "--json"};
  std::vector<std::string> plain_command{"evaluate", paper("instance4")};
  plain_command.insert(plain_command.end(), common.begin(), common.end());
  std::vector<std::string> believing_command = plain_command;
  believing_command.insert(believing_command.end(), {"--belief", (folder / "belief.json").string()});
  std::vector<std::string> same_command = plain_command;
  same_command.insert(same_command.end(), {"--belief", paper("instance4")});
  const auto plain = ontime(plain_command);
  const auto believing = ontime(believing_command);
  ASSERT_EQ(believing.exit_code, 0) << believing.err;
  const json out = json::parse(believing.out);
  EXPECT_EQ(out["belief"], (folder / "belief.json").string());
  EXPECT_EQ(out["acting"], "concurrent");
  // The exact value of dp-rerun deciding on the belief's model, in the world's (hopeless skeletons
  // kept, so that the world's distributions tell the allocator nothing).
  const ConcurrentMdp world(truth, HopelessSkeletons::kept);
  const ConcurrentMdp believed(with_distributions_of(truth, misleading_belief(truth)));
  const auto allocator = seen_by_belief(believed, make_concurrent_allocator_factory("dp-rerun", believed))();
  const double expected = evaluate_exactly(world, *allocator).success_probability;
  EXPECT_EQ(out["exact_success_probability"].get<double>(), expected);
  EXPECT_LT(expected, json::parse(plain.out)["exact_success_probability"].get<double>());

  // The instance itself as the belief: the same numbers as without one.
  json same_out = json::parse(ontime(same_command).out);
  same_out.erase("belief");
  EXPECT_EQ(same_out, json::parse(plain.out));
}

TEST(Cli, AdaptRunsEpisodesWithTheUpdatedPriorAsTheLibraryDoes) {
  const auto folder = scratch("adapt");
  const Problem truth = testing::paper_instance("instance4");
  const Problem prior = misleading_belief(truth);
  save_problem(prior, folder / "prior.json");
  const auto result = ontime({"adapt", paper("instance4"), "--belief", (folder / "prior.json").string(), "--solver",
                              "dp-rerun", "--strength", "2", "--episodes", "4", "--sequences", "30", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  AdaptationOptions options;
  options.strength = 2;
  options.episodes = 4;
  options.sequences = 30;
  const AdaptationResult expected = run_adaptation(truth, load_problem(folder / "prior.json"), options);
  EXPECT_EQ(out["successes"].get<std::vector<std::uint64_t>>(), expected.successes);
  EXPECT_EQ(out["exact_success_probability"].get<std::vector<double>>(), expected.exact);
  EXPECT_EQ(out["success_rate"].size(), 4u);
  // A prior of another deadline: exit 2 naming it, before any episode.
  const auto other =
      ontime({"adapt", paper("instance4"), "--belief", paper("instance1"), "--solver", "dp-rerun", "--episodes", "2"});
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("instance1.json: the deadlines differ"), std::string::npos) << other.err;
}

// Every shipped example with backtracking (SPEC §7), its own prior: `adapt` learns planning and
// backtracking together (the believed instances used to be refused: "planning and backtrack
// probabilities sum above 1"), with the library's numbers; the first episode plans with the prior
// itself, dp-rerun's own value. The first, with the command's defaults (10 episodes of 100
// sequences), as it was refused.
TEST(Cli, AdaptTakesEveryShippedExampleWithBacktracking) {
  for (const char* path : {"data/instances/kitchen-grasps.json", "data/instances/chains/cup-through-the-door.json",
                           "data/instances/backtracking/grasp-and-place.json"}) {
    SCOPED_TRACE(path);
    const std::string instance = testing::source_path(path).string();
    const bool defaults = std::string(path) == "data/instances/kitchen-grasps.json";
    std::vector<std::string> command = {"adapt", instance, "--belief", instance, "--solver", "dp-rerun", "--json"};
    if (!defaults) command.insert(command.end(), {"--episodes", "4", "--sequences", "20"});
    const auto result = ontime(command);
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const json out = json::parse(result.out);
    const Problem truth = load_problem(instance);
    AdaptationOptions options;
    if (!defaults) {
      options.episodes = 4;
      options.sequences = 20;
    }
    const AdaptationResult expected = run_adaptation(truth, truth, options);
    EXPECT_EQ(out["successes"].get<std::vector<std::uint64_t>>(), expected.successes);
    EXPECT_EQ(out["exact_success_probability"].get<std::vector<double>>(), expected.exact);
    const Mdp mdp(truth);
    DpRerunAllocator allocator(mdp);
    EXPECT_NEAR(expected.exact.front(), evaluate_exactly(mdp, allocator).success_probability, 1e-12);
  }
}

TEST(Cli, FitStrengthScoresEachStrengthOnUnseenLogs) {
  const auto folder = scratch("fit_strength");
  // Training: found at 1, at 2, cut off after 2, found at 1 (pooled p(1) = 1/2, p(2) = 1/4).
  write_text(folder / "train.jsonl",
             "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1, "
             "\"world\": \"t\", \"features\": [0]}\n"
             "{\"action\": \"a\", \"planning_seconds\": 2, \"found\": true, \"execution_seconds\": 1, "
             "\"world\": \"t\", \"features\": [0]}\n"
             "{\"action\": \"a\", \"planning_seconds\": 2, \"found\": false, \"world\": \"t\", "
             "\"features\": [0]}\n"
             "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1, "
             "\"world\": \"t\", \"features\": [0]}\n");
  write_text(folder / "unseen.jsonl",
             "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1, "
             "\"world\": \"v\", \"features\": [0]}\n"
             "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": false, \"world\": \"v\", "
             "\"features\": [0]}\n");
  const auto fit = ontime({"fit", (folder / "train.jsonl").string(), "--conditional", "pooled", "--step", "1", "-o",
                           (folder / "model.json").string()});
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const auto result = ontime({"fit-strength", (folder / "unseen.jsonl").string(), "--model",
                              (folder / "model.json").string(), "--strengths", "1,3", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  ASSERT_EQ(out["scores"].size(), 2u);
  // tests/learn/online_adaptation_test.cpp: -(log 1/2 + log((s/2) / (s + 1))) / 2.
  for (const json& score : out["scores"]) {
    const double s = score["strength"].get<double>();
    EXPECT_NEAR(score["nll"].get<double>(), -(std::log(0.5) + std::log(s / 2 / (s + 1))) / 2, 1e-14);
  }
  EXPECT_EQ(out["best"].get<double>(), 3.0);  // (3/2)/4 = 0.375 foresees the cut-off better than (1/2)/2
  EXPECT_EQ(ontime({"fit-strength", (folder / "unseen.jsonl").string(), "--model", (folder / "model.json").string(),
                    "--strengths", "0"})
                .exit_code,
            2);
}

// Two records of one world with one feature, for fit-strength.
const std::string kStrengthLog =
    "{\"action\": \"a\", \"planning_seconds\": 2, \"found\": false, \"world\": \"t\", \"features\": [0]}\n"
    "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1, \"world\": \"t\", "
    "\"features\": [0]}\n";

// fit-strength: each strength read by the command line's number parser, and a log of another
// feature count than the model's refused naming the log.
TEST(Cli, FitStrengthReadsItsStrengthsExactlyAndNamesALogOfOtherFeatures) {
  const auto dir = scratch("fit-strength-numbers");
  const std::string train = (dir / "train.jsonl").string();
  write_text(train, kStrengthLog);
  const std::string model = (dir / "model.json").string();
  ASSERT_EQ(ontime({"fit", train, "--conditional", "pooled", "--step", "1", "-o", model}).exit_code, 0);
  for (const std::string strengths : {"0x10", "1,,2", "1,", "", "nan", "inf", "-1", "0", "1e999", "2 "}) {
    const auto result = ontime({"fit-strength", train, "--model", model, "--strengths", strengths});
    EXPECT_EQ(result.exit_code, 2) << strengths << ": " << result.err;
    EXPECT_NE(result.err.find("--strengths"), std::string::npos) << strengths << ": " << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  }
  const auto read = ontime({"fit-strength", train, "--model", model, "--strengths", "0.5,16,1e3", "--json"});
  ASSERT_EQ(read.exit_code, 0) << read.err;
  const json scores = json::parse(read.out)["scores"];
  ASSERT_EQ(scores.size(), 3u);
  EXPECT_EQ(scores[0]["strength"].get<double>(), 0.5);
  EXPECT_EQ(scores[1]["strength"].get<double>(), 16.0);
  EXPECT_EQ(scores[2]["strength"].get<double>(), 1000.0);

  const std::string wide = (dir / "wide.jsonl").string();
  std::string two_features = kStrengthLog;
  for (std::size_t at = two_features.find("[0]"); at != std::string::npos; at = two_features.find("[0]", at)) {
    two_features.replace(at, 3, "[0, 1]");
  }
  write_text(wide, two_features);
  const auto refused = ontime({"fit-strength", wide, "--model", model});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(refused.err, "ontime: error: " + wide + ": record 1: has 2 features, the model " + model + " takes 1\n");
}

}  // namespace
}  // namespace ontime
