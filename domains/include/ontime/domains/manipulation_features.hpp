#pragma once
// The features of a manipulation action: what a conditional time model (learn/) sees of
// move+pick(O) or move+place(O,R) in a kitchen it may never have refined in. One layout for both
// kinds, a fixed-length vector from the world file's geometry alone (docs/learning.md,
// "Features"), in O(objects + furniture boxes + skeleton positions) per action.
//
// The world the action starts in: the objects of its context (moved before it) no longer stand
// where they started; where they went is read from the first skeleton holding the action (the
// region its prefix placed them in last), but not where in that region. The subject is the
// object (pick) or the region's rectangle of placement centres (place); its surface the top it
// stands on (the furniture box under it at its region's height); "others" are the objects
// standing on the same surface (same furniture, same height) except the action's object and the
// moved ones.
//
//   is_place           0 for a pick, 1 for a place
//   object_short       the object's footprint, its shorter side (m); the held object for a place
//   object_long        its longer side (m)
//   object_height      its height (m)
//   surface_height     the top of the surface: the object's (pick) or the region's (place) (m)
//   reach              from the subject's centre to the nearest open edge of its surface (m): an
//                      edge outside which the robot's base (a square of its longer side, centred
//                      on the subject's projection onto the edge) stands on the floor clear of
//                      every furniture box lower than the base's height; with no open edge, the
//                      nearest edge
//   nearest_gap        the gap from the subject's footprint to the nearest other (m), capped at
//                      kManipulationGapCap
//   neighbours         others within kManipulationNeighbourRadius of the subject's footprint
//   approach_occupied  the share of the approach strip covered by the others' footprints: the strip
//                      kManipulationApproachWidth wide from the subject's centre straight to the
//                      edge of `reach` (0 when that strip has no area)
//   region_area        place: the area of the region's rectangle (m²); pick: 0
//   region_occupied    place: the share of the rectangle covered by the others' footprints, plus
//                      the footprint areas of the objects the prefix placed there, at most 1 (a
//                      rectangle without area: 1 when anything is counted, else 0); pick: 0
//
// A pick of an object that its context moved takes it at the centre of the region it went to.
// The same vector for the same world and action on every machine (no randomness, no tolerances).

#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/manipulation_world.hpp"

namespace ontime::domains {

inline constexpr double kManipulationGapCap = 0.5;
inline constexpr double kManipulationNeighbourRadius = 0.15;
// The open gripper with its clearance (0.14 m) and 8 cm either side, where neighbours crowd the
// hand and the forearm on their way to the object.
inline constexpr double kManipulationApproachWidth = 0.3;

// The names, in the order of manipulation_action_features' vector.
const std::vector<std::string>& manipulation_feature_names();

// Throws std::invalid_argument (the message says why) when `action_id` is not move+pick(O) or
// move+place(O,R) of the world's objects and regions, or names a context although it is in none
// of the world's skeletons (where those objects went is then unknown).
std::vector<double> manipulation_action_features(const ManipulationWorld& world, std::string_view action_id);

}  // namespace ontime::domains
