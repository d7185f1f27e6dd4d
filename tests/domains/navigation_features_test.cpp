#include "ontime/domains/navigation_features.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "ontime/domains/navigation.hpp"
#include "support/mini_world.hpp"

namespace ontime::domains {
namespace {

using nlohmann::ordered_json;

// Index of a feature by name, so that a reordering shows as a failure here and nowhere else.
std::size_t navigation_feature(const std::string& name) {
  const auto& names = navigation_feature_names();
  const auto found = std::find(names.begin(), names.end(), name);
  EXPECT_NE(found, names.end()) << name;
  return static_cast<std::size_t>(found - names.begin());
}

// The mini world (tests/support/mini_world.hpp): rooms of 3 m x 3 m, doors of 1.0 m, one box of
// 1.0 m x 0.5 m turned by 0.3 rad at (7.5, 2.5) in C. Values computed by hand.
TEST(NavigationFeatures, MoveIntoAFurnishedRoom) {
  const NavigationWorld world = parse_navigation_world(testing::kMiniWorld, "mini.json");
  const std::vector<double> f = navigation_action_features(world, "move(B,C)");
  ASSERT_EQ(f.size(), navigation_feature_names().size());
  EXPECT_DOUBLE_EQ(f[navigation_feature("door_width")], 1.0);
  EXPECT_NEAR(f[navigation_feature("door_slack")], 0.292, 1e-12);  // 1.0 - (0.668 + 2 x 0.02)
  // The door's centre (6, 1.5) in the box's frame: (-1.7285, 0.5121) against half sizes (0.5,
  // 0.25): 1.2285 along and 0.2621 across, so sqrt(1.2285² + 0.2621²).
  EXPECT_NEAR(f[navigation_feature("door_furniture")], 1.2561635920864183, 1e-12);
  EXPECT_DOUBLE_EQ(f[navigation_feature("source_area")], 9.0);
  EXPECT_DOUBLE_EQ(f[navigation_feature("target_area")], 9.0);
  EXPECT_DOUBLE_EQ(f[navigation_feature("source_pieces")], 0.0);
  EXPECT_DOUBLE_EQ(f[navigation_feature("target_pieces")], 1.0);
  EXPECT_DOUBLE_EQ(f[navigation_feature("source_occupied")], 0.0);
  EXPECT_NEAR(f[navigation_feature("target_occupied")], 0.5 / 9, 1e-15);
  EXPECT_DOUBLE_EQ(f[navigation_feature("route_length")], 3.0);    // (4.5, 1.5) to (6, 1.5) to (7.5, 1.5)
  EXPECT_DOUBLE_EQ(f[navigation_feature("sampling_area")], 18.0);  // x 3..9, y 0..3

  // The other direction swaps the rooms' features and keeps the door's.
  const std::vector<double> back = navigation_action_features(world, "move(C,B)");
  EXPECT_DOUBLE_EQ(back[navigation_feature("source_pieces")], 1.0);
  EXPECT_DOUBLE_EQ(back[navigation_feature("target_pieces")], 0.0);
  EXPECT_NEAR(back[navigation_feature("source_occupied")], 0.5 / 9, 1e-15);
  EXPECT_DOUBLE_EQ(back[navigation_feature("door_furniture")], f[navigation_feature("door_furniture")]);
  EXPECT_DOUBLE_EQ(back[navigation_feature("route_length")], 3.0);
}

TEST(NavigationFeatures, NoFurnitureNearTheDoorIsTheCap) {
  const NavigationWorld world = parse_navigation_world(testing::kMiniWorld, "mini.json");
  const std::vector<double> f = navigation_action_features(world, "move(B,D)");
  EXPECT_DOUBLE_EQ(f[navigation_feature("door_furniture")], kFeatureDistanceCap);
  EXPECT_DOUBLE_EQ(f[navigation_feature("sampling_area")], 18.0);  // x 3..6, y 0..6
  EXPECT_DOUBLE_EQ(f[navigation_feature("route_length")], 3.0);
}

// Two doors between the same rooms: the wider one counts (the planner finds the easier passage).
// A narrower door and a roomier room change exactly their own features.
TEST(NavigationFeatures, TheWiderOfTwoDoorsAndEachChangeItsOwnFeature) {
  ordered_json json = ordered_json::parse(testing::kMiniWorld);
  json["doors"].push_back({{"rooms", {"A", "B"}}, {"center", {3, 2.4}}, {"width", 0.8}});
  const NavigationWorld two = parse_navigation_world(json.dump(), "two.json");
  EXPECT_DOUBLE_EQ(navigation_action_features(two, "move(A,B)")[navigation_feature("door_width")], 1.0);

  json = ordered_json::parse(testing::kMiniWorld);
  json["doors"][0]["width"] = 0.8;
  json["rooms"]["A"]["min"] = {-1, 0};
  const NavigationWorld narrow = parse_navigation_world(json.dump(), "narrow.json");
  const NavigationWorld mini = parse_navigation_world(testing::kMiniWorld, "mini.json");
  const std::vector<double> before = navigation_action_features(mini, "move(A,B)");
  const std::vector<double> after = navigation_action_features(narrow, "move(A,B)");
  EXPECT_NEAR(after[navigation_feature("door_slack")], 0.092, 1e-12);
  EXPECT_DOUBLE_EQ(after[navigation_feature("source_area")], 12.0);
  EXPECT_DOUBLE_EQ(after[navigation_feature("sampling_area")], 21.0);
  EXPECT_DOUBLE_EQ(after[navigation_feature("route_length")],
                   before[navigation_feature("route_length")] + 0.5);  // A's centre moved 0.5 m
  EXPECT_EQ(after[navigation_feature("target_area")], before[navigation_feature("target_area")]);
  EXPECT_EQ(after[navigation_feature("target_pieces")], before[navigation_feature("target_pieces")]);
}

TEST(NavigationFeatures, RefusesWhatTheWorldDoesNotHave) {
  const NavigationWorld world = parse_navigation_world(testing::kMiniWorld, "mini.json");
  EXPECT_THROW(navigation_action_features(world, "move(A,C)"), std::invalid_argument);  // no door
  EXPECT_THROW(navigation_action_features(world, "move(A,Z)"), std::invalid_argument);  // no room
  EXPECT_THROW(navigation_action_features(world, "pick(B1)"), std::invalid_argument);
}

TEST(NavigationFeatures, TheDomainGivesTheSameFeatures) {
  const NavigationDomain domain(parse_navigation_world(testing::kMiniWorld, "mini.json"));
  EXPECT_EQ(domain.feature_names(), navigation_feature_names());
  EXPECT_EQ(domain.action_features("move(B,C)"), navigation_action_features(domain.world(), "move(B,C)"));
}

}  // namespace
}  // namespace ontime::domains
