#pragma once
// Internal: whether the robot of a kitchen can reach an object to pick it, or a region to place
// an object in, at all: some base pose drawn as the refinement draws them (a ring of
// `planner.base_distance` around the tool frame, facing it within `planner.base_heading_spread`),
// on the floor and clear of walls and furniture with the arm carried, where KDL finds IK for one
// of the object's grasps and for the approach `planner.approach_distance` back along the gripper,
// both clear. Other movable objects are left out: this is the kinematic and furniture check of
// the scene generator (manipulation_generator.hpp), not a plan. At most kReachDraws draws, each
// at most two IK solves (about 100 µs each); every draw from `seed`.

#include <cstddef>
#include <cstdint>

#include "ontime/domains/manipulation_world.hpp"

namespace ontime::domains::detail {

inline constexpr int kReachDraws = 20000;

// The object standing where the world puts it.
bool can_pick(const ManipulationWorld& world, std::size_t object, std::uint64_t seed);

// The object in the hand, placed at the centre of the region's rectangle (yaw 0).
bool can_place(const ManipulationWorld& world, std::size_t object, std::size_t region, std::uint64_t seed);

}  // namespace ontime::domains::detail
