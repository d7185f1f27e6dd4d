#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/manipulation_collision.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

const ManipulationDomain& kitchen_domain() {
  static const ManipulationDomain domain(
      load_manipulation_world(testing::source_path("data/domains/manipulation.json")));
  return domain;
}

const Pr2Arm& kitchen_arm() {
  static const Pr2Arm arm(kitchen_domain().world().robot.torso_lift);
  return arm;
}

// Refines `action` from `start` with up to `steps` steps of 2,000 checks; fails the test when
// nothing is found.
std::unique_ptr<Refinement> refined(const std::string& action, const Configuration& start, std::uint64_t seed,
                                    int steps = 40) {
  const EffortSettings effort{EffortUnit::collision_checks, 1000};
  auto refinement = kitchen_domain().refine(action, start, seed, effort);
  for (int step = 1; step <= steps; ++step) {
    if (refinement->advance(2.0 * step) == RefinementStatus::found) return refinement;
  }
  ADD_FAILURE() << action << " not refined in " << steps << " steps";
  return refinement;
}

// The world of a configuration with the bare geometry (no clearance); a held object is attached
// with the grasp it has in `grasped` (the configuration in which it was picked up).
std::unique_ptr<ManipulationCollision> bare_world(const Configuration& at, const Configuration& grasped) {
  const ManipulationDomain& domain = kitchen_domain();
  const Pr2Arm& arm = kitchen_arm();
  const KitchenState state = domain.state(at), then = domain.state(grasped);
  Transform grasp = Transform::Identity();
  if (state.held >= 0) {
    grasp = (base_transform(then.base) * arm.torso() * arm.tool(then.arm)).inverse() *
            object_transform(then.objects[static_cast<std::size_t>(state.held)]);
  }
  return std::make_unique<ManipulationCollision>(domain.world(), arm, state.objects, state.held, grasp, 0.0);
}

// Checks every motion segment with the bare geometry at a resolution four times finer than the
// planner's: arm segments in joint space, base segments in SE(2). The last configuration is the
// world after the action (an object picked up or put down where the robot stands): checked on
// its own.
void expect_collision_free(const std::vector<Configuration>& motion) {
  const ManipulationDomain& domain = kitchen_domain();
  const ManipulationWorld& world = domain.world();
  const auto during = bare_world(motion.front(), motion.front());
  const double arm_step = world.planner.arm_resolution / 4, base_step = world.planner.base_resolution / 4;
  int checked = 0;
  for (std::size_t i = 0; i + 2 < motion.size(); ++i) {
    const KitchenState a = domain.state(motion[i]), b = domain.state(motion[i + 1]);
    ASSERT_EQ(a.held, b.held);
    const double base_length = std::hypot(b.base.x - a.base.x, b.base.y - a.base.y) +
                               0.5 * std::abs(std::remainder(b.base.theta - a.base.theta, 2 * std::numbers::pi));
    const int pieces = std::max(
        1, static_cast<int>(std::ceil(std::max(joint_distance(a.arm, b.arm) / arm_step, base_length / base_step))));
    for (int k = 0; k <= pieces; ++k) {
      const double t = static_cast<double>(k) / pieces;
      const Pose base{a.base.x + t * (b.base.x - a.base.x), a.base.y + t * (b.base.y - a.base.y),
                      a.base.theta + t * std::remainder(b.base.theta - a.base.theta, 2 * std::numbers::pi)};
      ASSERT_FALSE(during->collides(base, interpolate_joints(a.arm, b.arm, t))) << "segment " << i << " at " << t;
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
  const KitchenState before = domain.state(motion[motion.size() - 2]), after = domain.state(motion.back());
  EXPECT_EQ(before.arm, after.arm);
  EXPECT_EQ(before.base.x, after.base.x);
  EXPECT_FALSE(bare_world(motion.back(), motion.back())->collides(after.base, after.arm));
}

TEST(ManipulationRefinement, PickingAndPlacingGivesCollisionFreeMotionsAndMovesTheObject) {
  const ManipulationDomain& domain = kitchen_domain();
  const ManipulationWorld& world = domain.world();
  const auto b3 = static_cast<std::size_t>(world.object_index("B3"));
  const KitchenState start = domain.state(domain.initial_configuration());

  const auto pick = refined("move+pick(B3)", domain.initial_configuration(), 5);
  ASSERT_EQ(pick->status(), RefinementStatus::found);
  const std::vector<Configuration> pick_motion = pick->motion();
  EXPECT_EQ(pick_motion.front(), domain.initial_configuration());
  EXPECT_EQ(pick_motion.back(), pick->final_configuration());
  expect_collision_free(pick_motion);
  const KitchenState picked = domain.state(pick->final_configuration());
  EXPECT_EQ(picked.held, static_cast<int>(b3));
  EXPECT_EQ(picked.objects, start.objects);  // the object is lifted by the next action
  // The gripper holds B3 with one of its grasps.
  const Pr2Arm& arm = kitchen_arm();
  const Transform tool = base_transform(picked.base) * arm.torso() * arm.tool(picked.arm);
  const Transform held = object_transform(picked.objects[b3]).inverse() * tool;  // tool in the object's frame
  double nearest = 1e9;
  for (const Transform& grasp : box_grasps(world.objects[b3].size)) {
    nearest = std::min(nearest, (grasp.translation() - held.translation()).norm() +
                                    Eigen::AngleAxisd(grasp.linear().transpose() * held.linear()).angle());
  }
  EXPECT_LT(nearest, 1e-3);
  EXPECT_GT(pick->execution_seconds(), world.robot.gripper_seconds);

  const auto place = refined("move+place(B3,C1)", pick->final_configuration(), 6);
  ASSERT_EQ(place->status(), RefinementStatus::found);
  expect_collision_free(place->motion());
  const KitchenState placed = domain.state(place->final_configuration());
  EXPECT_EQ(placed.held, -1);
  const PlacementRegion& c1 = world.regions[static_cast<std::size_t>(world.region_index("C1"))];
  EXPECT_TRUE(c1.contains(placed.objects[b3].x, placed.objects[b3].y));
  EXPECT_DOUBLE_EQ(placed.objects[b3].z, world.resting_z(b3, c1));
  for (std::size_t i = 0; i < world.objects.size(); ++i) {
    if (i != b3) {
      EXPECT_EQ(placed.objects[i], start.objects[i]);
    }
  }
}

TEST(ManipulationRefinement, IsResumableAndDependsOnItsSeedOnly) {
  const ManipulationDomain& domain = kitchen_domain();
  const EffortSettings effort{EffortUnit::collision_checks, 1000};
  // Slices of one step against the same steps in a second refinement with the same seed.
  auto one = domain.refine("move+pick(B5)", domain.initial_configuration(), 3, effort);
  auto two = domain.refine("move+pick(B5)", domain.initial_configuration(), 3, effort);
  int step = 1;
  while (one->advance(2.0 * step) != RefinementStatus::found && step < 40) ++step;
  for (int k = 1; k <= step; ++k) two->advance(2.0 * k);
  ASSERT_EQ(one->status(), RefinementStatus::found);
  ASSERT_EQ(two->status(), RefinementStatus::found);
  EXPECT_EQ(one->effort().checks(), two->effort().checks());
  EXPECT_EQ(one->motion(), two->motion());
  EXPECT_EQ(one->execution_seconds(), two->execution_seconds());
  auto other = domain.refine("move+pick(B5)", domain.initial_configuration(), 4, effort);
  for (int k = 1; k <= 40 && other->advance(2.0 * k) != RefinementStatus::found; ++k) {
  }
  EXPECT_NE(other->effort().checks(), one->effort().checks());
}

TEST(ManipulationRefinement, RejectsStartsThatDoNotSuitTheAction) {
  const ManipulationDomain& domain = kitchen_domain();
  const EffortSettings effort{EffortUnit::collision_checks, 1000};
  EXPECT_THROW(domain.refine("move+place(B1,R1)", domain.initial_configuration(), 1, effort), std::invalid_argument);
  EXPECT_THROW(domain.refine("move+pick(B9)", domain.initial_configuration(), 1, effort), std::invalid_argument);
  EXPECT_THROW(domain.refine("move+pick(B1)", Configuration{1, 2, 3}, 1, effort), std::invalid_argument);
  Configuration blocked = domain.initial_configuration();
  blocked[1] = 3.3;  // the base inside the worktop
  EXPECT_THROW(domain.refine("move+pick(B1)", blocked, 1, effort), std::invalid_argument);
}

TEST(ManipulationDomain, ConfigurationsCarryTheWorld) {
  const ManipulationDomain& domain = kitchen_domain();
  const KitchenState start = domain.state(domain.initial_configuration());
  EXPECT_EQ(ManipulationDomain::configuration(start), domain.initial_configuration());
  EXPECT_EQ(domain.initial_configuration().size(), 3u + 7u + 1u + 4u * 6u);
  EXPECT_EQ(start.held, -1);
  EXPECT_EQ(start.arm, domain.world().robot.carry);
}

TEST(ManipulationDomain, AFallbackStartRebuildsTheWorldOfTheSkeletonPrefix) {
  const ManipulationDomain& domain = kitchen_domain();
  const ManipulationWorld& world = domain.world();
  const KitchenState state = domain.state(domain.fallback_start("move+place(B1,R1)[B3,B4]", 9));
  EXPECT_EQ(state.held, world.object_index("B1"));
  for (const char* id : {"B3", "B4"}) {
    const ObjectPose& pose = state.objects[static_cast<std::size_t>(world.object_index(id))];
    EXPECT_TRUE(world.regions[static_cast<std::size_t>(world.region_index("C1"))].contains(pose.x, pose.y)) << id;
  }
  const ObjectPose& b2 = state.objects[static_cast<std::size_t>(world.object_index("B2"))];
  EXPECT_EQ(b2, world.objects[static_cast<std::size_t>(world.object_index("B2"))].pose);
  // A refinement accepts it as its start (it checks the robot and the held object).
  const EffortSettings effort{EffortUnit::collision_checks, 1000};
  EXPECT_NO_THROW(
      domain.refine("move+place(B1,R1)[B3,B4]", domain.fallback_start("move+place(B1,R1)[B3,B4]", 9), 1, effort));
}

TEST(ManipulationDomain, ExecutionTimesFollowTheSlowestJointAndTheBase) {
  const ManipulationDomain& domain = kitchen_domain();
  const double speed = domain.world().robot.arm_speed;
  const ArmJoints a{0, 0, 0, -1, 3.0, -1, 0};
  ArmJoints b = a;
  b[0] = 1.0;   // shoulder pan: 1 rad at 2.088 rad/s
  b[4] = -3.0;  // forearm roll: 0.28 rad the short way at 3.6 rad/s
  EXPECT_NEAR(domain.arm_seconds({a, b}), 1.0 / (speed * 2.088), 1e-12);
  EXPECT_NEAR(domain.arm_seconds({a, b, a}), 2.0 / (speed * 2.088), 1e-12);
  const auto& robot = domain.world().robot;
  EXPECT_NEAR(domain.drive_seconds({Pose{0, 0, 0}, Pose{3, 4, 0}, Pose{3, 4, 1}}),
              5.0 / robot.linear_speed + 1.0 / robot.angular_speed, 1e-12);
}

}  // namespace
}  // namespace ontime::domains
