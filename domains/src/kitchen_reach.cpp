#include "kitchen_reach.hpp"

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "ontime/domains/manipulation_collision.hpp"
#include "ontime/domains/pr2_arm.hpp"
#include "ontime/util/random.hpp"

namespace ontime::domains::detail {
namespace {

using std::numbers::pi;

// Some draw reaches the object at `pose` with one of its grasps; `held`: whether the robot holds
// it (a place) or it stands there (a pick). `alone` holds the object as its only movable one.
bool reachable(const ManipulationWorld& alone, const ObjectPose& pose, bool held, std::uint64_t seed) {
  SplitMix64 random(seed);
  const auto uniform = [&random](double low, double high) { return low + (high - low) * uniform01(random); };
  const Pr2Arm arm(alone.robot.torso_lift);
  const std::vector<Transform> grasps = box_grasps(alone.objects.front().size);
  const ManipulationPlanner& planner = alone.planner;
  const auto& floor = alone.floor;
  ManipulationCollision collision(alone, arm, {pose}, held ? 0 : -1, Transform::Identity(), alone.robot.clearance);
  for (int draw = 0; draw < kReachDraws; ++draw) {
    const Transform& grasp = grasps[std::min(
        grasps.size() - 1, static_cast<std::size_t>(uniform01(random) * static_cast<double>(grasps.size())))];
    if (held) collision.set_grasp(grasp.inverse());
    const Transform tool = object_transform(pose) * grasp;
    Transform back = Transform::Identity();
    back.translation().x() = -planner.approach_distance;
    const Transform backed = tool * back;
    const double distance = uniform(planner.base_distance[0], planner.base_distance[1]);
    const double around = uniform(-pi, pi);
    const double x = tool.translation().x() + distance * std::cos(around);
    const double y = tool.translation().y() + distance * std::sin(around);
    const double heading = std::atan2(tool.translation().y() - y, tool.translation().x() - x) +
                           uniform(-planner.base_heading_spread, planner.base_heading_spread);
    const Pose base{x, y, std::remainder(heading, 2 * pi)};
    ArmJoints guess{};
    for (std::size_t j = 0; j < kArmJointCount; ++j)
      guess[j] = uniform(pr2_left_arm_joints()[j].lower, pr2_left_arm_joints()[j].upper);
    if (!(x > floor[0] && x < floor[2] && y > floor[1] && y < floor[3])) continue;
    if (collision.collides(base, alone.robot.carry)) continue;
    const Transform torso = base_transform(base) * arm.torso();
    if (!arm.may_reach(torso.inverse() * tool) || !arm.may_reach(torso.inverse() * backed)) continue;
    const std::optional<ArmJoints> joints = arm.inverse(torso.inverse() * tool, guess);
    if (!joints || collision.collides(base, *joints)) continue;
    const std::optional<ArmJoints> before = arm.inverse(torso.inverse() * backed, *joints);
    if (before && !collision.collides(base, *before)) return true;
  }
  return false;
}

ManipulationWorld alone_with(const ManipulationWorld& world, std::size_t object) {
  ManipulationWorld alone = world;
  alone.objects = {world.objects.at(object)};
  alone.skeletons.clear();
  alone.goal.clear();
  return alone;
}

}  // namespace

bool can_pick(const ManipulationWorld& world, std::size_t object, std::uint64_t seed) {
  return reachable(alone_with(world, object), world.objects.at(object).pose, false, seed);
}

bool can_place(const ManipulationWorld& world, std::size_t object, std::size_t region, std::uint64_t seed) {
  const PlacementRegion& r = world.regions.at(region);
  const ObjectPose pose{(r.min_x + r.max_x) / 2, (r.min_y + r.max_y) / 2, world.resting_z(object, r), 0};
  return reachable(alone_with(world, object), pose, true, seed);
}

}  // namespace ontime::domains::detail
