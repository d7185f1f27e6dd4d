#include "ontime/domains/navigation_generator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>

#include "ontime/domains/navigation.hpp"
#include "ontime/domains/navigation_collision.hpp"
#include "ontime/util/input_file.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

BuildingOptions building(std::uint64_t seed, int rows = 6, int cols = 5) {
  BuildingOptions options;
  options.rows = rows;
  options.cols = cols;
  options.seed = seed;
  return options;
}

// Neighbouring room pairs of a rows x cols grid.
int neighbour_pairs(int rows, int cols) { return rows * (cols - 1) + (rows - 1) * cols; }

// Rooms reachable from `from` through doors.
std::size_t reachable(const NavigationWorld& world, const std::string& from) {
  std::set<std::string> seen{from};
  std::vector<std::string> frontier{from};
  while (!frontier.empty()) {
    const std::string room = frontier.back();
    frontier.pop_back();
    for (const Door& door : world.doors) {
      for (int side = 0; side < 2; ++side) {
        if (door.rooms[side] == room && seen.insert(door.rooms[1 - side]).second) {
          frontier.push_back(door.rooms[1 - side]);
        }
      }
    }
  }
  return seen.size();
}

TEST(NavigationGenerator, TheSameSeedWritesTheSameFileAndAnotherSeedAnother) {
  const std::string first = generate_navigation_world_text(building(1));
  EXPECT_EQ(generate_navigation_world_text(building(1)), first);
  EXPECT_NE(generate_navigation_world_text(building(2)), first);
  BuildingOptions denser = building(1);
  denser.door_density = 1.0;
  EXPECT_NE(generate_navigation_world_text(denser), first);
}

TEST(NavigationGenerator, TheCommittedBuildingIsSeedOneWithTheDefaults) {
  EXPECT_EQ(generate_navigation_world_text(building(1)),
            read_input_file(testing::source_path("data/domains/building-6x5.json"), "world"));
}

TEST(NavigationGenerator, WritesAWorldTheCheckerAcceptsWithTheOfficeSettings) {
  const NavigationWorld world = parse_navigation_world(generate_navigation_world_text(building(1)), "b.json");
  const NavigationWorld office = load_navigation_world(testing::source_path("data/domains/navigation.json"));
  EXPECT_EQ(world.name, "building-6x5");
  ASSERT_EQ(world.rooms.size(), 30u);
  for (const Room& room : world.rooms) {
    EXPECT_DOUBLE_EQ(room.max_x - room.min_x, 4.0);
    EXPECT_DOUBLE_EQ(room.max_y - room.min_y, 4.0);
  }
  // Round(0.8 x 49 neighbour pairs) doors, at least a spanning tree: every room is reachable.
  EXPECT_EQ(world.doors.size(), static_cast<std::size_t>(std::lround(0.8 * neighbour_pairs(6, 5))));
  EXPECT_EQ(reachable(world, world.start_room), world.rooms.size());
  EXPECT_TRUE(world.skeletons.empty());
  EXPECT_FALSE(world.obstacles.empty());
  // The deadline grows with the building: 5 steps a move of a shortest path (9 moves here).
  EXPECT_EQ(world.collection.deadline, 45);
  EXPECT_EQ(generate_navigation_world(building(1, 2, 3)).collection.deadline, office.collection.deadline);
  EXPECT_EQ(world.collection.step_seconds, office.collection.step_seconds);
  EXPECT_EQ(world.collection.checks_per_second, office.collection.checks_per_second);
  EXPECT_EQ(world.planner.range, office.planner.range);
  EXPECT_EQ(world.planner.resolution, office.planner.resolution);
  EXPECT_EQ(world.robot.length, office.robot.length);
  EXPECT_EQ(world.robot.clearance, office.robot.clearance);
}

TEST(NavigationGenerator, DoorWidthsVaryFromNarrowToComfortable) {
  const NavigationWorld world = generate_navigation_world(building(1));
  const double passable = world.robot.width + 2 * world.robot.clearance;
  std::size_t narrow = 0, comfortable = 0;
  for (const Door& door : world.doors) {
    EXPECT_GT(door.width, passable);
    if (door.width < 0.9) ++narrow;
    if (door.width >= 1.0 && door.width <= 1.2) ++comfortable;
  }
  EXPECT_EQ(narrow + comfortable, world.doors.size());
  EXPECT_GT(narrow, 0u);
  EXPECT_GT(comfortable, world.doors.size() / 2);
}

TEST(NavigationGenerator, RoomsRangeFromEmptyToCluttered) {
  const NavigationWorld world = generate_navigation_world(building(1));
  std::map<std::string, int> pieces;
  for (const Obstacle& obstacle : world.obstacles) {
    for (const Room& room : world.rooms) {
      if (room.contains(obstacle.shape.x, obstacle.shape.y)) ++pieces[room.id];
    }
  }
  std::size_t empty = 0;
  int most = 0;
  for (const Room& room : world.rooms) {
    empty += pieces[room.id] == 0 ? 1 : 0;
    most = std::max(most, pieces[room.id]);
  }
  EXPECT_GT(empty, 0u);
  EXPECT_GE(most, 4);
}

// Into both rooms of every door: the robot drives through the door, turns, drives to the room's
// centre and turns there, collision-free with its clearance, in every generated world.
TEST(NavigationGenerator, EveryDoorIsPassableFromBothSidesAndEveryRoomCanBeCrossed) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    for (const auto& [rows, cols] : {std::pair{6, 5}, std::pair{2, 3}}) {
      const NavigationWorld world = generate_navigation_world(building(seed, rows, cols));
      const NavigationCollision collision(world, world.robot.clearance);
      for (const Door& door : world.doors) {
        for (const std::string& id : door.rooms) {
          const std::vector<Pose> route = door_route(world, door, id);
          ASSERT_GT(route.size(), 2u);
          EXPECT_DOUBLE_EQ(route.front().x, door.x);
          EXPECT_DOUBLE_EQ(route.front().y, door.y);
          // A pose on this side of the door, inside the room.
          EXPECT_TRUE(world.room(id).contains(route[route.size() / 4].x, route[route.size() / 4].y));
          for (const Pose& pose : route) {
            ASSERT_FALSE(collision.collides(pose))
                << "seed " << seed << ", door " << door.rooms[0] << "-" << door.rooms[1] << " into " << id << " at "
                << pose.x << ", " << pose.y << ", " << pose.theta;
          }
        }
      }
    }
  }
}

TEST(NavigationGenerator, StartAndGoalAreInOppositeCorners) {
  for (const auto& [rows, cols] : {std::pair{6, 5}, std::pair{2, 3}, std::pair{1, 2}}) {
    const NavigationWorld world = generate_navigation_world(building(4, rows, cols));
    const Room& start = world.room(world.start_room);
    const Room& goal = world.room(world.goal_room);
    const double side = start.max_x - start.min_x;
    const double grid_distance = std::abs(goal.min_x - start.min_x) / side + std::abs(goal.min_y - start.min_y) / side;
    EXPECT_DOUBLE_EQ(grid_distance, rows - 1 + cols - 1);
    EXPECT_TRUE(start.contains(world.start.x, world.start.y));
  }
}

// Many room paths lead from start to goal, many of them about as short as the shortest.
TEST(NavigationGenerator, ManyRoomPathsOfSimilarLengthLeadToTheGoal) {
  for (const std::uint64_t seed : {1, 2, 3, 4}) {
    const NavigationWorld world = generate_navigation_world(building(seed));
    const auto paths = world.room_paths(world.start_room, world.goal_room);
    std::size_t shortest = paths.at(0).size();
    for (const auto& path : paths) shortest = std::min(shortest, path.size());
    EXPECT_EQ(shortest, 10u) << "seed " << seed;  // 9 moves: corner to corner of 6 x 5
    const auto near = std::count_if(paths.begin(), paths.end(),
                                    [&](const std::vector<std::string>& path) { return path.size() <= shortest + 2; });
    EXPECT_GT(paths.size(), 100u) << "seed " << seed;
    EXPECT_GE(near, 20) << "seed " << seed;
  }
  // Without extra doors, a spanning tree: exactly one room path.
  BuildingOptions tree = building(1, 3, 3);
  tree.door_density = 0;
  const NavigationWorld world = generate_navigation_world(tree);
  EXPECT_EQ(world.doors.size(), 8u);
  EXPECT_EQ(world.room_paths(world.start_room, world.goal_room).size(), 1u);
  EXPECT_EQ(reachable(world, world.start_room), 9u);
}

TEST(NavigationGenerator, EveryActionIsEveryDoorInBothDirections) {
  const NavigationDomain domain(generate_navigation_world(building(2, 2, 3)));
  const std::vector<StandaloneAction> actions = domain.every_action();
  const NavigationWorld& world = domain.world();
  ASSERT_EQ(actions.size(), 2 * world.doors.size());
  std::set<std::pair<std::string, std::string>> moves;
  for (const StandaloneAction& action : actions) {
    const std::vector<std::string> rooms = move_rooms(action.action);
    ASSERT_EQ(rooms.size(), 2u);
    moves.emplace(rooms[0], rooms[1]);
    EXPECT_EQ(action.from_initial_configuration, rooms[0] == world.start_room) << action.action;
  }
  for (const Door& door : world.doors) {
    EXPECT_EQ(moves.count({door.rooms[0], door.rooms[1]}), 1u);
    EXPECT_EQ(moves.count({door.rooms[1], door.rooms[0]}), 1u);
  }
  EXPECT_EQ(moves.size(), actions.size());
}

// Skeletons: the task planner's shortest room paths, a move reached after other moves named
// "#2" (an instance's actions form a prefix tree), the world still its checker's.
TEST(NavigationGenerator, SkeletonsAreTheShortestRoomPathsAsAPrefixTree) {
  BuildingOptions options = building(5, 3, 3);
  options.narrow_door_share = 0.5;
  const std::string plain = generate_navigation_world_text(options);
  options.skeletons = 6;
  const NavigationWorld world = generate_navigation_world(options);
  EXPECT_EQ(generate_navigation_world_text(options), generate_navigation_world_text(options));
  // The same building: only the description and the skeletons differ.
  const NavigationWorld without = parse_navigation_world(plain, "plain");
  EXPECT_TRUE(without.skeletons.empty());
  EXPECT_EQ(world.doors.size(), without.doors.size());
  EXPECT_EQ(world.obstacles.size(), without.obstacles.size());

  const auto paths = world.room_paths(world.start_room, world.goal_room);
  ASSERT_EQ(world.skeletons.size(), std::min<std::size_t>(6, paths.size()));
  std::set<std::vector<std::string>> room_paths(paths.begin(), paths.end());
  std::map<std::string, std::vector<std::string>> prefix_of;
  std::size_t renamed = 0;
  for (const std::vector<std::string>& skeleton : world.skeletons) {
    std::vector<std::string> rooms{world.start_room};
    for (std::size_t l = 0; l < skeleton.size(); ++l) {
      rooms.push_back(move_rooms(skeleton[l]).at(1));
      const std::vector<std::string> prefix(skeleton.begin(), skeleton.begin() + static_cast<std::ptrdiff_t>(l));
      const auto [seen, added] = prefix_of.emplace(skeleton[l], prefix);
      EXPECT_EQ(seen->second, prefix) << skeleton[l] << " after other actions";
      renamed += skeleton[l].find('#') != std::string::npos && added ? 1 : 0;
    }
    EXPECT_TRUE(room_paths.contains(rooms));
  }
  EXPECT_EQ(world.skeletons.front().front(), "move(R1,R4)");
  EXPECT_GE(renamed, 1u);  // move(R8,R9) ends two paths after different moves
  EXPECT_EQ(world.skeletons[2].back(), "move(R8,R9)#2");
}

TEST(NavigationGenerator, RefusesOptionsOutOfRange) {
  const auto refused = [](const std::function<void(BuildingOptions&)>& edit) {
    BuildingOptions options;
    edit(options);
    EXPECT_THROW(generate_navigation_world_text(options), std::invalid_argument);
  };
  refused([](BuildingOptions& o) { o.rows = 0; });
  refused([](BuildingOptions& o) { o.cols = kMaxBuildingSide + 1; });
  refused([](BuildingOptions& o) { o.rows = o.cols = 1; });
  refused([](BuildingOptions& o) { o.room_size = kMinBuildingRoomSize - 0.5; });
  refused([](BuildingOptions& o) { o.door_density = 1.5; });
  refused([](BuildingOptions& o) { o.narrow_door_share = -0.1; });
  refused([](BuildingOptions& o) { o.narrow_width_min = 0.70; });  // the robot with its clearance: 0.708 m
  refused([](BuildingOptions& o) { o.wide_width_max = kMaxBuildingDoorWidth + 0.01; });
  refused([](BuildingOptions& o) { o.wide_width_min = 1.3; });  // above its maximum, 1.2
  refused([](BuildingOptions& o) { o.empty_room_share = -0.1; });
  refused([](BuildingOptions& o) { o.cluttered_room_share = 1.1; });
  refused([](BuildingOptions& o) { o.empty_room_share = o.cluttered_room_share = 0.6; });
  refused([](BuildingOptions& o) { o.min_boxes = 8; });  // above max_boxes, 7
  refused([](BuildingOptions& o) { o.max_boxes = kMaxBuildingBoxes + 1; });
  refused([](BuildingOptions& o) { o.min_boxes = -1; });
  refused([](BuildingOptions& o) { o.skeletons = -1; });
  refused([](BuildingOptions& o) { o.skeletons = kMaxBuildingSkeletons + 1; });
}

// The family options: every door's width within its kind's range, rooms all empty or all
// cluttered with the boxes asked for, and the world still passable through every door.
TEST(NavigationGenerator, FamilyOptionsSetDoorWidthsAndClutter) {
  BuildingOptions narrow = building(4, 3, 3);
  narrow.narrow_door_share = 1;
  narrow.narrow_width_min = 0.72;
  narrow.narrow_width_max = 0.74;
  narrow.empty_room_share = 1;
  narrow.cluttered_room_share = 0;
  const NavigationWorld bare = generate_navigation_world(narrow);
  ASSERT_FALSE(bare.doors.empty());
  for (const Door& door : bare.doors) {
    EXPECT_GE(door.width, 0.72);
    EXPECT_LE(door.width, 0.74);
  }
  EXPECT_TRUE(bare.obstacles.empty());
  EXPECT_NE(bare.description.find("Narrow doors 0.72-0.74 m"), std::string::npos) << bare.description;

  BuildingOptions wide = building(4, 3, 3);
  wide.narrow_door_share = 0;
  wide.wide_width_min = 1.6;
  wide.wide_width_max = 1.8;
  wide.empty_room_share = 0;
  wide.cluttered_room_share = 1;
  wide.min_boxes = wide.max_boxes = 9;
  const NavigationWorld cluttered = generate_navigation_world(wide);
  for (const Door& door : cluttered.doors) {
    EXPECT_GE(door.width, 1.6);
    EXPECT_LE(door.width, 1.8);
  }
  // Boxes by room; a box that finds no place in 200 tries is left out, so a room of 4 m holds
  // fewer than nine, but more boxes asked give more boxes placed.
  const auto boxes_by_room = [](const NavigationWorld& world) {
    std::map<std::string, int> boxes;
    for (const Obstacle& obstacle : world.obstacles) {
      EXPECT_NE(obstacle.name.find(" box "), std::string::npos) << obstacle.name;
      for (const Room& room : world.rooms) {
        if (room.contains(obstacle.shape.x, obstacle.shape.y)) ++boxes[room.id];
      }
    }
    return boxes;
  };
  BuildingOptions few = wide;
  few.min_boxes = few.max_boxes = 2;
  std::map<std::string, int> many_boxes = boxes_by_room(cluttered),
                             few_boxes = boxes_by_room(generate_navigation_world(few));
  int many_total = 0, few_total = 0;
  for (const Room& room : cluttered.rooms) {
    EXPECT_GE(many_boxes[room.id], 1) << room.id;
    EXPECT_LE(many_boxes[room.id], 9) << room.id;
    EXPECT_GE(few_boxes[room.id], 1) << room.id;
    EXPECT_LE(few_boxes[room.id], 2) << room.id;
    many_total += many_boxes[room.id];
    few_total += few_boxes[room.id];
  }
  EXPECT_GT(many_total, few_total + static_cast<int>(cluttered.rooms.size()));
  const NavigationCollision collision(cluttered, cluttered.robot.clearance);
  for (const Door& door : cluttered.doors) {
    for (const std::string& id : door.rooms) {
      for (const Pose& pose : door_route(cluttered, door, id)) ASSERT_FALSE(collision.collides(pose));
    }
  }
}

}  // namespace
}  // namespace ontime::domains
