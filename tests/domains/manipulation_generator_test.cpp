#include "ontime/domains/manipulation_generator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include "ontime/domains/collection.hpp"
#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/manipulation_features.hpp"
#include "ontime/util/error.hpp"

namespace ontime::domains {
namespace {

std::size_t feature(const std::string& name) {
  const auto& names = manipulation_feature_names();
  return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
}

std::array<std::array<double, 2>, 4> footprint(const MovableObject& object) {
  return Rectangle{object.pose.x, object.pose.y, object.size[0], object.size[1], object.pose.yaw}.corners();
}

// The table top an object stands on: the box of its region's furniture at the region's height.
const Box3& top_of(const ManipulationWorld& world, const MovableObject& object) {
  const PlacementRegion& region = world.regions[static_cast<std::size_t>(world.region_index(object.region))];
  for (const FixedObject& fixed : world.fixed) {
    for (const Box3& box : fixed.boxes) {
      if (fixed.name == region.surface && std::abs(box.max[2] - region.height) < 1e-9) return box;
    }
  }
  ADD_FAILURE() << object.id << " stands on no top";
  return world.fixed.front().boxes.front();
}

// The widest gap between the two footprints' projections on the four axes of their sides:
// positive when a side separates them (they do not overlap; a lower bound of their distance).
double separation(const MovableObject& a, const MovableObject& b) {
  double widest = -1e9;
  for (const MovableObject* side : {&a, &b}) {
    for (const double angle : {side->pose.yaw, side->pose.yaw + std::numbers::pi / 2}) {
      const auto extent = [&](const MovableObject& object) {
        double low = 1e9, high = -1e9;
        for (const auto& p : footprint(object)) {
          const double along = p[0] * std::cos(angle) + p[1] * std::sin(angle);
          low = std::min(low, along);
          high = std::max(high, along);
        }
        return std::array<double, 2>{low, high};
      };
      const auto ea = extent(a), eb = extent(b);
      widest = std::max({widest, eb[0] - ea[1], ea[0] - eb[1]});
    }
  }
  return widest;
}

// What every generated kitchen promises, checked on the world read back.
void expect_feasible(const ManipulationWorld& world, const KitchenOptions& options) {
  ASSERT_EQ(world.fixed.size(), static_cast<std::size_t>(options.tables));
  ASSERT_EQ(world.regions.size(), static_cast<std::size_t>(options.regions));
  ASSERT_GE(world.objects.size(), static_cast<std::size_t>(options.min_objects));
  ASSERT_LE(world.objects.size(), static_cast<std::size_t>(options.max_objects));
  ASSERT_EQ(world.goal.size(), static_cast<std::size_t>(options.targets));
  EXPECT_EQ(world.collection.deadline, 20 * options.targets);
  for (const MovableObject& object : world.objects) {
    // On its table top, 2 cm inside every edge, resting on it.
    const Box3& top = top_of(world, object);
    for (const auto& p : footprint(object)) {
      EXPECT_GE(p[0], top.min[0] + 0.02 - 1e-9) << object.id;
      EXPECT_LE(p[0], top.max[0] - 0.02 + 1e-9) << object.id;
      EXPECT_GE(p[1], top.min[1] + 0.02 - 1e-9) << object.id;
      EXPECT_LE(p[1], top.max[1] - 0.02 + 1e-9) << object.id;
    }
    EXPECT_NEAR(object.pose.z, top.max[2] + world.planner.placement_gap + object.size[2] / 2, 1e-12) << object.id;
    // Within a class's sizes, fitting the gripper.
    EXPECT_LT(std::max(object.size[0], object.size[1]), 0.07) << object.id;
    EXPECT_GE(object.size[2], 0.08) << object.id;
    // In no region's rectangle.
    for (const PlacementRegion& region : world.regions) {
      EXPECT_FALSE(region.contains(object.pose.x, object.pose.y)) << object.id << " in " << region.id;
    }
  }
  for (std::size_t i = 0; i < world.objects.size(); ++i) {
    for (std::size_t j = i + 1; j < world.objects.size(); ++j) {
      EXPECT_GT(separation(world.objects[i], world.objects[j]), 0.0)
          << world.objects[i].id << " and " << world.objects[j].id;
    }
  }
  // Each target's neighbours (the extractor's count) make its clearing choices: the skeletons are
  // the product of (neighbours + 1), each ending with every target in its goal region.
  std::size_t product = 1;
  for (const auto& [object, region] : world.goal) {
    const double neighbours = manipulation_action_features(world, "move+pick(" + object + ")")[feature("neighbours")];
    EXPECT_GE(neighbours, options.min_clutter) << object;
    EXPECT_LE(neighbours, options.max_clutter) << object;
    product *= static_cast<std::size_t>(neighbours) + 1;
  }
  EXPECT_EQ(world.skeletons.size(), product);
  EXPECT_EQ(world.skeletons.front().size(), 2 * world.goal.size());
}

TEST(KitchenGenerator, TheSameSeedGivesTheSameFile) {
  const KitchenOptions options;
  const std::string first = generate_kitchen_text(options, 1);
  EXPECT_EQ(generate_kitchen_text(options, 1), first);
  EXPECT_NE(generate_kitchen_text(options, 2), first);
  KitchenOptions bottles = options;
  bottles.classes = {"bottle"};
  EXPECT_NE(generate_kitchen_text(bottles, 1), first);
  // The world as read back is the text's.
  const ManipulationWorld world = generate_kitchen(options, 1);
  EXPECT_EQ(world.name, "kitchen");
  EXPECT_EQ(world.source, "kitchen");
}

TEST(KitchenGenerator, EveryKitchenIsFeasible) {
  KitchenOptions crowded;
  crowded.tables = 3;
  crowded.regions = 6;
  crowded.targets = 3;
  crowded.min_clutter = 2;
  crowded.max_clutter = 3;
  crowded.min_objects = 12;
  crowded.max_objects = 16;
  KitchenOptions sparse;
  sparse.tables = 1;
  sparse.regions = 1;
  sparse.targets = 1;
  sparse.min_clutter = 0;
  sparse.max_clutter = 0;
  sparse.min_objects = 1;
  sparse.max_objects = 3;
  for (const KitchenOptions& options : {KitchenOptions{}, crowded, sparse}) {
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
      SCOPED_TRACE("seed " + std::to_string(seed) + ", " + std::to_string(options.tables) + " tables");
      expect_feasible(generate_kitchen(options, seed), options);
    }
  }
}

TEST(KitchenGenerator, ObjectsAreOfTheClassesAskedFor) {
  KitchenOptions options;
  options.classes = {"cup", "bottle"};
  const ManipulationWorld world = generate_kitchen(options, 3);
  for (const MovableObject& object : world.objects) {
    const bool cup = object.id.starts_with("cup"), bottle = object.id.starts_with("bottle");
    ASSERT_TRUE(cup || bottle) << object.id;
    EXPECT_EQ(object.size[0], object.size[1]) << object.id;  // both square
    EXPECT_GE(object.size[2], cup ? 0.08 : 0.2) << object.id;
    EXPECT_LE(object.size[2], cup ? 0.12 : 0.28) << object.id;
  }
}

// The skeleton that clears every neighbour first is refined through, action after action, by the
// domain's planner: the goal is met where it ends.
TEST(KitchenGenerator, TheClearingSkeletonCanBeRefined) {
  const ManipulationDomain domain(generate_kitchen(KitchenOptions{}, 2));
  const ManipulationWorld& world = domain.world();
  CollectionOptions options;
  options.effort.checks_per_second = world.collection.checks_per_second;
  options.step_seconds = world.collection.step_seconds;
  options.budget_steps = world.collection.deadline;
  const auto motions = refine_skeleton(domain, world.skeletons.back(), 1, options);
  ASSERT_EQ(motions.size(), world.skeletons.back().size());
  const KitchenState end = domain.state(motions.back().back());
  EXPECT_EQ(end.held, -1);
  for (const auto& [object, region] : world.goal) {
    const ObjectPose& pose = end.objects[static_cast<std::size_t>(world.object_index(object))];
    EXPECT_TRUE(world.regions[static_cast<std::size_t>(world.region_index(region))].contains(pose.x, pose.y)) << object;
  }
}

void expect_refused(const KitchenOptions& options, const std::string& message) {
  const ParameterSpelling flags = [](std::string_view parameter) { return "--" + std::string(parameter); };
  try {
    generate_kitchen_text(options, 1, flags);
    ADD_FAILURE() << "accepted; expected: " << message;
  } catch (const UsageError& error) {
    EXPECT_EQ(std::string(error.what()), message);
  }
}

TEST(KitchenGenerator, OptionsOutOfRangeNameTheOption) {
  KitchenOptions o;
  o.min_objects = 9;
  o.max_objects = 7;
  expect_refused(o, "--min-objects (9) must not exceed --max-objects (7)");
  o = {};
  o.min_clutter = 2;
  o.max_clutter = 1;
  expect_refused(o, "--min-clutter (2) must not exceed --max-clutter (1)");
  o = {};
  o.region_min = 0.3;
  o.region_max = 0.2;
  expect_refused(o, "--region-min (0.3) must not exceed --region-max (0.2)");
  o = {};
  o.region_max = 0.5;
  expect_refused(o, "--region-max: must be a finite number from 0.1 to 0.35 (got 0.5)");
  o = {};
  o.tables = 4;
  expect_refused(o, "--tables: must be a whole number from 1 to 3 (got 4)");
  o = {};
  o.targets = 3;
  expect_refused(o,
                 "--min-objects (6) must be at least --targets x (1 + --max-clutter) = 9: every target and its "
                 "neighbours");
  o = {};
  o.classes = {"cup", "plate"};
  expect_refused(o, "--classes: unknown class 'plate' (known: cup, box, bottle)");
  o.classes = {};
  expect_refused(o, "--classes: name at least one class (cup, box, bottle)");
  // Without a spelling, the parameter's own name.
  o = {};
  o.regions = 0;
  EXPECT_THROW(generate_kitchen_text(o, 1), UsageError);
}

TEST(KitchenGenerator, OptionsWithoutAFeasibleSceneAreRefused) {
  KitchenOptions o;
  o.tables = 1;
  o.regions = 6;
  o.region_min = 0.35;
  o.region_max = 0.35;
  try {
    generate_kitchen_text(o, 1);
    ADD_FAILURE() << "accepted";
  } catch (const UsageError& error) {
    const std::string message = error.what();
    EXPECT_TRUE(
        message.starts_with("no feasible kitchen in 50 draws with these options (the last: no room on "
                            "table 1 for region R"))
        << message;
  }
}

}  // namespace
}  // namespace ontime::domains
