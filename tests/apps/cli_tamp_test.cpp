// CLI tests of the live TAMP commands: `tamp` (skeletons streamed into live episodes; the
// modelled clock reproducing the episodes for any thread count) and `run --live` (every
// episode's charges and timeline). They need the domains build.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "apps/cli_test_support.hpp"

namespace ontime {
namespace {

using namespace cli_test;

// The whole TAMP loop: skeletons streamed by the room-path planner, refined by the real planner,
// every search charged; its picture's data; bad deadlines and libraries refused before any work.
TEST(Cli, TampStreamsSkeletonsIntoLiveEpisodes) {
  const std::filesystem::path dir = scratch("tamp");
  const std::string world = testing::source_path("data/domains/navigation.json").string();
  const std::string library = testing::source_path("data/instances/navigation.json").string();
  const auto result = ontime({"tamp",
                              "--world",
                              world,
                              "--library",
                              library,
                              "--deadline",
                              "45",
                              "--solver",
                              "dp-rerun",
                              "--episodes",
                              "6",
                              "--threads",
                              "1",
                              "--max-skeletons",
                              "3",
                              "--task-seconds",
                              "0.5",
                              "--json",
                              "--picture",
                              (dir / "episode.png").string(),
                              "--picture-episode",
                              "1",
                              "--no-plot"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["deadline_steps"].get<int>(), 15);
  ASSERT_EQ(out["episode_results"].size(), 6u);
  std::uint64_t successes = 0;
  for (const json& episode : out["episode_results"]) {
    successes += episode["status"] == "success" ? 1 : 0;
    const int found = episode["skeletons_found"].get<int>();
    EXPECT_GE(found, 1);
    EXPECT_LE(found, 3);
    // Every skeleton found was charged its half second of search.
    EXPECT_GE(episode["outside_seconds"].get<double>(), 0.5 * found - 1e-9);
    EXPECT_LE(episode["elapsed_seconds"].get<double>(), 45.0 + 1e-6);
  }
  EXPECT_EQ(out["successes"].get<std::uint64_t>(), successes);
  const json drawing = json::parse(read_file(dir / "episode.json"));
  EXPECT_FALSE(drawing["skeletons"].empty());
  for (const json& skeleton : drawing["skeletons"]) EXPECT_GE(skeleton["points"].size(), 3u);
  EXPECT_TRUE(std::filesystem::exists(dir / "episode-timeline.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "episode.png"));

  const auto too_short = ontime({"tamp", "--world", world, "--library", library, "--deadline", "2", "--solver", "dp"});
  EXPECT_EQ(too_short.exit_code, 2);
  EXPECT_NE(too_short.err.find("--deadline 2"), std::string::npos) << too_short.err;
  // A library without the moves of the room paths: named, with the action missing.
  const auto missing =
      ontime({"tamp", "--world", world, "--library", paper("instance1"), "--deadline", "45", "--solver", "dp"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("instance1.json: actions: no action 'move(R1,"), std::string::npos) << missing.err;
}

// With --clock model nothing real is on the clock: each decision is charged the model's seconds
// (here dp-rerun, which does not search: 10 us), the allocator's handling of an outcome nothing,
// and the episodes are the same, to every charge, for any thread count.
TEST(Cli, TampOnTheModelledClockReproducesToTheEpisode) {
  const std::string world = testing::source_path("data/domains/navigation.json").string();
  const std::string library = testing::source_path("data/instances/navigation.json").string();
  const auto run = [&](const std::string& threads, const std::string& solver) {
    std::vector<std::string> command = {"tamp",  "--world",         world,  "--library",  library, "--deadline",
                                        "45",    "--solver",        solver, "--episodes", "6",     "--threads",
                                        threads, "--max-skeletons", "3",    "--clock",    "model", "--json"};
    if (solver == "mcts") command.insert(command.end(), {"--iterations", "40"});
    const auto result = ontime(command);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    json out = json::parse(result.out);
    out.erase("seconds");  // the run's own duration
    return out;
  };
  const json one = run("1", "dp-rerun");
  EXPECT_EQ(one, run("2", "dp-rerun"));
  EXPECT_EQ(one["clock"], "model");
  std::size_t steps = 0;
  for (const json& episode : one["episode_results"]) {
    for (const json& step : episode["timeline"]) {
      EXPECT_NEAR(step["decision_seconds"].get<double>(), 1e-5, 1e-12);
      EXPECT_EQ(step["observe_seconds"].get<double>(), 0.0);
      ++steps;
    }
  }
  EXPECT_GT(steps, 6U);
  // A searching allocator: 10 us + 2 us for each of its 40 iterations when it searches (not
  // where one choice is all there is).
  const json searched = run("2", "mcts");
  EXPECT_EQ(searched, run("1", "mcts"));
  std::size_t searches = 0;
  for (const json& episode : searched["episode_results"]) {
    for (const json& step : episode["timeline"]) {
      const double seconds = step["decision_seconds"].get<double>();
      const bool searched_here = std::abs(seconds - (1e-5 + 40 * 2e-6)) < 1e-12;
      EXPECT_TRUE(searched_here || std::abs(seconds - 1e-5) < 1e-12) << seconds;
      searches += searched_here ? 1 : 0;
    }
  }
  EXPECT_GT(searches, 0U);

  const auto real_with_model_options = ontime({"tamp", "--world", world, "--library", library, "--deadline", "45",
                                               "--solver", "dp-rerun", "--decision-seconds", "0.001"});
  EXPECT_EQ(real_with_model_options.exit_code, 2);
  EXPECT_NE(real_with_model_options.err.find("need --clock model"), std::string::npos) << real_with_model_options.err;
  const auto wall = ontime({"tamp", "--world", world, "--library", library, "--deadline", "45", "--solver", "dp-rerun",
                            "--clock", "model", "--effort", "wall"});
  EXPECT_EQ(wall.exit_code, 2);
  EXPECT_NE(wall.err.find("--clock model needs --effort checks"), std::string::npos) << wall.err;
}

// Learning across episodes: the success by episode index over the sequences, adding up to the
// run's; the text report prints it; options that do not go together are refused before any work.
TEST(Cli, TampLearnsAcrossTheEpisodesOfEachSequence) {
  const std::string world = testing::source_path("data/domains/navigation.json").string();
  const std::string library = testing::source_path("data/instances/navigation.json").string();
  const std::vector<std::string> base = {"tamp",       "--world", world,      "--library",  library,
                                         "--deadline", "45",      "--solver", "dp-rerun",   "--max-skeletons",
                                         "3",          "--clock", "model",    "--episodes", "3"};
  std::vector<std::string> command = base;
  command.insert(command.end(), {"--sequences", "4", "--adapt-strength", "2", "--json"});
  const auto result = ontime(command);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["episodes"].get<int>(), 12);
  const json& adaptation = out["adaptation"];
  EXPECT_EQ(adaptation["sequences"].get<int>(), 4);
  EXPECT_EQ(adaptation["episodes_per_sequence"].get<int>(), 3);
  ASSERT_EQ(adaptation["by_episode"].size(), 3u);
  int successes = 0;
  for (const json& episode : adaptation["by_episode"]) {
    const int count = episode["successes"].get<int>();
    EXPECT_DOUBLE_EQ(episode["success_rate"].get<double>(), count / 4.0);
    successes += count;
  }
  EXPECT_EQ(successes, out["successes"].get<int>());
  command = base;
  command.insert(command.end(), {"--sequences", "2", "--adapt-strength", "2"});
  const auto text = ontime(command);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("online update        2 sequences of 3 episodes, the library a prior of strength 2"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("success by episode   1:"), std::string::npos) << text.out;

  command = base;
  command.insert(command.end(), {"--sequences", "2"});
  const auto lonely = ontime(command);
  EXPECT_EQ(lonely.exit_code, 2);
  EXPECT_NE(lonely.err.find("--sequences needs --adapt-strength"), std::string::npos) << lonely.err;
  command = base;
  command.insert(command.end(), {"--adapt-strength", "0"});
  EXPECT_EQ(ontime(command).exit_code, 2);
  command = base;
  command.insert(command.end(), {"--adapt-strength", "2", "--picture", "x.png"});
  const auto picture = ontime(command);
  EXPECT_EQ(picture.exit_code, 2);
  EXPECT_NE(picture.err.find("--picture is not taken with --adapt-strength"), std::string::npos) << picture.err;
}

// The manipulation kitchen whose refinements give up and blame the grasp (SPEC §7), learning across
// episodes with its fitted library (data/instances/kitchen-grasps.json: planning and backtracking
// of move+place(B1,S) take all its mass) as a prior of strength 10: the believed libraries were
// refused ("planning and backtrack probabilities sum above 1"); now every sequence runs, the same
// for any thread count, and each sequence's first episode is the run without learning.
TEST(Cli, TampLearnsAcrossEpisodesInAKitchenThatBacktracks) {
  const std::string world = testing::source_path("data/domains/kitchen-grasps.json").string();
  const std::string library = testing::source_path("data/instances/kitchen-grasps.json").string();
  const std::vector<std::string> base = {"tamp",      "--domain", "manipulation", "--world", world,
                                         "--library", library,    "--deadline",   "280",     "--solver",
                                         "dp-rerun",  "--clock",  "model",        "--json"};
  std::vector<std::string> command = base;
  command.insert(command.end(), {"--episodes", "3", "--sequences", "2", "--adapt-strength", "10", "--threads", "1"});
  const auto one = ontime(command);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  command.back() = "2";
  const auto two = ontime(command);
  ASSERT_EQ(two.exit_code, 0) << two.err;
  command = base;
  command.insert(command.end(), {"--episodes", "6", "--threads", "1"});
  const auto plain = ontime(command);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const json learning = json::parse(one.out), again = json::parse(two.out), without = json::parse(plain.out);
  EXPECT_GT(learning["backtracks"].get<double>(), 0.0);
  EXPECT_EQ(learning["adaptation"], again["adaptation"]);
  ASSERT_EQ(learning["episode_results"].size(), 6u);
  int successes = 0;
  for (std::size_t e = 0; e < 6; ++e) {
    const json& episode = learning["episode_results"][e];
    EXPECT_EQ(episode["status"], again["episode_results"][e]["status"]) << e;
    EXPECT_EQ(episode["elapsed_seconds"], again["episode_results"][e]["elapsed_seconds"]) << e;
    successes += episode["status"] == "success" ? 1 : 0;
  }
  int by_episode = 0;
  for (const json& episode : learning["adaptation"]["by_episode"]) by_episode += episode["successes"].get<int>();
  EXPECT_EQ(by_episode, successes);
  for (const std::size_t first : {std::size_t{0}, std::size_t{3}}) {
    EXPECT_EQ(learning["episode_results"][first]["status"], without["episode_results"][first]["status"]) << first;
    EXPECT_EQ(learning["episode_results"][first]["elapsed_seconds"],
              without["episode_results"][first]["elapsed_seconds"])
        << first;
  }
}

// Live episodes against the real planner: every episode's charges and timeline in the JSON, one
// episode's timeline as CSV; the live options need a live run.
TEST(Cli, RunLiveReportsEveryEpisodesChargesAndTimeline) {
  const std::filesystem::path dir = scratch("live");
  const auto result =
      ontime({"run", "--domain", "navigation", "--solver", "dp-rerun", "--live", "--episodes", "3", "--threads", "1",
              "--json", "--timeline", (dir / "timeline.png").string(), "--timeline-episode", "2", "--no-plot"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_TRUE(out["live"].get<bool>());
  EXPECT_EQ(out["effort"], "checks");
  ASSERT_EQ(out["episode_results"].size(), 3u);
  std::uint64_t successes = 0;
  for (const json& episode : out["episode_results"]) {
    successes += episode["status"] == "success" ? 1 : 0;
    ASSERT_FALSE(episode["timeline"].empty());
    double planning = 0;
    for (const json& step : episode["timeline"]) planning += step["planning_seconds"].get<double>();
    EXPECT_NEAR(episode["planning_seconds"].get<double>(), planning, 1e-9);
    // Planner calls count their nominal seconds: at least a little effort each.
    EXPECT_GT(planning, 0.0);
    EXPECT_LE(episode["elapsed_seconds"].get<double>(), 66.0 + 1e-6);
  }
  EXPECT_EQ(out["successes"].get<std::uint64_t>(), successes);
  EXPECT_LE(out["step_clock_successes"].get<std::uint64_t>() + out["step_clock_undecided"].get<std::uint64_t>(), 3u);
  // A row per step, then the robot's lane: plan-first, the plan executed after a success.
  const json& drawn = out["episode_results"][2];
  EXPECT_EQ(drawn["executions"].empty(), drawn["status"] != "success");
  EXPECT_EQ(line_count(dir / "timeline.csv"), drawn["timeline"].size() + 1 + drawn["executions"].size());
  EXPECT_FALSE(std::filesystem::exists(dir / "timeline.png"));

  const auto not_live = ontime({"run", "--domain", "navigation", "--solver", "dp", "--decision-share", "0.3"});
  EXPECT_EQ(not_live.exit_code, 2);
  EXPECT_NE(not_live.err.find("--decision-share needs live episodes"), std::string::npos) << not_live.err;
}

}  // namespace
}  // namespace ontime
