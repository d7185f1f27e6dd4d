#include "ontime/domains/navigation_world.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <set>

#include "ontime/domains/navigation_collision.hpp"
#include "ontime/util/error.hpp"
#include "support/mini_world.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

using nlohmann::ordered_json;

NavigationWorld office_world() { return load_navigation_world(testing::source_path("data/domains/navigation.json")); }

TEST(NavigationWorld, LoadsTheOfficeFloor) {
  const NavigationWorld world = office_world();
  EXPECT_EQ(world.rooms.size(), 13u);
  EXPECT_EQ(world.doors.size(), 15u);
  EXPECT_EQ(world.start_room, "R1");
  EXPECT_EQ(world.goal_room, "R13");
  EXPECT_EQ(world.collection.deadline, 22);
  EXPECT_EQ(world.skeletons.size(), 4u);
  const Room& r6 = world.room("R6");
  EXPECT_DOUBLE_EQ(r6.max_x - r6.min_x, 3.0);
  EXPECT_FALSE(world.walls.empty());
}

TEST(NavigationWorld, TheFourSkeletonsAreExactlyTheRoomPathsFromStartToGoal) {
  const NavigationWorld world = office_world();
  std::set<std::vector<std::string>> from_doors;
  for (const auto& path : world.room_paths(world.start_room, world.goal_room)) from_doors.insert(path);
  std::set<std::vector<std::string>> from_skeletons;
  for (const auto& skeleton : world.skeletons) {
    std::vector<std::string> rooms{world.start_room};
    for (const std::string& action : skeleton) rooms.push_back(move_rooms(action).at(1));
    from_skeletons.insert(rooms);
  }
  EXPECT_EQ(from_doors.size(), 4u);
  EXPECT_EQ(from_doors, from_skeletons);
  // The skeletons are the paper's (Section VII-A), sigma2 and sigma3 sharing move(R1,R5).
  EXPECT_EQ(world.skeletons[1][0], "move(R1,R5)");
  EXPECT_EQ(world.skeletons[2][0], "move(R1,R5)");
  EXPECT_EQ(world.skeletons[3],
            (std::vector<std::string>{"move(R1,R10)", "move(R10,R11)", "move(R11,R12)", "move(R12,R13)"}));
}

TEST(NavigationWorld, WallsCloseEveryRoomExceptAtDoors) {
  const NavigationWorld world = office_world();
  const NavigationCollision bare(world, 0.0);
  // A thin probe robot cannot cross a wall between two rooms that share no door (R2 above R5)
  // but passes the centre of every door.
  NavigationWorld thin = world;
  thin.robot.length = thin.robot.width = 0.05;
  const NavigationCollision probe(thin, 0.0);
  EXPECT_TRUE(probe.collides(Pose{4.5, 9.0, 0.0}));  // the wall between R2 and R5
  EXPECT_TRUE(probe.collides(Pose{7.5, 6.0, 0.0}));  // the wall between R6 and R8
  for (const Door& door : world.doors) {
    EXPECT_FALSE(probe.collides(Pose{door.x, door.y, 0.0})) << door.rooms[0] << "-" << door.rooms[1];
    const double beside = door.width / 2 + 0.05;  // just past the opening, inside the wall
    const Pose wall = door.on_vertical_edge ? Pose{door.x, door.y + beside, 0.0} : Pose{door.x + beside, door.y, 0.0};
    EXPECT_TRUE(probe.collides(wall)) << door.rooms[0] << "-" << door.rooms[1];
  }
  EXPECT_FALSE(bare.collides(world.start));
}

TEST(NavigationWorld, ReadsMoveActions) {
  EXPECT_EQ(move_rooms("move(R1,R13)"), (std::vector<std::string>{"R1", "R13"}));
  EXPECT_TRUE(move_rooms("move(R1)").empty());
  EXPECT_TRUE(move_rooms("pick(B1)").empty());
  EXPECT_TRUE(move_rooms("move(R1, R2)").empty());
}

struct BadNavigationWorld {
  std::string what;
  std::function<void(ordered_json&)> edit;
  std::string place;
  std::string rule;
};

TEST(NavigationWorld, EveryBrokenRuleIsReportedWithItsPlace) {
  const std::vector<BadNavigationWorld> cases{
      {"negative wall", [](ordered_json& w) { w["wall_thickness"] = -1; }, "wall_thickness", "positive number"},
      {"unknown key", [](ordered_json& w) { w["colour"] = "red"; }, "colour", "unknown key"},
      {"no rooms", [](ordered_json& w) { w.erase("rooms"); }, "top level", "missing required key 'rooms'"},
      {"overlap",
       [](ordered_json& w) {
         w["rooms"]["B"]["min"] = {2.5, 0};
       },
       "rooms.B", "overlaps room A"},
      {"inverted",
       [](ordered_json& w) {
         w["rooms"]["D"]["max"] = {6, 2};
       },
       "rooms.D", "'max' must exceed 'min'"},
      {"tiny room",
       [](ordered_json& w) {
         w["rooms"]["D"]["max"] = {6, 3.7};
       },
       "rooms.D", "too small for the robot"},
      {"room not a box", [](ordered_json& w) { w["rooms"]["A"]["min"] = {0}; }, "rooms.A.min", "array of 2 numbers"},
      {"door far",
       [](ordered_json& w) {
         w["doors"][0]["rooms"] = {"A", "C"};
       },
       "doors[0].rooms", "share no edge"},
      {"door corner to corner",
       [](ordered_json& w) {
         w["doors"][0]["rooms"] = {"A", "D"};
       },
       "doors[0].rooms", "share no edge"},
      {"door off edge",
       [](ordered_json& w) {
         w["doors"][0]["center"] = {3.2, 1.5};
       },
       "doors[0].center", "not on the edge x = 3"},
      {"door narrow", [](ordered_json& w) { w["doors"][1]["width"] = 0.7; }, "doors[1].width",
       "narrower than the robot"},
      {"door corner",
       [](ordered_json& w) {
         w["doors"][0]["center"] = {3, 0.3};
       },
       "doors[0]", "does not fit"},
      {"door room", [](ordered_json& w) { w["doors"][2]["rooms"][1] = "Z"; }, "doors[2].rooms[1]", "unknown room 'Z'"},
      {"door same room",
       [](ordered_json& w) {
         w["doors"][2]["rooms"] = {"B", "B"};
       },
       "doors[2].rooms", "two different rooms"},
      {"obstacle outside",
       [](ordered_json& w) {
         w["obstacles"][0]["center"] = {7.5, 4.5};
       },
       "obstacles[0].center", "not inside any room"},
      {"obstacle size",
       [](ordered_json& w) {
         w["obstacles"][0]["size"] = {1.0, 0};
       },
       "obstacles[0].size", "must be positive"},
      {"obstacle angle", [](ordered_json& w) { w["obstacles"][0]["angle"] = "flat"; }, "obstacles[0].angle",
       "must be a number"},
      {"start blocked",
       [](ordered_json& w) {
         w["obstacles"][0]["center"] = {1.5, 1.5};
       },
       "start.pose", "collides"},
      {"start elsewhere",
       [](ordered_json& w) {
         w["start"]["pose"] = {4.5, 1.5, 0};
       },
       "start.pose", "not inside the start room A"},
      {"start room", [](ordered_json& w) { w["start"]["room"] = "Q"; }, "start.room", "unknown room 'Q'"},
      {"goal is start", [](ordered_json& w) { w["goal_room"] = "A"; }, "goal_room", "must differ"},
      {"goal unreachable",
       [](ordered_json& w) {
         ordered_json doors = ordered_json::array();
         for (const auto& door : w["doors"]) {
           if (door["rooms"][0] != "C" && door["rooms"][1] != "C") doors.push_back(door);
         }
         w["doors"] = doors;
       },
       "goal_room", "C cannot be reached from the start room A"},
      {"resolution", [](ordered_json& w) { w["planner"]["resolution"] = 0.1; }, "planner.resolution",
       "below the wall thickness"},
      {"range", [](ordered_json& w) { w["planner"]["range"] = 0; }, "planner.range", "positive number"},
      {"deadline", [](ordered_json& w) { w["collection"]["deadline"] = 0; }, "collection.deadline",
       "whole number of steps"},
      {"rate", [](ordered_json& w) { w["collection"]["checks_per_second"] = -5; }, "collection.checks_per_second",
       "positive"},
      {"speed", [](ordered_json& w) { w["robot"]["linear_speed"] = 0; }, "robot.linear_speed", "positive number"},
      {"footprint",
       [](ordered_json& w) {
         w["robot"]["footprint"] = {0.6, -1};
       },
       "robot.footprint", "must be positive"},
      {"not a move", [](ordered_json& w) { w["skeletons"][0][1] = "fly(B,C)"; }, "skeletons[0][1]",
       "is not move(FROM,TO)"},
      {"no door",
       [](ordered_json& w) {
         w["skeletons"][0] = {"move(A,B)", "move(B,C)", "move(C,D)", "move(D,B)"};
         w["goal_room"] = "B";
       },
       "skeletons[0][2]", "no door joins C and D"},
      {"wrong start", [](ordered_json& w) { w["skeletons"][0][0] = "move(B,A)"; }, "skeletons[0][0]",
       "starts in B but the robot is in A"},
      {"wrong end",
       [](ordered_json& w) {
         w["skeletons"][0] = {"move(A,B)", "move(B,D)"};
       },
       "skeletons[0]", "not in the goal room C"},
      {"skeleton rule", [](ordered_json& w) { w["skeletons"] = ordered_json::array(); }, "skeletons",
       "at least one skeleton"},
  };
  for (const BadNavigationWorld& bad : cases) {
    ordered_json world = ordered_json::parse(testing::kMiniWorld);
    bad.edit(world);
    try {
      parse_navigation_world(world.dump(), "world.json");
      ADD_FAILURE() << bad.what << ": accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), "world.json") << bad.what;
      EXPECT_EQ(error.place(), bad.place) << bad.what << ": " << error.what();
      EXPECT_NE(error.rule().find(bad.rule), std::string::npos) << bad.what << ": " << error.what();
    }
  }
}

TEST(NavigationWorld, MalformedTextIsReportedWithLineAndColumn) {
  try {
    parse_navigation_world("{\n  \"rooms\": {,\n}", "world.json");
    FAIL() << "accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "line 2, column 13");
    EXPECT_NE(error.rule().find("invalid JSON"), std::string::npos);
  }
  try {
    parse_navigation_world(R"({"wall_thickness": 0.1, "wall_thickness": 0.2})", "world.json");
    FAIL() << "accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "wall_thickness");
    EXPECT_NE(error.rule().find("duplicate key"), std::string::npos);
  }
}

// Skeletons are optional: a world may be only a map, its skeletons left to a task planner.
TEST(NavigationWorld, AWorldWithoutSkeletonsHasNone) {
  ordered_json world = ordered_json::parse(testing::kMiniWorld);
  world.erase("skeletons");
  const NavigationWorld read = parse_navigation_world(world.dump(), "map.json");
  EXPECT_TRUE(read.skeletons.empty());
  EXPECT_EQ(read.doors.size(), 3u);
}

TEST(NavigationWorld, TheMiniWorldIsValid) {
  const NavigationWorld world = parse_navigation_world(testing::kMiniWorld, "mini.json");
  EXPECT_EQ(world.room_paths("A", "C"), (std::vector<std::vector<std::string>>{{"A", "B", "C"}}));
  EXPECT_EQ(world.room_paths("D", "C"), (std::vector<std::vector<std::string>>{{"D", "B", "C"}}));
}

}  // namespace
}  // namespace ontime::domains
