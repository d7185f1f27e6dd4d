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
bool overlaps_any(const std::vector<Point>& shape, const std::vector<std::vector<Point>>& standing) {
  for (const auto& other : standing) {
    if (convex_distance(shape, other) <= 0) return true;
  }
  return false;
}

// Where the moved objects stand in one draw (count_reaching_draws in the header): each set down
// in turn at the first of kLayoutTries uniform placements in its region that overlaps nothing
// standing on its surface, the unmoved objects and those set down before it.
class Layout {
 public:
  Layout(const ManipulationWorld& world, const std::vector<ObjectPose>& poses, const std::vector<MovedObject>& moved,
         std::size_t held, std::uint64_t seed)
      : world_(world), random_(seed) {
    std::vector<bool> is_moved(world.objects.size(), false);
    for (const MovedObject& m : moved) is_moved.at(m.object) = true;
    for (const MovedObject& m : moved) {
      if (m.object == held) continue;
      Slot slot{m.object, m.region, {}, {}};
      for (std::size_t j = 0; j < world.objects.size(); ++j) {
        if (is_moved[j] || j == held) continue;
        const auto on = static_cast<std::size_t>(world.region_index(world.objects[j].region));
        if (same_surface(world.regions.at(on), *m.region))
          slot.standing.push_back(object_footprint(world.objects[j], poses[j]));
      }
      for (std::size_t e = 0; e < slots_.size(); ++e) {
        if (same_surface(*slots_[e].region, *m.region)) slot.earlier.push_back(e);
      }
      slots_.push_back(std::move(slot));
    }
    placed_.resize(slots_.size());
  }

  // Draws the placements and sets them in `collision`; `subject` becomes the pose of the object to
  // pick when it is one of the moved.
  void draw(ManipulationCollision& collision, std::size_t object, ObjectPose& subject) {
    for (std::size_t s = 0; s < slots_.size(); ++s) {
      const Slot& slot = slots_[s];
      const PlacementRegion& region = *slot.region;
      const MovableObject& moved = world_.objects[slot.object];
      ObjectPose pose;
      for (int attempt = 0; attempt < kLayoutTries; ++attempt) {
        pose = ObjectPose{uniform(region.min_x, region.max_x), uniform(region.min_y, region.max_y),
                          world_.resting_z(slot.object, region), uniform(region.yaw_low, region.yaw_high)};
        placed_[s] = object_footprint(moved, pose);
        bool clear = !overlaps_any(placed_[s], slot.standing);
        for (const std::size_t e : slot.earlier) clear = clear && convex_distance(placed_[s], placed_[e]) > 0;
        if (clear) break;
      }
      collision.set_object_pose(slot.object, pose);
      if (slot.object == object) subject = pose;
    }
  }

 private:
  struct Slot {
    std::size_t object;
    const PlacementRegion* region;
    std::vector<std::vector<Point>> standing;  // the unmoved objects on its surface
    std::vector<std::size_t> earlier;          // slots set down before it on the same surface
  };
  double uniform(double low, double high) { return low + (high - low) * uniform01(random_); }

  const ManipulationWorld& world_;
  SplitMix64 random_;
  std::vector<Slot> slots_;
  std::vector<std::vector<Point>> placed_;
};

// Counts the draws that reach `object` (see the header) until `hits` have. `poses`: every movable
// object's pose. `held`: the object is in the hand, to be placed at its pose in `poses`, or with
// `region` at a placement each draw draws there; else it stands at its pose, to be picked.
ReachCount count_reaching(const ManipulationWorld& world, const std::vector<ObjectPose>& poses, std::size_t object,
                          bool held, const PlacementRegion* region, const std::vector<MovedObject>& moved, int hits,
                          int draws, std::uint64_t seed) {
  SplitMix64 random(seed);
  const auto uniform = [&random](double low, double high) { return low + (high - low) * uniform01(random); };
  const Pr2Arm arm(world.robot.torso_lift);
  const std::vector<Transform> grasps = box_grasps(world.objects.at(object).size);
  const ManipulationPlanner& planner = world.planner;
  const auto& floor = world.floor;
  ManipulationCollision collision(world, arm, poses, held ? static_cast<int>(object) : -1, Transform::Identity(),
                                  world.robot.clearance);
  Layout layout(world, poses, moved, held ? object : world.objects.size(), stream_seed(seed, 1));
  ObjectPose standing = poses.at(object);
  ReachCount count;
  while (count.reached < hits && count.drawn < draws) {
    ++count.drawn;
    const Transform& grasp = grasps[std::min(
        grasps.size() - 1, static_cast<std::size_t>(uniform01(random) * static_cast<double>(grasps.size())))];
    layout.draw(collision, object, standing);
    ObjectPose pose = standing;
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

bool same_surface(const PlacementRegion& a, const PlacementRegion& b) {
  return a.surface == b.surface && std::abs(a.height - b.height) <= kSameHeight;
}

std::vector<Point> object_footprint(const MovableObject& object, const ObjectPose& pose) {
  return rectangle_corners(Rectangle{pose.x, pose.y, object.size[0], object.size[1], pose.yaw});
}

bool can_pick(const ManipulationWorld& world, std::size_t object, std::uint64_t seed) {
  const ManipulationWorld alone = alone_with(world, object);
  return count_reaching(alone, {world.objects.at(object).pose}, 0, false, nullptr, {}, 1, kReachDraws, seed).reached >
         0;
}

bool can_place(const ManipulationWorld& world, std::size_t object, std::size_t region, std::uint64_t seed) {
  const PlacementRegion& r = world.regions.at(region);
  const ObjectPose pose{(r.min_x + r.max_x) / 2, (r.min_y + r.max_y) / 2, world.resting_z(object, r), 0};
  const ManipulationWorld alone = alone_with(world, object);
  return count_reaching(alone, {pose}, 0, true, nullptr, {}, 1, kReachDraws, seed).reached > 0;
}

ReachCount count_reaching_draws(const ManipulationWorld& world, const std::vector<ObjectPose>& poses,
                                std::size_t object, const PlacementRegion* region,
                                const std::vector<MovedObject>& moved, int hits, int draws, std::uint64_t seed) {
  return count_reaching(world, poses, object, region != nullptr, region, moved, hits, draws, seed);
}

}  // namespace ontime::domains::detail
