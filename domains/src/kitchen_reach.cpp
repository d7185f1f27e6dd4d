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

// Counts the draws that reach `object` (see the header) until `hits` have. `poses`: every movable
// object's pose. `held`: the object is in the hand, to be placed at its pose in `poses`, or with
// `region` at a placement each draw draws there; else it stands at its pose, to be picked.
ReachCount count_reaching(const ManipulationWorld& world, const std::vector<ObjectPose>& poses, std::size_t object,
                          bool held, const PlacementRegion* region, int hits, int draws, std::uint64_t seed) {
  SplitMix64 random(seed);
  const auto uniform = [&random](double low, double high) { return low + (high - low) * uniform01(random); };
  const Pr2Arm arm(world.robot.torso_lift);
  const std::vector<Transform> grasps = box_grasps(world.objects.at(object).size);
  const ManipulationPlanner& planner = world.planner;
  const auto& floor = world.floor;
  ManipulationCollision collision(world, arm, poses, held ? static_cast<int>(object) : -1, Transform::Identity(),
                                  world.robot.clearance);
  ReachCount count;
  while (count.reached < hits && count.drawn < draws) {
    ++count.drawn;
    const Transform& grasp = grasps[std::min(
        grasps.size() - 1, static_cast<std::size_t>(uniform01(random) * static_cast<double>(grasps.size())))];
    ObjectPose pose = poses.at(object);
    if (region != nullptr) {
      pose = ObjectPose{uniform(region->min_x, region->max_x), uniform(region->min_y, region->max_y),
                        world.resting_z(object, *region), uniform(region->yaw_low, region->yaw_high)};
    }
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
    if (region != nullptr && collision.held_object_collides(pose)) continue;
    if (!(x > floor[0] && x < floor[2] && y > floor[1] && y < floor[3])) continue;
    if (collision.collides(base, world.robot.carry)) continue;
    const Transform torso = base_transform(base) * arm.torso();
    if (!arm.may_reach(torso.inverse() * tool) || !arm.may_reach(torso.inverse() * backed)) continue;
    const std::optional<ArmJoints> joints = arm.inverse(torso.inverse() * tool, guess);
    if (!joints || collision.collides(base, *joints)) continue;
    const std::optional<ArmJoints> before = arm.inverse(torso.inverse() * backed, *joints);
    if (before && !collision.collides(base, *before)) ++count.reached;
  }
  return count;
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
  const ManipulationWorld alone = alone_with(world, object);
  return count_reaching(alone, {world.objects.at(object).pose}, 0, false, nullptr, 1, kReachDraws, seed).reached > 0;
}

bool can_place(const ManipulationWorld& world, std::size_t object, std::size_t region, std::uint64_t seed) {
  const PlacementRegion& r = world.regions.at(region);
  const ObjectPose pose{(r.min_x + r.max_x) / 2, (r.min_y + r.max_y) / 2, world.resting_z(object, r), 0};
  const ManipulationWorld alone = alone_with(world, object);
  return count_reaching(alone, {pose}, 0, true, nullptr, 1, kReachDraws, seed).reached > 0;
}

ReachCount count_reaching_draws(const ManipulationWorld& world, const std::vector<ObjectPose>& poses,
                                std::size_t object, const PlacementRegion* region, int hits, int draws,
                                std::uint64_t seed) {
  return count_reaching(world, poses, object, region != nullptr, region, hits, draws, seed);
}

}  // namespace ontime::domains::detail
