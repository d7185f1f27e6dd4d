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

// Draws until `hits` draws have reached `object` or `draws` were made, with every movable object
// standing at `poses` (the other objects are obstacles): `object` standing at its pose to be
// picked, or, with `region`, held and placed at a placement drawn uniformly in the region's
// rectangle and yaw range (a draw whose placement overlaps something does not reach).
ReachCount count_reaching_draws(const ManipulationWorld& world, const std::vector<ObjectPose>& poses,
                                std::size_t object, const PlacementRegion* region, int hits, int draws,
                                std::uint64_t seed);

}  // namespace ontime::domains::detail
