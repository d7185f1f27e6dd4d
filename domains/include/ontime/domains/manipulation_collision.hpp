#pragma once
// Collision checking of the manipulation domain's robot with FCL: the base, the torso and the
// left arm's links as simple shapes, the held object attached to the gripper, against the walls,
// the floor (a slab 2 cm below z = 0, clear of the padded base), the furniture, the movable
// objects (a dynamic AABB tree) and the robot itself.
//
// The robot's shapes, in the frames of pr2_arm.hpp (docs/domains.md draws them):
//   base      box of the world's `robot.base_size`, on the floor
//   torso     box x in [-0.30, 0.10], y in [-0.30, 0.08], from the base's top to 0.35 m above
//             the shoulder (column, head and the tucked right arm)
//   shoulder  sphere of radius 0.11 at the shoulder pan joint
//   upper arm capsule of radius 0.065 along x from 0.05 to 0.40 (upper arm roll frame)
//   forearm   capsule of radius 0.05 along x from 0.02 to 0.30 (forearm roll frame)
//   palm      box x in [0, 0.13], 0.10 wide (y), 0.06 high (z) (wrist roll frame)
//   fingers   two boxes x in [0.13, 0.20], 0.015 thick, 0.025 high, their inner faces 0.09 apart
//             (open): the tool frame (x = 0.18) lies between them
// Every robot shape is padded by `clearance` on every side; the held object is not (it starts
// and ends a few millimetres above its support). Self-collisions checked: the gripper, the
// forearm and the held object against the base and the torso; the gripper and the held object
// against the upper arm; the upper arm against the torso; the held object against the forearm.
//
// One checker per refinement (the movable objects stay where they are during one), not
// thread-safe.

#include <memory>
#include <optional>
#include <vector>

#include "ontime/domains/manipulation_world.hpp"
#include "ontime/domains/pr2_arm.hpp"

namespace ontime::domains {

// The gripper's opening (inner faces of the open fingers) and where the palm starts, in the
// tool frame: the geometry that grasps are built around.
inline constexpr double kGripperOpening = 0.09;
inline constexpr double kPalmFront = -0.05;
// Top grasps hold an object this far below its top.
inline constexpr double kTopGraspDepth = 0.03;

// The grasps of an upright box of `size` (x, y, z), as the tool frame in the object's frame:
// eight side grasps (approaching each vertical face horizontally through the centre, the
// gripper upright or upside down) and four top grasps (approaching from above, the fingers
// across x or y, either way round, the tool frame kTopGraspDepth below the top).
std::vector<Transform> box_grasps(const std::array<double, 3>& size);

// An object's frame in the world.
Transform object_transform(const ObjectPose& pose);
// The robot base's frame (base_footprint) in the world.
Transform base_transform(const Pose& base);

class ManipulationCollision {
 public:
  // `poses`: every movable object's pose; object `held` (-1: none) is carried with the tool
  // frame -> object transform `grasp` instead of standing at its pose.
  ManipulationCollision(const ManipulationWorld& world, const Pr2Arm& arm, const std::vector<ObjectPose>& poses,
                        int held, const Transform& grasp, double clearance);
  ~ManipulationCollision();
  ManipulationCollision(const ManipulationCollision&) = delete;
  ManipulationCollision& operator=(const ManipulationCollision&) = delete;

  // True when the robot at base pose `base` with arm joints `arm` (and the held object)
  // overlaps a wall, a piece of furniture, a movable object or itself.
  bool collides(const Pose& base, const ArmJoints& arm) const;

  // True when the held object, standing at `pose` (a placement), overlaps a wall, a piece of
  // furniture or another movable object. Throws std::logic_error when nothing is held.
  bool held_object_collides(const ObjectPose& pose) const;

  // Another grasp of the held object (tool frame -> object).
  void set_grasp(const Transform& grasp);
  // Moves a standing (not held) object.
  void set_object_pose(std::size_t object, const ObjectPose& pose);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ontime::domains
