#include "ontime/domains/pr2_arm.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/manipulation_collision.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

ArmJoints random_joints(SplitMix64& random) {
  ArmJoints joints{};
  for (std::size_t j = 0; j < kArmJointCount; ++j) {
    const ArmJointSpec& spec = pr2_left_arm_joints()[j];
    joints[j] = spec.lower + (spec.upper - spec.lower) * uniform01(random);
  }
  return joints;
}

TEST(Pr2Arm, StretchedOutTheToolLiesAtTheSumOfTheLinkLengths) {
  const Pr2Arm arm(0.15);
  EXPECT_NEAR(arm.torso().translation().z(), 0.790675 + 0.15, 1e-12);
  const Transform tool = arm.torso() * arm.tool(ArmJoints{});
  // Shoulder 0.188 to the left of the torso, then 0.1 + 0.4 + 0.321 + 0.18 straight ahead.
  EXPECT_NEAR(tool.translation().x(), -0.05 + 1.001, 1e-12);
  EXPECT_NEAR(tool.translation().y(), 0.188, 1e-12);
  EXPECT_NEAR(tool.translation().z(), 0.940675, 1e-12);
  // Elbow flexed by a right angle: the forearm and gripper point up from the elbow.
  const Transform bent = arm.torso() * arm.tool(ArmJoints{0, 0, 0, -std::numbers::pi / 2, 0, 0, 0});
  EXPECT_NEAR(bent.translation().x(), -0.05 + 0.5, 1e-12);
  EXPECT_NEAR(bent.translation().z(), 0.940675 + 0.501, 1e-12);
}

TEST(Pr2Arm, InverseKinematicsReachesTheTargetWithinTolerance) {
  const Pr2Arm arm(0.15);
  SplitMix64 random(11);
  int found = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Transform target = arm.tool(random_joints(random));
    const std::optional<ArmJoints> solution = arm.inverse(target, random_joints(random));
    if (!solution) continue;
    ++found;
    EXPECT_TRUE(Pr2Arm::within_limits(*solution));
    const Transform reached = arm.tool(*solution);
    EXPECT_LE((reached.translation() - target.translation()).norm(), Pr2Arm::kPositionTolerance);
    EXPECT_LE(Eigen::AngleAxisd(reached.linear().transpose() * target.linear()).angle(), Pr2Arm::kOrientationTolerance);
  }
  // Reachable targets from random initial guesses: a good share converges (measured 54%).
  EXPECT_GT(found, 60);
  // Beyond the arm's reach there is no solution.
  Transform far = Transform::Identity();
  far.translation() = Eigen::Vector3d(2.0, 0.2, 0.0);
  EXPECT_FALSE(arm.inverse(far, ArmJoints{}).has_value());
}

TEST(Pr2Arm, ContinuousJointsTurnTheShortWay) {
  EXPECT_NEAR(joint_difference(4, 3.1, -3.1), 2 * std::numbers::pi - 6.2, 1e-12);
  EXPECT_NEAR(joint_difference(3, -0.1, -2.0), -1.9, 1e-12);  // the elbow has limits: no wrap
  const ArmJoints a{0, 0, 0, -1, 3.0, -1, -3.0};
  const ArmJoints b{0, 0, 0, -1, -3.0, -1, 3.0};
  const ArmJoints middle = interpolate_joints(a, b, 0.5);
  EXPECT_NEAR(std::abs(middle[4]), std::numbers::pi, 1e-12);
  EXPECT_NEAR(std::abs(middle[6]), std::numbers::pi, 1e-12);
  EXPECT_NEAR(joint_distance(a, b), std::sqrt(2) * (2 * std::numbers::pi - 6.0), 1e-12);
}

TEST(ManipulationCollision, TheRobotCollidesWithFurnitureItselfAndTheFloorButNotInTheOpen) {
  const ManipulationWorld world = load_manipulation_world(testing::source_path("data/domains/manipulation.json"));
  const Pr2Arm arm(world.robot.torso_lift);
  std::vector<ObjectPose> poses;
  for (const MovableObject& object : world.objects) poses.push_back(object.pose);
  const ManipulationCollision collision(world, arm, poses, -1, Transform::Identity(), world.robot.clearance);
  EXPECT_FALSE(collision.collides(world.start, world.robot.carry));
  EXPECT_TRUE(collision.collides(Pose{1.1, 3.3, 0}, world.robot.carry));   // inside the shelf
  EXPECT_TRUE(collision.collides(Pose{-0.2, 1.5, 0}, world.robot.carry));  // in the wall
  // The arm hanging straight down in front of the shoulder goes through the base.
  EXPECT_TRUE(collision.collides(world.start, ArmJoints{0, std::numbers::pi / 2 - 0.2, 0, 0, 0, 0, 0}));
  // Stretched forward at the start it touches nothing.
  EXPECT_FALSE(collision.collides(world.start, ArmJoints{}));
  // The same reach in front of the worktop ends inside it.
  EXPECT_TRUE(collision.collides(Pose{3.0, 2.4, std::numbers::pi / 2}, ArmJoints{0, 0.1, 0, 0, 0, 0, 0}));
  // Placements: the held object where B1 stands collides; on the free part of the worktop not.
  const int b2 = world.object_index("B2");
  const ManipulationCollision holding(world, arm, poses, b2, Transform::Identity(), world.robot.clearance);
  EXPECT_TRUE(holding.held_object_collides(poses[static_cast<std::size_t>(world.object_index("B1"))]));
  EXPECT_FALSE(holding.held_object_collides(ObjectPose{2.7, 3.3, 0.9 + 0.005 + 0.1, 0.3}));
  EXPECT_TRUE(holding.held_object_collides(ObjectPose{2.7, 3.3, 0.9 + 0.05, 0.3}));  // sunk into the top
}

TEST(ManipulationCollision, EveryGraspHoldsTheBoxBetweenTheOpenFingers) {
  const std::array<double, 3> size{0.06, 0.06, 0.2};
  const std::vector<Transform> grasps = box_grasps(size);
  ASSERT_EQ(grasps.size(), 12u);
  for (const Transform& grasp : grasps) {
    // The tool frame is a rotation: the object's centre lies on the gripper's axis.
    EXPECT_NEAR(grasp.linear().determinant(), 1.0, 1e-12);
    const Transform object = grasp.inverse();  // the object in the tool frame
    EXPECT_NEAR(object.translation().y(), 0.0, 1e-12);
    EXPECT_NEAR(object.translation().z(), 0.0, 1e-12);
    // The fingers close along y across a side of the box (0.06 wide).
    const Eigen::Vector3d across = object.linear().transpose() * Eigen::Vector3d::UnitY();
    EXPECT_NEAR(std::abs(across.z()), 0.0, 1e-12);
  }
}

}  // namespace
}  // namespace ontime::domains
