#include "ontime/domains/manipulation_features.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

using nlohmann::ordered_json;

// Index of a feature by name, so that a reordering shows as a failure here and nowhere else.
std::size_t manipulation_feature(const std::string& name) {
  const auto& names = manipulation_feature_names();
  const auto found = std::find(names.begin(), names.end(), name);
  EXPECT_NE(found, names.end()) << name;
  return static_cast<std::size_t>(found - names.begin());
}

// A room of 4 m x 3 m with one table against the back wall (x 1.0-2.4, y 2.3-3.0, top at 0.74),
// every object turned by 0 (axis-aligned), so that every value below is a sum of rectangles:
//   A   6 x 4 cm, 20 cm high, at (1.5, 2.6): x 1.47-1.53, y 2.58-2.62
//   N1  6 x 6 cm at (1.6, 2.5): x 1.57-1.63, y 2.47-2.53, in front of A and to its right
//   N2  6 x 6 cm at (1.3, 2.6): x 1.27-1.33, y 2.57-2.63, 14 cm left of A
//   F   5 x 5 cm at (2.2, 2.5): x 2.175-2.225, y 2.475-2.525
//   G   5 x 5 cm at (2.0, 2.58): x 1.975-2.025, y 2.555-2.605, partly in region R
//   R   placements x 1.9-2.1, y 2.4-2.6; P (where the objects start) x 1.05-1.15, y 2.35-2.45
// The robot's base is 0.668 m square and 0.33 m high.
constexpr const char* kMiniKitchen = R"json({
  "name": "mini-kitchen",
  "floor": {"min": [0, 0], "max": [4.0, 3.0]},
  "walls": {"thickness": 0.1, "height": 2.0},
  "robot": {
    "base": {"size": [0.668, 0.668, 0.33], "linear_speed": 1.0, "angular_speed": 1.0},
    "torso_lift": 0.15, "arm_speed": 0.5, "gripper_seconds": 1.0, "clearance": 0.01,
    "carry": [0.5, 0.6, 1.0, -1.8, -2.8, -1.0, 2.8]
  },
  "start": {"base": [2.0, 1.0, 1.5708]},
  "planner": {
    "arm_range": 0.8, "arm_resolution": 0.03, "base_range": 1.0, "base_resolution": 0.02,
    "base_distance": [0.45, 0.95], "base_heading_spread": 0.5, "approach_distance": 0.1,
    "ik_checks": 30, "target_checks": 3000, "placement_gap": 0.005
  },
  "collection": {"deadline": 40, "step_seconds": 7.0, "checks_per_second": 250},
  "fixed": {
    "table": [{"min": [1.0, 2.3, 0.7], "max": [2.4, 3.0, 0.74]}]
  },
  "regions": {
    "P": {"on": "table", "height": 0.74, "min": [1.05, 2.35], "max": [1.15, 2.45]},
    "R": {"on": "table", "height": 0.74, "min": [1.9, 2.4], "max": [2.1, 2.6]}
  },
  "objects": {
    "A": {"size": [0.06, 0.04, 0.2], "on": "P", "pose": [1.5, 2.6, 0]},
    "N1": {"size": [0.06, 0.06, 0.1], "on": "P", "pose": [1.6, 2.5, 0]},
    "N2": {"size": [0.06, 0.06, 0.1], "on": "P", "pose": [1.3, 2.6, 0]},
    "F": {"size": [0.05, 0.05, 0.1], "on": "P", "pose": [2.2, 2.5, 0]},
    "G": {"size": [0.05, 0.05, 0.1], "on": "P", "pose": [2.0, 2.58, 0]}
  },
  "goal": {"A": "R"},
  "skeletons": [
    ["move+pick(A)", "move+place(A,R)"],
    ["move+pick(N1)", "move+place(N1,R)", "move+pick(A)[N1]", "move+place(A,R)[N1]"],
    ["move+pick(N1)", "move+place(N1,R)", "move+pick(N1)[N1]", "move+place(N1,P)[N1]",
     "move+pick(A)[N1,N1]", "move+place(A,R)[N1,N1]"]
  ]
})json";

ManipulationWorld mini(const ordered_json& json) { return parse_manipulation_world(json.dump(), "mini-kitchen.json"); }
ManipulationWorld mini() { return parse_manipulation_world(kMiniKitchen, "mini-kitchen.json"); }

TEST(ManipulationFeatures, PickAmongNeighbours) {
  const std::vector<double> f = manipulation_action_features(mini(), "move+pick(A)");
  ASSERT_EQ(f.size(), manipulation_feature_names().size());
  EXPECT_EQ(f[manipulation_feature("is_place")], 0.0);
  EXPECT_DOUBLE_EQ(f[manipulation_feature("object_short")], 0.04);
  EXPECT_DOUBLE_EQ(f[manipulation_feature("object_long")], 0.06);
  EXPECT_DOUBLE_EQ(f[manipulation_feature("object_height")], 0.2);
  EXPECT_DOUBLE_EQ(f[manipulation_feature("surface_height")], 0.74);
  // The front edge (y 2.3) is open: the base fits on the floor in front of it. The back edge
  // is against the wall; the left (0.5 m) and right (0.9 m) edges are farther.
  EXPECT_NEAR(f[manipulation_feature("reach")], 0.3, 1e-12);
  // N1: 4 cm apart in x, 5 cm in y, corner to corner; N2 14 cm to the left; F and G farther.
  EXPECT_NEAR(f[manipulation_feature("nearest_gap")], std::hypot(0.04, 0.05), 1e-12);
  EXPECT_EQ(f[manipulation_feature("neighbours")], 2.0);
  // The strip x 1.35-1.65, y 2.3-2.6 (0.3 x 0.3 m) holds all of N1 (0.06 x 0.06) and nothing of N2.
  EXPECT_NEAR(f[manipulation_feature("approach_occupied")], 0.0036 / 0.09, 1e-12);
  EXPECT_EQ(f[manipulation_feature("region_area")], 0.0);
  EXPECT_EQ(f[manipulation_feature("region_occupied")], 0.0);
}

TEST(ManipulationFeatures, PlaceInAPartlyOccupiedRegion) {
  const std::vector<double> f = manipulation_action_features(mini(), "move+place(A,R)");
  EXPECT_EQ(f[manipulation_feature("is_place")], 1.0);
  EXPECT_DOUBLE_EQ(f[manipulation_feature("object_short")], 0.04);  // the held object's
  EXPECT_DOUBLE_EQ(f[manipulation_feature("object_height")], 0.2);
  EXPECT_DOUBLE_EQ(f[manipulation_feature("surface_height")], 0.74);
  EXPECT_NEAR(f[manipulation_feature("reach")], 0.2, 1e-12);  // R's centre (2.0, 2.5) to the front edge
  EXPECT_EQ(f[manipulation_feature("nearest_gap")], 0.0);     // G stands partly in the rectangle
  EXPECT_EQ(f[manipulation_feature("neighbours")], 2.0);      // G, and F 7.5 cm right of it
  EXPECT_EQ(f[manipulation_feature("approach_occupied")],
            0.0);  // x 1.85-2.15, y 2.3-2.5: G starts at 2.555, F at 2.175
  EXPECT_NEAR(f[manipulation_feature("region_area")], 0.04, 1e-12);
  EXPECT_NEAR(f[manipulation_feature("region_occupied")], 0.05 * 0.045 / 0.04, 1e-12);  // G's part: y 2.555-2.6
}

// Objects moved before the action no longer stand where they started; those placed in the
// region take their footprint's area of it.
TEST(ManipulationFeatures, TheContextMovesObjects) {
  const ManipulationWorld world = mini();
  const std::vector<double> pick = manipulation_action_features(world, "move+pick(A)[N1]");
  EXPECT_NEAR(pick[manipulation_feature("nearest_gap")], 0.14, 1e-12);  // N2
  EXPECT_EQ(pick[manipulation_feature("neighbours")], 1.0);
  EXPECT_EQ(pick[manipulation_feature("approach_occupied")], 0.0);
  const std::vector<double> place = manipulation_action_features(world, "move+place(A,R)[N1]");
  EXPECT_NEAR(place[manipulation_feature("region_occupied")], (0.05 * 0.045 + 0.06 * 0.06) / 0.04, 1e-12);
  // After N1 went to R and on to P, it counts in neither; it is picked at R's centre.
  const std::vector<double> again = manipulation_action_features(world, "move+pick(N1)[N1]");
  EXPECT_NEAR(again[manipulation_feature("nearest_gap")], 0.025, 1e-12);  // N1 at y 2.47-2.53 under G from 2.555
  EXPECT_EQ(again[manipulation_feature("neighbours")], 2.0);              // G, and F 14.5 cm to the right
  EXPECT_NEAR(again[manipulation_feature("reach")], 0.2, 1e-12);
  EXPECT_NEAR(manipulation_action_features(world, "move+place(A,R)[N1,N1]")[manipulation_feature("region_occupied")],
              0.05 * 0.045 / 0.04, 1e-12);
}

// A low box in front of the table closes its front edge: the reach is to the left edge, and the
// strip runs there. A box above the base's height does not close it. With no open edge, the
// nearest edge counts.
TEST(ManipulationFeatures, TheReachIsToAnEdgeTheBaseCanStandAt) {
  ordered_json json = ordered_json::parse(kMiniKitchen);
  json["fixed"]["bench"] = ordered_json::array({{{"min", {1.2, 1.9, 0}}, {"max", {1.8, 2.3, 0.3}}}});
  const std::vector<double> left = manipulation_action_features(mini(json), "move+pick(A)");
  EXPECT_NEAR(left[manipulation_feature("reach")], 0.5, 1e-12);
  // The strip x 1.0-1.5, y 2.45-2.75 holds all of N2: 0.0036 of 0.15 m².
  EXPECT_NEAR(left[manipulation_feature("approach_occupied")], 0.0036 / 0.15, 1e-12);

  json["fixed"]["bench"][0]["min"][2] = 0.4;
  json["fixed"]["bench"][0]["max"][2] = 0.6;
  EXPECT_NEAR(manipulation_action_features(mini(json), "move+pick(A)")[manipulation_feature("reach")], 0.3, 1e-12);

  json["fixed"]["bench"][0]["min"][2] = 0.0;
  json["fixed"]["bench"][0]["max"][2] = 0.3;
  json["fixed"]["stool"] = ordered_json::array({{{"min", {0.5, 2.3, 0}}, {"max", {1.0, 2.9, 0.3}}}});
  json["floor"]["max"][0] = 2.6;  // no room for the base right of the table
  json["start"]["base"][0] = 1.5;
  EXPECT_NEAR(manipulation_action_features(mini(json), "move+pick(A)")[manipulation_feature("reach")], 0.3, 1e-12);
}

TEST(ManipulationFeatures, TheCommittedKitchen) {
  const ManipulationWorld kitchen = load_manipulation_world(testing::source_path("data/domains/manipulation.json"));
  // B1 at the back of the shelf board (front edge y 3.2), B3 and B4 in front of it 16 cm apart:
  // the strip x 0.70-1.00, y 3.2-3.4 holds both whole (y 3.22-3.28).
  const std::vector<double> b1 = manipulation_action_features(kitchen, "move+pick(B1)");
  EXPECT_NEAR(b1[manipulation_feature("reach")], 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(b1[manipulation_feature("surface_height")], 0.85);
  EXPECT_EQ(b1[manipulation_feature("neighbours")], 2.0);
  EXPECT_NEAR(b1[manipulation_feature("nearest_gap")], std::hypot(0.05, 0.09),
              1e-12);  // B1 x 0.82-0.88, y 3.37-3.43; B3's corner
  EXPECT_NEAR(b1[manipulation_feature("approach_occupied")], 2 * 0.0036 / 0.06, 1e-12);
  const std::vector<double> freed = manipulation_action_features(kitchen, "move+pick(B1)[B3,B4]");
  EXPECT_EQ(freed[manipulation_feature("neighbours")], 0.0);
  EXPECT_EQ(freed[manipulation_feature("nearest_gap")], kManipulationGapCap);
  EXPECT_EQ(freed[manipulation_feature("approach_occupied")], 0.0);
  // With B3 and B4 moved away, more of the robot's draws reach B1.
  EXPECT_GT(freed[manipulation_feature("log_reach_share_v2")], b1[manipulation_feature("log_reach_share_v2")]);
  // B4 placed in C1 (0.45 m x 0.26 m) after B3 was: B3's footprint counts there.
  EXPECT_NEAR(manipulation_action_features(kitchen, "move+place(B4,C1)[B3]")[manipulation_feature("region_occupied")],
              0.0036 / (0.45 * 0.26), 1e-12);
}

// A ring of eight boxes 30 cm high around A's place (x 1.47-1.53, y 2.58-2.62), 1 cm from it and
// 4 mm from one another (no finger fits between): rows of three 5.6 x 4 cm boxes behind (y
// 2.63-2.67) and in front (y 2.53-2.57) of it, x 1.412-1.588, and a 4 x 5.2 cm box either side (x
// 1.42-1.46 and 1.54-1.58, y 2.574-2.626).
void add_ring_around_a(ordered_json& json) {
  for (int i = 0; i < 3; ++i) {
    const double x = 1.44 + 0.06 * i;
    json["objects"]["B" + std::to_string(i)] = {{"size", {0.056, 0.04, 0.3}}, {"on", "P"}, {"pose", {x, 2.65, 0}}};
    json["objects"]["F" + std::to_string(i)] = {{"size", {0.056, 0.04, 0.3}}, {"on", "P"}, {"pose", {x, 2.55, 0}}};
  }
  json["objects"]["S1"] = {{"size", {0.04, 0.052, 0.3}}, {"on", "P"}, {"pose", {1.44, 2.6, 0}}};
  json["objects"]["S2"] = {{"size", {0.04, 0.052, 0.3}}, {"on", "P"}, {"pose", {1.56, 2.6, 0}}};
}

// log_reach_share_v2: A alone on the table is reached by some of the robot's own target draws; walled in
// by eight taller boxes 1 cm from it, by none of 100,000 (no finger fits beside it and no
// side is open), although its gaps and neighbour count say only "crowded".
TEST(ManipulationFeatures, TheReachShareSeesAClosedApproach) {
  ordered_json json = ordered_json::parse(kMiniKitchen);
  for (const char* other : {"N1", "N2", "F", "G"}) json["objects"].erase(other);
  json["skeletons"] = ordered_json::array({{"move+pick(A)", "move+place(A,R)"}});
  const ManipulationWorld alone = mini(json);
  const std::vector<double> open = manipulation_action_features(alone, "move+pick(A)");
  EXPECT_GE(open[manipulation_feature("log_reach_share_v2")], std::log10(1.0 / kManipulationReachDraws));
  EXPECT_LE(open[manipulation_feature("log_reach_share_v2")], 0.0);
  add_ring_around_a(json);
  const std::vector<double> closed = manipulation_action_features(mini(json), "move+pick(A)");
  EXPECT_EQ(closed[manipulation_feature("log_reach_share_v2")], std::log10(kManipulationReachShareFloor));
  EXPECT_NEAR(closed[manipulation_feature("nearest_gap")], 0.01, 1e-12);
  EXPECT_EQ(closed[manipulation_feature("neighbours")], 8.0);
  // The same draws for the same world: the feature does not vary between calls.
  EXPECT_EQ(manipulation_action_features(alone, "move+pick(A)"), open);
  // Placing A in R, empty in this world, is reached too.
  EXPECT_GT(manipulation_action_features(alone, "move+place(A,R)")[manipulation_feature("log_reach_share_v2")],
            std::log10(kManipulationReachShareFloor));
}

// log_reach_share_v2 with a context: A is taken from (2.2, 2.5) and placed in W, a row along the
// table (x 1.1-1.9 at y 2.6) whose centre is the empty slot in the ring of add_ring_around_a. Set
// down at W's centre, A would stand walled in and no draw would reach it (the share the guess at
// the centre gave: the floor, for a pick the refinement finds). A refinement sets A down where it
// overlaps nothing, nearly always outside the ring, and so does each of the feature's draws: the
// share is then near A's share standing in the open.
TEST(ManipulationFeatures, TheReachShareSetsMovedObjectsDownWhereTheyFit) {
  ordered_json json = ordered_json::parse(kMiniKitchen);
  for (const char* other : {"N1", "N2", "F", "G"}) json["objects"].erase(other);
  json["objects"]["A"]["pose"] = {2.2, 2.5, 0};
  add_ring_around_a(json);
  json["regions"]["W"] = {{"on", "table"}, {"height", 0.74}, {"min", {1.1, 2.6}}, {"max", {1.9, 2.6}}};
  json["skeletons"] =
      ordered_json::array({{"move+pick(A)", "move+place(A,W)", "move+pick(A)[A]", "move+place(A,R)[A]"}});
  const ManipulationWorld world = mini(json);
  const std::size_t share = manipulation_feature("log_reach_share_v2");
  const double moved = manipulation_action_features(world, "move+pick(A)[A]")[share];
  const double in_the_open = manipulation_action_features(world, "move+pick(A)")[share];
  EXPECT_GT(moved, std::log10(kManipulationReachShareFloor));
  EXPECT_GE(moved, in_the_open - 1.0);  // the ring beside some placements blocks draws, not nine in ten
  // The layouts come from the feature's fixed seed: the same value on every call.
  EXPECT_EQ(manipulation_action_features(world, "move+pick(A)[A]")[share], moved);
}

TEST(ManipulationFeatures, RefusesWhatTheWorldDoesNotHave) {
  const ManipulationWorld world = mini();
  EXPECT_THROW(manipulation_action_features(world, "move+pick(Z)"), std::invalid_argument);      // no object
  EXPECT_THROW(manipulation_action_features(world, "move+place(A,Q)"), std::invalid_argument);   // no region
  EXPECT_THROW(manipulation_action_features(world, "move(R1,R2)"), std::invalid_argument);       // another domain's
  EXPECT_THROW(manipulation_action_features(world, "move+pick(A)[N2]"), std::invalid_argument);  // context unknown
  // Without a context, an action in no skeleton starts from the world as it is.
  EXPECT_EQ(manipulation_action_features(world, "move+pick(N2)")[manipulation_feature("neighbours")],
            1.0);  // A, 14 cm away
}

TEST(ManipulationFeatures, TheDomainGivesTheSameFeatures) {
  const ManipulationDomain domain(mini());
  EXPECT_EQ(domain.feature_names(), manipulation_feature_names());
  EXPECT_EQ(domain_feature_names("manipulation"), manipulation_feature_names());
  EXPECT_EQ(domain.action_features("move+place(A,R)[N1]"),
            manipulation_action_features(domain.world(), "move+place(A,R)[N1]"));
  EXPECT_THROW(domain.action_features("move+pick(Z)"), std::invalid_argument);
}

}  // namespace
}  // namespace ontime::domains
