#pragma once
// The features of a navigation action: what a conditional time model (learn/) sees of
// move(FROM,TO) in a world it may never have refined in. A fixed-length vector computed from the
// world file's geometry alone, in O(doors + furniture) per action (docs/learning.md, "Features"):
//
//   door_width        the opening of the door joining FROM and TO (m); of two doors, the wider
//   door_slack        door_width minus the robot's width with its clearance on both sides (m):
//                     how narrow the passage is for this robot (RRT-Connect's hard part)
//   door_furniture    distance from the door's centre to the nearest furniture of either room,
//                     capped at kFeatureDistanceCap (m): clutter at the passage
//   source_area       area of FROM (m²)
//   target_area       area of TO (m²); the goal pose is sampled there
//   source_pieces     furniture pieces in FROM (a piece belongs to the room holding its centre)
//   target_pieces     furniture pieces in TO
//   source_occupied   furniture area in FROM over its area (pieces do not overlap in generated
//                     worlds; overlapping pieces are counted twice)
//   target_occupied   the same for TO
//   route_length      FROM's centre to the door's centre to TO's centre (m): the execution's scale
//   sampling_area     the bounding box of both rooms (m²), where the planner samples
//
// The same vector for the same world and action on every machine (no randomness, no
// tolerance-dependent geometry).

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/navigation_world.hpp"

namespace ontime::domains {

inline constexpr double kFeatureDistanceCap = 5.0;

// The names, in the order of navigation_action_features' vector.
const std::vector<std::string>& navigation_feature_names();

// Throws std::invalid_argument when `action` is not move(FROM,TO) between two rooms of the world
// joined by a door (the message says which).
std::vector<double> navigation_action_features(const NavigationWorld& world, std::string_view action);

}  // namespace ontime::domains
