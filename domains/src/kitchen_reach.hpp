#pragma once
// Internal: whether, and how often, the robot of a kitchen reaches an object to pick it, or a
// region to place an object in. A draw is drawn as the refinement draws a target: a grasp of the
// object, for a place a placement in the region, a base pose on a ring of `planner.base_distance`
// around the tool frame facing it within `planner.base_heading_spread`; it reaches when the base
// stands on the floor clear of everything with the arm carried and KDL finds collision-free IK for
// the grasp and for the approach `planner.approach_distance` back along the gripper. Each draw
// costs at most two IK solves (about 100 µs each); every draw from `seed`.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "ontime/domains/manipulation_world.hpp"
#include "planar_geometry.hpp"

namespace ontime::domains::detail {

inline constexpr int kReachDraws = 20000;

// The scene generator's kinematic and furniture check (manipulation_generator.hpp), not a plan:
// the object alone in the kitchen (other movable objects left out), at most kReachDraws draws.
// The object standing where the world puts it.
bool can_pick(const ManipulationWorld& world, std::size_t object, std::uint64_t seed);
// The object in the hand, placed at the centre of the region's rectangle (yaw 0).
bool can_place(const ManipulationWorld& world, std::size_t object, std::size_t region, std::uint64_t seed);

// The draws made and how many of them reached.
struct ReachCount {
  int drawn = 0;
  int reached = 0;
};

// Heights that differ by no more than this are the same surface.
inline constexpr double kSameHeight = 1e-9;
// Whether two regions lie on the same top: the same furniture at the same height.
bool same_surface(const PlacementRegion& a, const PlacementRegion& b);
// An object's footprint standing at `pose`: its x-y rectangle turned by the yaw.
std::vector<Point> object_footprint(const MovableObject& object, const ObjectPose& pose);

// An object an earlier action placed in `region`: where in it is not known.
struct MovedObject {
  std::size_t object = 0;
  const PlacementRegion* region = nullptr;
};

// Draws until `hits` draws have reached `object` or `draws` were made, with every movable object
// standing at `poses` (the other objects are obstacles): `object` standing at its pose to be
// picked, or, with `region`, held and placed at a placement drawn uniformly in the region's
// rectangle and yaw range (a draw whose placement overlaps something does not reach).
//
// `moved` (in the order they were placed; the held object among them is skipped): each draw first
// sets each of them down anew at a placement drawn uniformly in its region's rectangle and yaw
// range whose footprint overlaps no footprint standing on the same surface (the first of
// kLayoutTries that does not, else the last), as a refinement's placement would have left it; their
// poses in `poses` are not used. So the share is over where they may stand, not one guess of it.
// These placements come from a stream of their own, so the draws of the targets are the same
// with and without `moved`.
inline constexpr int kLayoutTries = 100;
ReachCount count_reaching_draws(const ManipulationWorld& world, const std::vector<ObjectPose>& poses,
                                std::size_t object, const PlacementRegion* region,
                                const std::vector<MovedObject>& moved, int hits, int draws, std::uint64_t seed);

}  // namespace ontime::domains::detail
