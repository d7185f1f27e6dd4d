// CLI tests of the domain commands that build worlds and logs: `collect` (the log and the fitted
// instance, its OMPL benchmark log, an interrupted collection resumed to the same files, every
// action, the manipulation domain), `map` and `generate-world`, and worlds whose goal cannot be
// reached. They need the domains build (tests/CMakeLists.txt filters them out otherwise).

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli_test_support.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "support/mini_world.hpp"

namespace ontime {
namespace {

using namespace cli_test;

TEST(Cli, CollectWritesTheLogAndTheFittedInstance) {
  const std::filesystem::path dir = scratch("collect");
  const std::string log = (dir / "logs" / "navigation.jsonl").string();
  const std::string instance = (dir / "navigation.json").string();
  const auto result = ontime({"collect", "--domain", "navigation", "--trials", "2", "--threads", "2", "--seed", "4",
                              "--log", log, "-o", instance, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["attempts"].get<int>(), 30);
  EXPECT_EQ(out["deadline"].get<int>(), 22);
  EXPECT_EQ(out["effort"], "checks");
  EXPECT_EQ(out["actions"].size(), 15u);
  const std::string lines = read_file(log);
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 30);
  const auto solved = ontime({"solve", instance, "--json"});
  EXPECT_EQ(solved.exit_code, 0) << solved.err;
  // Fitting the written log again gives the same instance.
  const std::string refit = (dir / "refit.json").string();
  ASSERT_EQ(ontime({"fit", log, "--step", "3", "--deadline", "22", "--skeletons",
                    testing::source_path("data/domains/navigation.json").string(), "-o", refit, "--name", "navigation"})
                .exit_code,
            0);
  EXPECT_EQ(json::parse(read_file(refit))["actions"], json::parse(read_file(instance))["actions"]);
}

// The OMPL benchmark log of a collection fits (speed 1, planners named by their actions) the same
// instance as the collection.
TEST(Cli, CollectWritesAnOmplBenchmarkLogThatFitsTheSameInstance) {
  const std::filesystem::path dir = scratch("collect-ompl");
  const std::string log = (dir / "navigation.log").string();
  const std::string instance = (dir / "navigation.json").string();
  const auto result = ontime({"collect", "--domain", "navigation", "--trials", "2", "--threads", "2", "--seed", "4",
                              "--log", log, "--log-format", "ompl-benchmark", "-o", instance, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string text = read_file(log);
  EXPECT_EQ(text.substr(0, text.find('\n')), "Experiment navigation");
  EXPECT_NE(text.find("\n66 seconds per run\n"), std::string::npos) << text;  // 22 steps of 3 s
  EXPECT_NE(text.find("\n15 planners\n"), std::string::npos);
  const std::string refit = (dir / "refit.json").string();
  const auto fit = ontime({"fit", "--format", "ompl-benchmark", log, "--speed", "1", "--step", "3", "--deadline", "22",
                           "--skeletons", testing::source_path("data/domains/navigation.json").string(), "-o", refit,
                           "--name", "navigation", "--json"});
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_EQ(json::parse(fit.out)["records"].get<int>(), 30);
  EXPECT_EQ(json::parse(read_file(refit))["actions"], json::parse(read_file(instance))["actions"]);
}

TEST(Cli, CollectRejectsBadDomainsAndWorlds) {
  const std::filesystem::path dir = scratch("bad-world");
  const auto unknown = ontime({"collect", "--domain", "kitchen", "--trials", "1"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown domain 'kitchen'"), std::string::npos) << unknown.err;
  json world = json::parse(read_file(testing::source_path("data/domains/navigation.json")));
  world["doors"][3]["width"] = 0.5;
  const std::string bad = (dir / "world.json").string();
  std::ofstream(bad) << world.dump(1);
  const auto result = ontime({"collect", "--domain", "navigation", "--world", bad, "--trials", "1", "--log",
                              (dir / "l.jsonl").string(), "-o", (dir / "i.json").string()});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_NE(result.err.find(bad + ": doors[3].width: narrower than the robot"), std::string::npos) << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "l.jsonl"));
  EXPECT_EQ(ontime({"collect", "--domain", "navigation", "--effort", "minutes"}).exit_code, 2);
  // An output that cannot be written stops the command before any planning.
  std::ofstream(dir / "file") << "x";
  const auto unwritable = ontime({"collect", "--domain", "navigation", "--trials", "1", "--log",
                                  (dir / "file" / "l.jsonl").string(), "-o", (dir / "i.json").string()});
  EXPECT_EQ(unwritable.exit_code, 2);
  EXPECT_NE(unwritable.err.find("cannot write into"), std::string::npos) << unwritable.err;
}

// SIGINT in the middle of a collection leaves no output and a checkpoint; --resume finishes it
// with the very files an uninterrupted run writes.
TEST(Cli, AnInterruptedCollectionResumesToTheSameFiles) {
  const std::filesystem::path dir = scratch("resume");
  const std::string world = (dir / "mini.json").string();
  std::ofstream(world) << testing::kMiniWorld;
  const auto collect = [&](const std::string& name, const std::vector<std::string>& extra) {
    std::vector<std::string> arguments{ONTIME_CLI, "collect",
                                       "--domain", "navigation",
                                       "--world",  world,
                                       "--trials", "300",
                                       "--seed",   "8",
                                       "--log",    (dir / (name + ".jsonl")).string(),
                                       "-o",       (dir / (name + ".json")).string()};
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    return arguments;
  };
  ASSERT_EQ(testing::run_process(collect("whole", {})).exit_code, 0);
  const std::filesystem::path checkpoint = dir / "cut.jsonl.checkpoint";
  const auto interrupted = testing::run_process(collect("cut", {"--threads", "2"}), [&] {
    const std::string text = read_file(checkpoint);
    return std::count(text.begin(), text.end(), '\n') >= 20;
  });
  ASSERT_EQ(interrupted.exit_code, 128 + SIGINT) << interrupted.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "cut.jsonl"));
  EXPECT_FALSE(std::filesystem::exists(dir / "cut.json"));
  const std::size_t saved = line_count(checkpoint);
  EXPECT_GE(saved, 20u);
  EXPECT_LT(saved, 601u);  // the settings line and at most 600 trials: the run was cut short
  // Without --resume the checkpoint is not thrown away.
  const auto refused = testing::run_process(collect("cut", {}));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("--resume"), std::string::npos) << refused.err;
  EXPECT_EQ(line_count(checkpoint), saved);
  // Another cut-off is another collection: refused, naming the setting.
  const auto other = testing::run_process(collect("cut", {"--resume", "--budget", "5"}));
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("line 1: the checkpoint of another collection ('budget_steps'"), std::string::npos)
      << other.err;
  const auto resumed = testing::run_process(collect("cut", {"--resume", "--threads", "1", "--json"}));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(json::parse(resumed.out)["resumed_attempts"].get<std::size_t>(), saved - 1);
  EXPECT_EQ(read_file(dir / "cut.jsonl"), read_file(dir / "whole.jsonl"));
  EXPECT_EQ(read_file(dir / "cut.json"), read_file(dir / "whole.json"));
  EXPECT_FALSE(std::filesystem::exists(checkpoint));
}

TEST(Cli, CollectRunsTheManipulationDomain) {
  const std::filesystem::path dir = scratch("collect-kitchen");
  const auto result = ontime({"collect", "--domain", "manipulation", "--trials", "1", "--budget", "1", "--log",
                              (dir / "m.jsonl").string(), "-o", (dir / "m.json").string(), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["attempts"].get<int>(), 36);
  EXPECT_EQ(out["deadline"].get<int>(), 40);
  const json instance = json::parse(read_file(dir / "m.json"));
  EXPECT_EQ(instance["skeletons"].size(), 8u);
  EXPECT_EQ(instance["actions"].size(), 36u);
  EXPECT_EQ(instance["skeletons"][7].size(), 12u);
}

// The kitchen whose places give up: collect writes backtrack records and fits culprits; map draws
// it; run drives the real refiner that backtracks, with the instance's distributions or a
// belief's (here the same log read without its backtracks), and refuses a belief of other actions.
TEST(Cli, RunDrivesARefinerThatBacktracksWithABelief) {
  const std::filesystem::path dir = scratch("kitchen-grasps");
  const std::string world = testing::source_path("data/domains/kitchen-grasps.json").string();
  const auto collected = ontime({"collect", "--domain", "manipulation", "--world", world, "--trials", "2", "--log",
                                 (dir / "g.jsonl").string(), "-o", (dir / "g.json").string(), "--json"});
  ASSERT_EQ(collected.exit_code, 0) << collected.err;
  const json fitted = json::parse(read_file(dir / "g.json"));
  EXPECT_EQ(fitted["actions"]["move+place(B1,S)"]["culprits"], json({{"move+pick(B1)", 1.0}}));
  EXPECT_NE(read_file(dir / "g.jsonl").find(R"x("backtrack":"move+pick(B1)")x"), std::string::npos);

  json ignorant = json::parse(read_file(testing::source_path("data/instances/kitchen-grasps.json")));
  for (auto& [id, action] : ignorant["actions"].items()) {
    action.erase("backtrack");
    action.erase("culprits");
  }
  std::ofstream(dir / "ignorant.json") << ignorant.dump(1);
  const std::string instance = testing::source_path("data/instances/kitchen-grasps.json").string();
  const auto run =
      ontime({"run", "--domain", "manipulation", "--world", world, "--instance", instance, "--belief",
              (dir / "ignorant.json").string(), "--solver", "dp-rerun", "--episodes", "3", "--threads", "1", "--json"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json out = json::parse(run.out);
  EXPECT_EQ(out["belief"], (dir / "ignorant.json").string());
  EXPECT_EQ(out["episodes"], 3);
  EXPECT_GE(out["backtracks"].get<double>(), 0.0);

  // The map draws the regrasp and captions the infeasible direct placement instead of failing.
  const auto map = ontime({"map", "--domain", "manipulation", "--world", world, "-o", (dir / "map.png").string()});
  ASSERT_EQ(map.exit_code, 0) << map.err;
  const json drawing = json::parse(read_file(dir / "map.json"));
  ASSERT_EQ(drawing["paths"].size(), 2u);
  EXPECT_TRUE(drawing["paths"][0]["points"].empty());
  EXPECT_NE(
      drawing["paths"][0]["label"].get<std::string>().find("not refined: no motion found for move+place(B1,S) in "),
      std::string::npos);
  EXPECT_GT(drawing["paths"][1]["points"].size(), 2u);

  const std::string other = testing::source_path("data/instances/navigation.json").string();
  const auto refused = ontime({"run", "--domain", "manipulation", "--world", world, "--instance", instance, "--belief",
                               other, "--solver", "dp-rerun", "--episodes", "1"});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find(other + ": "), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("the deadlines differ (22 and 40 steps) (--belief against"), std::string::npos)
      << refused.err;
}

TEST(Cli, MapDrawsTheWorldAndOneMotionPerSkeleton) {
  const std::filesystem::path dir = scratch("map");
  const std::string png = (dir / "map.png").string();
  const auto result = ontime({"map", "--domain", "navigation", "-o", png});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const json drawing = json::parse(read_file(dir / "map.json"));
  EXPECT_EQ(drawing["paths"].size(), 4u);
  EXPECT_GT(drawing["polygons"].size(), 13u);
}

TEST(Cli, GenerateWorldWritesTheSameBuildingForTheSameSeed) {
  const std::filesystem::path dir = scratch("generate-world");
  const std::string first = (dir / "first.json").string();
  const auto result = ontime({"generate-world", "--seed", "1", "-o", first});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("30 rooms, 39 doors"), std::string::npos) << result.out;
  // The committed building is seed 1 with the defaults.
  EXPECT_EQ(read_file(first), read_file(testing::source_path("data/domains/building-6x5.json")));
  const std::string other = (dir / "other.json").string();
  ASSERT_EQ(ontime({"generate-world", "--rows", "3", "--cols", "4", "--room-size", "5", "--door-density", "1", "--seed",
                    "2", "-o", other})
                .exit_code,
            0);
  const json world = json::parse(read_file(other));
  EXPECT_EQ(world["name"], "building-3x4");
  EXPECT_EQ(world["rooms"].size(), 12u);
  EXPECT_EQ(world["doors"].size(), 17u);  // every neighbour pair: 3 x 3 + 2 x 4
  EXPECT_FALSE(world.contains("skeletons"));
  EXPECT_EQ(world["rooms"]["R12"]["max"], json::array({20, 15}));
  // Bad options: exit 2, one line, nothing written.
  const std::string never = (dir / "never.json").string();
  for (const std::vector<std::string>& bad : std::vector<std::vector<std::string>>{
           {"--rows", "0"},
           {"--cols", "51"},
           {"--rows", "1", "--cols", "1"},
           {"--room-size", "2"},
           {"--door-density", "1.5"},
           {"--narrow-doors", "-0.1"},
           {"--seed", "-1"},
       }) {
    std::vector<std::string> arguments{"generate-world", "-o", never};
    arguments.insert(arguments.end(), bad.begin(), bad.end());
    const auto refused = ontime(arguments);
    EXPECT_EQ(refused.exit_code, 2) << bad[0];
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(never)) << bad[0];
  }
  EXPECT_EQ(ontime({"generate-world"}).exit_code, 2);  // -o is required
  const auto missing = ontime({"generate-world", "-o", (dir / "no" / "such" / "folder.json").string()});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
}

// --domain manipulation writes a kitchen table scene with its goal and skeletons, the same file
// for the same options and seed, and refuses the building's options and bad ones in one line.
TEST(Cli, GenerateWorldWritesTheSameKitchenForTheSameSeed) {
  const std::filesystem::path dir = scratch("generate-kitchen");
  const std::vector<std::string> options{
      "generate-world", "--domain", "manipulation",  "--tables", "3",         "--regions", "4", "--targets", "1",
      "--min-objects",  "4",        "--max-objects", "5",        "--classes", "cup,box"};
  const auto run = [&](const std::string& file, std::vector<std::string> extra) {
    std::vector<std::string> arguments = options;
    arguments.insert(arguments.end(), {"-o", (dir / file).string()});
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    return ontime(arguments);
  };
  const auto first = run("first.json", {"--seed", "7", "--json"});
  ASSERT_EQ(first.exit_code, 0) << first.err;
  ASSERT_EQ(run("again.json", {"--seed", "7"}).exit_code, 0);
  EXPECT_EQ(read_file(dir / "first.json"), read_file(dir / "again.json"));
  const json out = json::parse(first.out);
  EXPECT_EQ(out["name"], "kitchen");
  EXPECT_EQ(out["tables"].get<int>(), 3);
  EXPECT_EQ(out["regions"].get<int>(), 4);
  EXPECT_EQ(out["goal"].size(), 1u);
  const json world = json::parse(read_file(dir / "first.json"));
  EXPECT_EQ(world["skeletons"].size(), out["skeletons"].get<std::size_t>());
  EXPECT_EQ(world["collection"]["deadline"].get<int>(), 20);
  EXPECT_GE(world["objects"].size(), 4u);
  EXPECT_LE(world["objects"].size(), 5u);
  for (const auto& [id, object] : world["objects"].items()) {
    EXPECT_TRUE(id.starts_with("cup") || id.starts_with("box")) << id;
  }
  // Another seed, another scene; the kitchen is collected along its skeletons like the paper's.
  ASSERT_EQ(run("other.json", {"--seed", "8"}).exit_code, 0);
  EXPECT_NE(read_file(dir / "other.json"), read_file(dir / "first.json"));
  const std::string never = (dir / "never.json").string();
  for (const std::vector<std::string>& bad : std::vector<std::vector<std::string>>{
           {"--min-objects", "5", "--max-objects", "4"},
           {"--min-clutter", "2", "--max-clutter", "1"},
           {"--tables", "4"},
           {"--classes", "plate"},
           {"--targets", "3"},
           {"--rows", "3"},
       }) {
    std::vector<std::string> arguments{"generate-world", "--domain", "manipulation", "-o", never};
    arguments.insert(arguments.end(), bad.begin(), bad.end());
    const auto refused = ontime(arguments);
    EXPECT_EQ(refused.exit_code, 2) << bad[0];
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_NE(refused.err.find(bad[0]), std::string::npos) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(never)) << bad[0];
  }
  const auto building = ontime({"generate-world", "--tables", "2", "-o", never});
  EXPECT_EQ(building.exit_code, 2);
  EXPECT_NE(building.err.find("--tables is an option of the manipulation generator"), std::string::npos)
      << building.err;
}

TEST(Cli, MapDrawsAGeneratedBuildingWithoutSkeletons) {
  const std::filesystem::path dir = scratch("map-building");
  const std::string png = (dir / "building.png").string();
  const auto result = ontime({"map", "--domain", "navigation", "--world",
                              testing::source_path("data/domains/building-6x5.json").string(), "-o", png});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const json drawing = json::parse(read_file(dir / "building.json"));
  EXPECT_EQ(drawing["paths"].size(), 0u);
  std::size_t rooms = 0;
  for (const json& polygon : drawing["polygons"]) rooms += polygon["kind"] == "room" ? 1 : 0;
  EXPECT_EQ(rooms, 30u);
}

// --every-action refines every doorway move in both directions, whatever the skeletons, and
// fits an instance with one skeleton per move.
TEST(Cli, CollectEveryActionCoversEveryDirectedDoor) {
  const std::filesystem::path dir = scratch("collect-every-action");
  const std::string world_file = (dir / "small.json").string();
  ASSERT_EQ(ontime({"generate-world", "--rows", "2", "--cols", "2", "--seed", "3", "-o", world_file}).exit_code, 0);
  const std::size_t doors = json::parse(read_file(world_file))["doors"].size();
  const std::string log = (dir / "small.jsonl").string();
  const std::string instance = (dir / "small-moves.json").string();
  const auto result = ontime({"collect", "--domain", "navigation", "--world", world_file, "--every-action", "--trials",
                              "2", "--threads", "2", "--log", log, "-o", instance, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json out = json::parse(result.out);
  EXPECT_EQ(out["attempts"].get<std::size_t>(), 2 * 2 * doors);
  EXPECT_TRUE(out["every_action"].get<bool>());
  const json fitted = json::parse(read_file(instance));
  ASSERT_EQ(fitted["skeletons"].size(), 2 * doors);
  std::set<std::string> moves;
  for (const json& skeleton : fitted["skeletons"]) {
    ASSERT_EQ(skeleton.size(), 1u);
    moves.insert(skeleton[0].get<std::string>());
  }
  const json world = json::parse(read_file(world_file));  // kept: the loop reads inside it
  for (const json& door : world["doors"]) {
    const std::string a = door["rooms"][0], b = door["rooms"][1];
    EXPECT_EQ(moves.count("move(" + a + "," + b + ")"), 1u);
    EXPECT_EQ(moves.count("move(" + b + "," + a + ")"), 1u);
  }
  // fit --library gives the collection's instance back.
  const std::string refit = (dir / "refit.json").string();
  ASSERT_EQ(ontime({"fit", log, "--step", "3", "--deadline", "22", "--library", "-o", refit, "--name", "navigation"})
                .exit_code,
            0);
  EXPECT_EQ(json::parse(read_file(refit))["actions"], fitted["actions"]);
  EXPECT_EQ(json::parse(read_file(refit))["skeletons"], fitted["skeletons"]);
  // Without skeletons and without --every-action there is nothing to collect.
  const auto nothing = ontime({"collect", "--domain", "navigation", "--world", world_file, "--trials", "1", "--log",
                               (dir / "n.jsonl").string(), "-o", (dir / "n.json").string()});
  EXPECT_EQ(nothing.exit_code, 2);
  EXPECT_EQ(std::count(nothing.err.begin(), nothing.err.end(), '\n'), 1) << nothing.err;
  EXPECT_NE(nothing.err.find("has no skeletons"), std::string::npos) << nothing.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "n.jsonl.checkpoint"));
  // A domain that cannot list its actions refuses --every-action.
  const auto kitchen = ontime({"collect", "--domain", "manipulation", "--every-action", "--trials", "1", "--log",
                               (dir / "k.jsonl").string(), "-o", (dir / "k.json").string()});
  EXPECT_EQ(kitchen.exit_code, 2);
  EXPECT_NE(kitchen.err.find("cannot list every action"), std::string::npos) << kitchen.err;
}

// Without output options, collect writes into the current directory's data/, and run takes its
// model from there once it exists, else the instance that comes with ontime.
TEST(Cli, CollectWritesWhereRunLooksForItsModel) {
  const std::filesystem::path dir = scratch("defaults");
  const std::string world = (dir / "mini.json").string();
  std::ofstream(world) << testing::kMiniWorld;
  const auto in_dir = [&](std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), {"/usr/bin/env", "-C", dir.string(), ONTIME_CLI});
    return testing::run_process(arguments);
  };
  const std::vector<std::string> run{"run",        "--domain", "navigation", "--solver", "dp",
                                     "--episodes", "1",        "--threads",  "1",        "--json"};
  const auto before = in_dir(run);
  ASSERT_EQ(before.exit_code, 0) << before.err;
  EXPECT_EQ(std::filesystem::path(json::parse(before.out)["instance"].get<std::string>()),
            testing::source_path("data/instances/navigation.json"));

  const auto collected = in_dir({"collect", "--domain", "navigation", "--world", world, "--trials", "2", "--json"});
  ASSERT_EQ(collected.exit_code, 0) << collected.err;
  const json out = json::parse(collected.out);
  EXPECT_EQ(out["log"], "data/logs/navigation.jsonl");
  EXPECT_EQ(out["instance"], "data/instances/navigation.json");
  EXPECT_EQ(line_count(dir / "data" / "logs" / "navigation.jsonl"), out["attempts"].get<std::size_t>());
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "data" / "instances" / "navigation.json"));

  std::vector<std::string> on_collected = run;
  on_collected.insert(on_collected.end(), {"--world", world});
  const auto after = in_dir(on_collected);
  ASSERT_EQ(after.exit_code, 0) << after.err;
  EXPECT_EQ(json::parse(after.out)["instance"], "data/instances/navigation.json");
}

// A building whose goal room has no door: every command that reads the world refuses it with
// the rule, before any work, and no library's raw warning reaches standard error.
TEST(Cli, AWorldWhoseGoalCannotBeReachedIsRefused) {
  const std::filesystem::path dir = scratch("unreachable");
  json building = json::parse(read_file(testing::source_path("data/domains/building-6x5.json")));
  json doors = json::array();
  for (const json& door : building["doors"]) {
    if (door["rooms"][0] != "R30" && door["rooms"][1] != "R30") doors.push_back(door);
  }
  ASSERT_LT(doors.size(), building["doors"].size());
  building["doors"] = doors;
  const std::string world = (dir / "walled-in.json").string();
  std::ofstream(world) << building.dump(2);
  const std::string library = testing::source_path("data/instances/building-6x5-moves.json").string();
  const std::string expected = world + ": goal_room: R30 cannot be reached from the start room R1";
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"tamp", "--world", world, "--library", library, "--deadline", "60", "--solver",
                                 "dp-rerun", "--episodes", "2"},
        std::vector<std::string>{"collect", "--domain", "navigation", "--world", world, "--every-action", "--trials",
                                 "2", "--log", (dir / "log.jsonl").string(), "-o", (dir / "instance.json").string()},
        std::vector<std::string>{"map", "--domain", "navigation", "--world", world, "-o",
                                 (dir / "map.png").string()}}) {
    const auto result = ontime(command);
    EXPECT_EQ(result.exit_code, 2) << command[0] << ": " << result.err;
    EXPECT_NE(result.err.find(expected), std::string::npos) << command[0] << ": " << result.err;
    EXPECT_EQ(result.err.find("Warning"), std::string::npos) << command[0] << ": " << result.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "log.jsonl"));
  EXPECT_FALSE(std::filesystem::exists(dir / "map.png"));
}

// An instance whose actions are not the world's (the paper's abstract actions in the building, the
// kitchen with grasps, whose objects the kitchen world does not have) is refused before any
// episode, naming the instance, the action and the world, in either acting mode.
TEST(Cli, RunRefusesAnInstanceWhoseActionsAreNotTheWorlds) {
  const std::string kitchen = testing::source_path("data/instances/kitchen-grasps.json").string();
  for (const auto& [domain, file] : {std::pair<std::string, std::string>{"navigation", paper("instance1")},
                                     std::pair<std::string, std::string>{"manipulation", kitchen}}) {
    for (const std::string act : {"plan-first", "concurrent"}) {
      const auto result = ontime(
          {"run", "--domain", domain, "--instance", file, "--solver", "greedy", "--episodes", "2", "--act", act});
      EXPECT_EQ(result.exit_code, 2) << domain << " " << act << ": " << result.err;
      EXPECT_NE(result.err.find(file + ": actions."), std::string::npos) << result.err;
      EXPECT_NE(result.err.find(": not an action of the world"), std::string::npos) << result.err;
    }
  }
}

}  // namespace
}  // namespace ontime

namespace ontime {
namespace {

using namespace cli_test;

TEST(Cli, RunActsWhilePlanningWithTheRealPlanner) {
  // Navigation at its own deadline: the robot drives each refined move while OMPL refines the next
  // from where that move ends. The model's exact value of dp-rerun's eager rule is the library's.
  const auto run = ontime({"run", "--domain", "navigation", "--solver", "dp-rerun", "--episodes", "40", "--act",
                           "concurrent", "--exact", "--json"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json out = json::parse(run.out);
  EXPECT_EQ(out["acting"], "concurrent");
  EXPECT_EQ(out["commit_rule"], allocator_registry().find("dp-rerun").commit_rule);
  const Problem navigation =
      load_problem(testing::source_path("data/instances/navigation.json").string()).with_acting(Acting::concurrent);
  const ConcurrentMdp mdp(navigation);
  const auto allocator = make_concurrent_allocator_factory("dp-rerun", mdp)();
  const double exact = evaluate_exactly(mdp, *allocator).success_probability;
  EXPECT_EQ(out["model_exact_success_probability"].get<double>(), exact);
  // Acting while planning is worth more than planning first, in the model.
  const auto plan_first =
      ontime({"run", "--domain", "navigation", "--solver", "dp-rerun", "--episodes", "1", "--exact", "--json"});
  ASSERT_EQ(plan_first.exit_code, 0) << plan_first.err;
  EXPECT_GT(exact, json::parse(plan_first.out)["model_exact_success_probability"].get<double>() + 0.2);
  EXPECT_GE(out["successes"].get<int>(), 1);

  // Live, on the robot's clock (planner calls count their nominal seconds): each episode's motions
  // with a start of the timeline for each, in order, the last one ending by the 66 s deadline on success.
  const auto live = ontime({"run", "--domain", "navigation", "--solver", "dp-rerun", "--episodes", "3", "--threads",
                            "1", "--act", "concurrent", "--live", "--json"});
  ASSERT_EQ(live.exit_code, 0) << live.err;
  const json lived = json::parse(live.out);
  EXPECT_TRUE(lived["live"].get<bool>());
  EXPECT_FALSE(lived.contains("step_clock_successes"));  // no step clock beside a concurrent session
  ASSERT_EQ(lived["episode_results"].size(), 3U);
  for (const json& episode : lived["episode_results"]) {
    std::vector<int> started;
    for (const json& step : episode["timeline"]) {
      if (step.contains("started")) started.push_back(step["started"].get<int>());
    }
    ASSERT_EQ(started.size(), episode["executions"].size());
    double free = 0;
    for (std::size_t i = 0; i < started.size(); ++i) {
      const json& execution = episode["executions"][i];
      EXPECT_EQ(execution["action"].get<int>(), started[i]);
      EXPECT_GE(execution["start"].get<double>(), free);  // one motion at a time
      free = execution["end"].get<double>();
    }
    if (episode["status"] == "success") {
      EXPECT_LE(free, 66.0 + 1e-9);
    }
  }

  // With a belief: the instance itself gives the same episodes; one in which move(R1,R5) is never
  // found gives the model value of dp-rerun deciding on its model (two skeletons hopeless to it).
  const std::filesystem::path dir = scratch("concurrent-belief");
  std::vector<Action> actions(navigation.actions().begin(), navigation.actions().end());
  actions[static_cast<std::size_t>(navigation.find_action("move(R1,R5)"))].planning = Distribution::from_pmf({0.0});
  save_problem(navigation.with_actions(std::move(actions)), dir / "belief.json");
  const std::vector<std::string> few{"run",       "--domain", "navigation", "--solver",   "dp-rerun", "--episodes", "4",
                                     "--threads", "1",        "--act",      "concurrent", "--exact",  "--json"};
  std::vector<std::string> believing_command = few;
  believing_command.insert(believing_command.end(), {"--belief", (dir / "belief.json").string()});
  std::vector<std::string> same_command = few;
  same_command.insert(same_command.end(),
                      {"--belief", testing::source_path("data/instances/navigation.json").string()});
  const auto alone = ontime(few);
  const auto same = ontime(same_command);
  const auto believing = ontime(believing_command);
  ASSERT_EQ(believing.exit_code, 0) << believing.err;
  EXPECT_EQ(json::parse(same.out)["successes"], json::parse(alone.out)["successes"]);
  EXPECT_EQ(json::parse(same.out)["model_exact_success_probability"],
            json::parse(alone.out)["model_exact_success_probability"]);
  const json believed_out = json::parse(believing.out);
  EXPECT_EQ(believed_out["belief"], (dir / "belief.json").string());
  const ConcurrentMdp world(navigation, HopelessSkeletons::kept);
  const ConcurrentMdp believed(with_distributions_of(navigation, load_problem((dir / "belief.json").string())));
  const auto believing_allocator = seen_by_belief(believed, make_concurrent_allocator_factory("dp-rerun", believed))();
  const double believed_exact = evaluate_exactly(world, *believing_allocator).success_probability;
  EXPECT_EQ(believed_out["model_exact_success_probability"].get<double>(), believed_exact);
  EXPECT_LT(believed_exact, exact - 0.05);

  for (const auto& [arguments, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--solver", "ppo"}, "ppo needs a trained policy"}}) {
    std::vector<std::string> command{"run", "--domain", "navigation", "--episodes", "2", "--act", "concurrent"};
    command.insert(command.end(), arguments.begin(), arguments.end());
    const auto refused = ontime(command);
    EXPECT_EQ(refused.exit_code, 2) << message << ": " << refused.err;
    EXPECT_NE(refused.err.find(message), std::string::npos) << refused.err;
  }
}

}  // namespace
}  // namespace ontime
