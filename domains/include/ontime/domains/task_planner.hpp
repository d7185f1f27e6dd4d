#pragma once
// Task planners that stream plan skeletons (TaskPlanner, domain.hpp): a sequence-before-satisfy
// TAMP system finds skeletons one after another while their actions are being refined. A
// TaskPlanner hands them out in its own order (shortest first, say); a streaming PlannerWorld
// (planner_world.hpp) turns each into a skeleton arriving in the episode's session.
//
// Room paths (navigation): the k shortest simple paths from the start room to the goal room
// of the room graph (rooms as vertices, doors as edges weighted by the distance from one room's
// centre through the door's centre to the other's), in order of length, each as its
// move(Ri,Rj) actions. They come from igraph's k-shortest-paths routine (Yen's algorithm), asked
// for batches of doubling size as the planners read further, and are computed once per world:
// every planner made by one factory shares them (under a lock; igraph's error state is global).

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ontime/domains/domain.hpp"
#include "ontime/domains/navigation_world.hpp"

namespace ontime::domains {

// Room paths of a navigation world in order of length (see above); `longest` caps how many are
// ever produced. The world must outlive the planners.
TaskPlannerFactory room_path_planners(const NavigationWorld& world, int longest = 1000);

// The domain's fixed skeletons, in their order (a domain without a task planner of its own).
TaskPlannerFactory fixed_skeleton_planners(const Domain& domain);

// The length of a room path (the sum of its doors' edge weights above), in metres.
double room_path_length(const NavigationWorld& world, const std::vector<std::string>& moves);

// A room path drawn from above: the start pose, then through each door's centre to the centre of
// the room it enters (for pictures).
std::vector<std::array<double, 2>> room_path_points(const NavigationWorld& world,
                                                    const std::vector<std::string>& moves);

}  // namespace ontime::domains
