#include "ontime/domains/manipulation_world.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>

#include "ontime/domains/collection.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

using nlohmann::ordered_json;

std::string kitchen_text() {
  std::ifstream in(testing::source_path("data/domains/manipulation.json"));
  return std::string(std::istreambuf_iterator<char>(in), {});
}

ManipulationWorld kitchen_world() {
  return load_manipulation_world(testing::source_path("data/domains/manipulation.json"));
}

std::vector<std::string> abstract(const std::vector<std::string>& skeleton) {
  std::vector<std::string> result;
  for (const std::string& id : skeleton) result.push_back(parse_manipulation_action(id).value().abstract());
  return result;
}

TEST(ManipulationWorld, LoadsTheKitchen) {
  const ManipulationWorld world = kitchen_world();
  EXPECT_EQ(world.objects.size(), 6u);
  EXPECT_EQ(world.regions.size(), 4u);
  EXPECT_EQ(world.collection.deadline, 40);
  EXPECT_EQ(world.goal, (std::vector<std::pair<std::string, std::string>>{{"B1", "R1"}, {"B2", "R2"}}));
  // Objects rest on their surface, the placement gap above it.
  const MovableObject& b1 = world.objects[static_cast<std::size_t>(world.object_index("B1"))];
  EXPECT_DOUBLE_EQ(b1.pose.z, 0.85 + world.planner.placement_gap + 0.1);
  EXPECT_EQ(world.walls.size(), 4u);
  EXPECT_EQ(world.planner.placement_draws, 0) << "places never give up unless the world says so";
}

TEST(ManipulationWorld, LoadsTheKitchenWhosePlacesGiveUp) {
  const ManipulationWorld world = load_manipulation_world(testing::source_path("data/domains/kitchen-grasps.json"));
  EXPECT_EQ(world.planner.placement_draws, 300);
  const PlacementRegion& cubby = world.regions[static_cast<std::size_t>(world.region_index("S"))];
  EXPECT_DOUBLE_EQ(cubby.yaw_low, -0.2);
  EXPECT_DOUBLE_EQ(cubby.yaw_high, 0.2);
  EXPECT_EQ(world.skeletons.size(), 2u);
}

TEST(ManipulationWorld, TheSkeletonsAreThoseOfAppendixA) {
  std::ifstream in(testing::source_path("data/domains/paper-skeletons.json"));
  const ordered_json paper = ordered_json::parse(in)["manipulation"];
  const ManipulationWorld world = kitchen_world();
  ASSERT_EQ(world.skeletons.size(), paper["skeletons"].size());
  for (std::size_t k = 0; k < world.skeletons.size(); ++k) {
    EXPECT_EQ(abstract(world.skeletons[k]), paper["skeletons"][k].get<std::vector<std::string>>()) << "sigma" << k + 1;
  }
  // Sharing as the appendix gives it: sigma1-4 share pick and place of B1, sigma5-8 the clearing
  // of B3 and B4 and then B1, sigma3 and sigma4 four actions, sigma7 and sigma8 eight.
  const auto shared = [&](std::size_t a, std::size_t b) {
    std::size_t n = 0;
    while (n < world.skeletons[a].size() && n < world.skeletons[b].size() &&
           world.skeletons[a][n] == world.skeletons[b][n])
      ++n;
    return n;
  };
  EXPECT_EQ(shared(0, 1), 2u);
  EXPECT_EQ(shared(0, 3), 2u);
  EXPECT_EQ(shared(2, 3), 4u);
  EXPECT_EQ(shared(4, 5), 6u);
  EXPECT_EQ(shared(4, 7), 6u);
  EXPECT_EQ(shared(6, 7), 8u);
  EXPECT_EQ(shared(0, 4), 0u);
  // Every tree node is its own refinement problem: 36 actions for 64 positions.
  EXPECT_EQ(skeleton_tree(world.skeletons).size(), 36u);
  // The same abstract action after another prefix has another id.
  EXPECT_NE(world.skeletons[0][2], world.skeletons[4][6]);
  EXPECT_EQ(abstract({world.skeletons[0][2]}), abstract({world.skeletons[4][6]}));
}

TEST(ManipulationWorld, ReadsActionIds) {
  const auto pick = parse_manipulation_action("move+pick(B2)[B3,B4,B1]").value();
  EXPECT_EQ(pick.kind, ManipulationKind::pick);
  EXPECT_EQ(pick.object, "B2");
  EXPECT_EQ(pick.context, (std::vector<std::string>{"B3", "B4", "B1"}));
  EXPECT_EQ(pick.abstract(), "move+pick(B2)");
  const auto place = parse_manipulation_action("move+place(B1,R1)").value();
  EXPECT_EQ(place.kind, ManipulationKind::place);
  EXPECT_EQ(place.region, "R1");
  EXPECT_TRUE(place.context.empty());
  for (const char* bad : {"move+pick(B1,R1)", "move+place(B1)", "pick(B1)", "move+pick(B1)[]", "move+pick(B1)[B2,]",
                          "move+pick(B1)[B2", "move+pick( B1)", "move(R1,R2)"}) {
    EXPECT_FALSE(parse_manipulation_action(bad).has_value()) << bad;
  }
}

struct BadKitchenWorld {
  std::string what;
  std::function<void(ordered_json&)> edit;
  std::string place;
  std::string rule;
};

TEST(ManipulationWorld, EveryBrokenRuleIsReportedWithItsPlace) {
  const std::vector<BadKitchenWorld> cases{
      {"unknown key", [](ordered_json& w) { w["colour"] = "red"; }, "colour", "unknown key"},
      {"no objects", [](ordered_json& w) { w.erase("objects"); }, "top level", "missing required key 'objects'"},
      {"floor",
       [](ordered_json& w) {
         w["floor"]["max"] = {0, 3};
       },
       "floor", "'max' must exceed 'min'"},
      {"box outside", [](ordered_json& w) { w["fixed"]["worktop"][0]["max"][0] = 7.0; }, "fixed.worktop[0]",
       "within the floor"},
      {"box inverted", [](ordered_json& w) { w["fixed"]["table"][0]["max"][2] = 0.6; }, "fixed.table[0]",
       "'max' must exceed"},
      {"region surface", [](ordered_json& w) { w["regions"]["R1"]["on"] = "oven"; }, "regions.R1.on",
       "unknown furniture 'oven'"},
      {"region height", [](ordered_json& w) { w["regions"]["R1"]["height"] = 0.8; }, "regions.R1", "top at height 0.8"},
      {"region off the top", [](ordered_json& w) { w["regions"]["R2"]["max"][0] = 3.9; }, "regions.R2",
       "under the whole rectangle"},
      {"region yaw",
       [](ordered_json& w) {
         w["regions"]["C1"]["yaw"] = {1, 0};
       },
       "regions.C1.yaw", "must not be below"},
      {"region id", [](ordered_json& w) { w["regions"]["R 3"] = w["regions"]["R1"]; }, "regions.\"R 3\"", "region ids"},
      {"object region", [](ordered_json& w) { w["objects"]["B1"]["on"] = "R9"; }, "objects.B1.on",
       "unknown region 'R9'"},
      {"object floating",
       [](ordered_json& w) {
         w["objects"]["B1"]["pose"] = {2.0, 1.0, 0};
       },
       "objects.B1.pose", "does not stand on"},
      {"object too wide",
       [](ordered_json& w) {
         w["objects"]["B2"]["size"] = {0.08, 0.06, 0.2};
       },
       "objects.B2.size", "gripper could not close"},
      {"object flat",
       [](ordered_json& w) {
         w["objects"]["B2"]["size"] = {0.06, 0.06, 0.05};
       },
       "objects.B2.size", "z must exceed"},
      {"objects overlap",
       [](ordered_json& w) {
         w["objects"]["B3"]["pose"] = {0.86, 3.40, 0};
       },
       "objects.B1", "overlaps"},
      {"goal object", [](ordered_json& w) { w["goal"]["B9"] = "R1"; }, "goal.B9", "unknown object 'B9'"},
      {"carry limit", [](ordered_json& w) { w["robot"]["carry"][3] = 0.5; }, "robot.carry[3]",
       "l_elbow_flex_joint must lie within"},
      {"torso", [](ordered_json& w) { w["robot"]["torso_lift"] = 0.5; }, "robot.torso_lift", "0 to 0.33 m"},
      {"arm speed", [](ordered_json& w) { w["robot"]["arm_speed"] = 1.5; }, "robot.arm_speed", "at most 1"},
      {"start outside",
       [](ordered_json& w) {
         w["start"]["base"] = {-1.0, 1.0, 0};
       },
       "start.base", "not on the floor"},
      {"start blocked",
       [](ordered_json& w) {
         w["start"]["base"] = {3.0, 3.2, 0};
       },
       "start.base", "collides"},
      {"base distance",
       [](ordered_json& w) {
         w["planner"]["base_distance"] = {0.9, 0.5};
       },
       "planner.base_distance", "nearest < farthest"},
      {"ik checks", [](ordered_json& w) { w["planner"]["ik_checks"] = 2.5; }, "planner.ik_checks", "whole number"},
      {"placement draws", [](ordered_json& w) { w["planner"]["placement_draws"] = -1; }, "planner.placement_draws",
       "whole number"},
      {"base resolution", [](ordered_json& w) { w["planner"]["base_resolution"] = 0.2; }, "planner.base_resolution",
       "below the wall thickness"},
      {"not an action", [](ordered_json& w) { w["skeletons"][0][1] = "fly(B1)"; }, "skeletons[0][1]",
       "neither move+pick"},
      {"wrong context", [](ordered_json& w) { w["skeletons"][0][2] = "move+pick(B2)"; }, "skeletons[0][2]",
       "must list the objects moved before it: [B1]"},
      {"full hand",
       [](ordered_json& w) {
         w["skeletons"][0] = {"move+pick(B1)", "move+pick(B2)"};
       },
       "skeletons[0][1]", "already holds B1"},
      {"empty hand", [](ordered_json& w) { w["skeletons"][0] = {"move+place(B5,C2)"}; }, "skeletons[0][0]",
       "the hand is empty"},
      {"unknown region", [](ordered_json& w) { w["skeletons"][0][1] = "move+place(B1,R7)"; }, "skeletons[0][1]",
       "unknown region 'R7'"},
      {"goal missed",
       [](ordered_json& w) {
         w["skeletons"][0] = {"move+pick(B1)", "move+place(B1,R1)"};
       },
       "skeletons[0]", "does not bring B2 to R2"},
      {"holding at the end", [](ordered_json& w) { w["skeletons"][0].erase(3); }, "skeletons[0]",
       "ends with B2 in the hand"},
      {"skeleton rule", [](ordered_json& w) { w["skeletons"][1] = w["skeletons"][0]; }, "skeletons[1]",
       "the same skeleton as skeletons[0]"},
  };
  for (const BadKitchenWorld& bad : cases) {
    ordered_json world = ordered_json::parse(kitchen_text());
    bad.edit(world);
    try {
      parse_manipulation_world(world.dump(), "kitchen.json");
      ADD_FAILURE() << bad.what << ": accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), "kitchen.json") << bad.what;
      EXPECT_EQ(error.place(), bad.place) << bad.what << ": " << error.what();
      EXPECT_NE(error.rule().find(bad.rule), std::string::npos) << bad.what << ": " << error.what();
    }
  }
}

}  // namespace
}  // namespace ontime::domains
