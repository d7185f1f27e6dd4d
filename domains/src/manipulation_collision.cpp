#include "ontime/domains/manipulation_collision.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/broadphase/default_broadphase_callbacks.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include <array>
#include <numbers>
#include <stdexcept>

namespace ontime::domains {
namespace {

using Object = fcl::CollisionObjectd;

// The robot's shapes (see the header), in the frame they move with.
constexpr std::array<double, 3> kTorsoMin{-0.30, -0.30, 0.0};  // z from the base's top
constexpr std::array<double, 3> kTorsoMax{0.10, 0.08, 0.35};   // z above the shoulder
constexpr double kShoulderRadius = 0.11;
constexpr double kUpperArmRadius = 0.065, kUpperArmFrom = 0.05, kUpperArmTo = 0.40;
constexpr double kForearmRadius = 0.05, kForearmFrom = 0.02, kForearmTo = 0.30;
constexpr double kPalmLength = 0.13, kPalmWidth = 0.10, kPalmHeight = 0.06;
constexpr double kFloorGap = 0.02;
constexpr double kFingerFrom = 0.13, kFingerTo = 0.20, kFingerThickness = 0.015, kFingerHeight = 0.025;

Transform translation(double x, double y, double z) {
  Transform result = Transform::Identity();
  result.translation() = Eigen::Vector3d(x, y, z);
  return result;
}

// A capsule along a frame's x axis from `from` to `to` (FCL's capsules run along z).
Transform along_x(double from, double to) {
  Transform result = translation((from + to) / 2, 0, 0);
  result.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return result;
}

std::unique_ptr<Object> box(double x, double y, double z) {
  return std::make_unique<Object>(std::make_shared<fcl::Boxd>(x, y, z), Transform::Identity());
}

// Exact test of two placed shapes, skipped when their bounding boxes are apart.
bool overlap(const Object& a, const Object& b) {
  if (!a.getAABB().overlap(b.getAABB())) return false;
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  return fcl::collide(&a, &b, request, result) > 0;
}

// Moves a shape to `transform` and updates its bounding box.
void place(Object& object, const Transform& transform) {
  object.setTransform(transform);
  object.computeAABB();
}

}  // namespace

Transform object_transform(const ObjectPose& pose) {
  Transform result = translation(pose.x, pose.y, pose.z);
  result.linear() = Eigen::AngleAxisd(pose.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return result;
}

Transform base_transform(const Pose& base) {
  Transform result = translation(base.x, base.y, 0);
  result.linear() = Eigen::AngleAxisd(base.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return result;
}

std::vector<Transform> box_grasps(const std::array<double, 3>& size) {
  const auto frame = [](const Eigen::Vector3d& x, const Eigen::Vector3d& y, const Eigen::Vector3d& origin) {
    Transform tool = Transform::Identity();
    tool.linear().col(0) = x;
    tool.linear().col(1) = y;
    tool.linear().col(2) = x.cross(y);
    tool.translation() = origin;
    return tool;
  };
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::vector<Transform> grasps;
  for (const Eigen::Vector3d& normal :
       {Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 1, 0)}) {
    const Eigen::Vector3d approach = -normal;
    for (const double side : {1.0, -1.0})
      grasps.push_back(frame(approach, (side * up).cross(approach), Eigen::Vector3d::Zero()));
  }
  const Eigen::Vector3d top(0, 0, size[2] / 2 - kTopGraspDepth);
  for (const Eigen::Vector3d& across :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)}) {
    grasps.push_back(frame(-up, across, top));
  }
  return grasps;
}

struct ManipulationCollision::Impl {
  const ManipulationWorld* world = nullptr;
  const Pr2Arm* arm = nullptr;
  std::vector<std::unique_ptr<Object>> statics;  // walls, furniture, standing objects
  std::vector<Object*> standing;                 // per movable object: its static, or null when held
  fcl::DynamicAABBTreeCollisionManagerd manager;
  // Robot shapes and the fixed placement of each in its moving frame.
  std::unique_ptr<Object> base, torso, shoulder, upper_arm, forearm, palm, left_finger, right_finger, held;
  Transform base_offset, torso_offset, upper_arm_offset, forearm_offset, palm_offset, left_offset, right_offset;
  Transform grasp = Transform::Identity();

  bool hits_world(Object* object) const {
    fcl::DefaultCollisionData<double> data;
    manager.collide(object, &data, fcl::DefaultCollisionFunction<double>);
    return data.result.isCollision();
  }
};

ManipulationCollision::ManipulationCollision(const ManipulationWorld& world, const Pr2Arm& arm,
                                             const std::vector<ObjectPose>& poses, int held, const Transform& grasp,
                                             double clearance)
    : impl_(std::make_unique<Impl>()) {
  Impl& impl = *impl_;
  impl.world = &world;
  impl.arm = &arm;
  impl.grasp = grasp;
  const auto add_static = [&impl](std::unique_ptr<Object> object, const Transform& transform) {
    place(*object, transform);
    impl.manager.registerObject(object.get());
    impl.statics.push_back(std::move(object));
  };
  const auto add_box = [&](const Box3& b) {
    add_static(box(b.max[0] - b.min[0], b.max[1] - b.min[1], b.max[2] - b.min[2]),
               translation((b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2, (b.min[2] + b.max[2]) / 2));
  };
  for (const Box3& wall : world.walls) add_box(wall);
  // The floor, for the arm: a slab whose top lies kFloorGap below z = 0, clear of the padding of
  // the base that stands on the floor.
  const auto& f = world.floor;
  add_box(Box3{{f[0], f[1], -kFloorGap - 0.1}, {f[2], f[3], -kFloorGap}});
  for (const FixedObject& fixed : world.fixed) {
    for (const Box3& part : fixed.boxes) add_box(part);
  }
  for (std::size_t i = 0; i < world.objects.size(); ++i) {
    impl.standing.push_back(nullptr);
    if (static_cast<int>(i) == held) continue;
    const auto& size = world.objects[i].size;
    add_static(box(size[0], size[1], size[2]), object_transform(poses.at(i)));
    impl.standing.back() = impl.statics.back().get();
  }
  impl.manager.setup();

  const double pad = 2 * clearance;
  const auto& base_size = world.robot.base_size;
  impl.base = box(base_size[0] + pad, base_size[1] + pad, base_size[2] + pad);
  impl.base_offset = translation(0, 0, base_size[2] / 2);
  const double torso_top = arm.torso().translation().z() + kTorsoMax[2];
  impl.torso =
      box(kTorsoMax[0] - kTorsoMin[0] + pad, kTorsoMax[1] - kTorsoMin[1] + pad, torso_top - base_size[2] + pad);
  impl.torso_offset =
      translation((kTorsoMin[0] + kTorsoMax[0]) / 2, (kTorsoMin[1] + kTorsoMax[1]) / 2, (base_size[2] + torso_top) / 2);
  impl.shoulder =
      std::make_unique<Object>(std::make_shared<fcl::Sphered>(kShoulderRadius + clearance), Transform::Identity());
  impl.upper_arm = std::make_unique<Object>(
      std::make_shared<fcl::Capsuled>(kUpperArmRadius + clearance, kUpperArmTo - kUpperArmFrom), Transform::Identity());
  impl.upper_arm_offset = along_x(kUpperArmFrom, kUpperArmTo);
  impl.forearm = std::make_unique<Object>(
      std::make_shared<fcl::Capsuled>(kForearmRadius + clearance, kForearmTo - kForearmFrom), Transform::Identity());
  impl.forearm_offset = along_x(kForearmFrom, kForearmTo);
  impl.palm = box(kPalmLength + pad, kPalmWidth + pad, kPalmHeight + pad);
  impl.palm_offset = translation(kPalmLength / 2, 0, 0);
  const double finger_y = kGripperOpening / 2 + kFingerThickness / 2;
  impl.left_finger = box(kFingerTo - kFingerFrom + pad, kFingerThickness + pad, kFingerHeight + pad);
  impl.right_finger = box(kFingerTo - kFingerFrom + pad, kFingerThickness + pad, kFingerHeight + pad);
  impl.left_offset = translation((kFingerFrom + kFingerTo) / 2, finger_y, 0);
  impl.right_offset = translation((kFingerFrom + kFingerTo) / 2, -finger_y, 0);
  if (held >= 0) {
    const auto& size = world.objects.at(static_cast<std::size_t>(held)).size;
    impl.held = box(size[0], size[1], size[2]);
  }
}

ManipulationCollision::~ManipulationCollision() = default;

bool ManipulationCollision::collides(const Pose& base, const ArmJoints& arm) const {
  Impl& impl = *impl_;
  const Transform body = base_transform(base);
  const Transform torso = body * impl.arm->torso();
  const ArmFrames frames = impl.arm->frames(arm);
  // The gripper first: it is the part that reaches among the objects.
  const Transform wrist = torso * frames[6];
  place(*impl.palm, wrist * impl.palm_offset);
  place(*impl.left_finger, wrist * impl.left_offset);
  place(*impl.right_finger, wrist * impl.right_offset);
  place(*impl.forearm, torso * frames[4] * impl.forearm_offset);
  if (impl.held) place(*impl.held, torso * frames[kArmJointCount] * impl.grasp);
  for (Object* part :
       {impl.left_finger.get(), impl.right_finger.get(), impl.palm.get(), impl.held.get(), impl.forearm.get()}) {
    if (part != nullptr && impl.hits_world(part)) return true;
  }
  place(*impl.upper_arm, torso * frames[2] * impl.upper_arm_offset);
  place(*impl.shoulder, torso * frames[0]);
  place(*impl.torso, body * impl.torso_offset);
  place(*impl.base, body * impl.base_offset);
  for (Object* part : {impl.upper_arm.get(), impl.shoulder.get(), impl.torso.get(), impl.base.get()}) {
    if (impl.hits_world(part)) return true;
  }
  // Self-collisions.
  for (Object* moving :
       {impl.left_finger.get(), impl.right_finger.get(), impl.palm.get(), impl.held.get(), impl.forearm.get()}) {
    if (moving == nullptr) continue;
    if (overlap(*moving, *impl.base) || overlap(*moving, *impl.torso)) return true;
    if (moving != impl.forearm.get() && overlap(*moving, *impl.upper_arm)) return true;
  }
  if (overlap(*impl.upper_arm, *impl.torso)) return true;
  return impl.held && overlap(*impl.held, *impl.forearm);
}

bool ManipulationCollision::held_object_collides(const ObjectPose& pose) const {
  Impl& impl = *impl_;
  if (!impl.held) throw std::logic_error("no object is held");
  place(*impl.held, object_transform(pose));
  return impl.hits_world(impl.held.get());
}

void ManipulationCollision::set_grasp(const Transform& grasp) {
  if (!impl_->held) throw std::logic_error("no object is held");
  impl_->grasp = grasp;
}

void ManipulationCollision::set_object_pose(std::size_t object, const ObjectPose& pose) {
  Object* standing = impl_->standing.at(object);
  if (standing == nullptr) throw std::logic_error("the held object does not stand anywhere");
  place(*standing, object_transform(pose));
  impl_->manager.update(standing);
}

}  // namespace ontime::domains
