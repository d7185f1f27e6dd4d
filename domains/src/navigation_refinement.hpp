#pragma once
// Internal: one refinement of move(FROM,TO) in the navigation domain (see navigation.hpp).
//
// The planner samples poses within the bounding box of the two rooms (the planner knows the
// extent of each room, paper §VII-A), so an action's difficulty is that of its own rooms.
// Phases, each resumable between two collision checks:
//   1. goal: draw poses uniformly in the target room (x, y within the walls, heading uniform)
//      until one is collision-free;
//   2. plan: OMPL RRT-Connect from the start pose to that goal, continued slice after slice;
//   3. shorten: greedy shortcutting of the path found (from each waypoint, jump to the farthest
//      later waypoint reachable in a straight collision-free motion).
// Every collision check of every phase is effort.

#include <memory>

#include "ontime/domains/domain.hpp"
#include "ontime/domains/navigation.hpp"

namespace ontime::domains {

// `start` must lie in `source`.
std::unique_ptr<Refinement> make_navigation_refinement(const NavigationDomain& domain, const Room& source,
                                                       const Room& target, const Pose& start, std::uint64_t seed,
                                                       const EffortSettings& effort);

}  // namespace ontime::domains
