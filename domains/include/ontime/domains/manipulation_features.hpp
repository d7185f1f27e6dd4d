#pragma once
// The features of a manipulation action: what a conditional time model (learn/) sees of
// move+pick(O) or move+place(O,R) in a kitchen it may never have refined in. One layout for both
// kinds, a fixed-length vector from the world file's geometry alone (docs/learning.md,
// "Features"), in O(objects + furniture boxes + skeleton positions) per action, plus
// log_reach_share's draws.
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
//   log_reach_share_v2 log10 of the share of target draws, drawn as the refinement draws them (a
//                      grasp, for a place a placement in the region, a base pose, the arm's IK
//                      for the grasp and its approach) from kManipulationReachSeed, that reach
//                      collision-free in the world the action starts in, each draw with the
//                      moved objects set down anew at a placement drawn in their regions that
//                      overlaps nothing on its surface (where a refinement left them is not in
//                      the world file; a single guess such as the region's centre can block an
//                      approach that is open almost everywhere else they may stand): reaching
//                      draws over draws made, drawing
//                      until kManipulationReachHits have reached or kManipulationReachDraws were
//                      made; a share of 0 (none of those reached) counts as
//                      kManipulationReachShareFloor. Gaps and counts say how crowded a subject
//                      is; this says whether any approach is left open, which they cannot. On a
//                      log scale because what matters is 0 against 1 in 1,000 against 1 in 100,
//                      which a model linear in the share cannot tell apart. "_v2": the second
//                      definition (the first drew 10,000 with the moved objects at the centres
//                      of their regions, floor 1e-5), so that a model fitted on the first
//                      refuses to predict with this one instead of misreading it
//
// For the features other than log_reach_share, a pick of an object that its context moved takes it
// at the centre of the region it went to.
// The same vector for the same world and action on every run: log_reach_share's draws come from a
// fixed seed, the other features involve no randomness and no tolerances. log_reach_share goes
// through libm and KDL as the refinement does (docs/reliability.md): where glibc picks another
// build of sin or atan2 for another CPU, a draw on the edge of a collision may turn out otherwise.
// It costs up to two IK solves per draw (an action with no open approach draws all
// kManipulationReachDraws); the others are geometry of rectangles.

#include <cstdint>
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
// log_reach_share's draws: at most this many, stopping after kManipulationReachHits reaching ones,
// from this seed. Most actions a refinement finds reach in 1 draw in 1,000 to 100 on the training
// kitchens, but a refinement cut off at the deadline has made up to about 35,000 draws (a draw
// rejected early costs two of its 35,000-70,000 checks), so a share too small for 10,000 draws to
// see is still found by some of 30 attempts: with 10,000 draws, 47 of the 61 training actions
// that drew no reaching target were found at least once; with 100,000, 14 of 28 (docs/learning.md).
inline constexpr int kManipulationReachDraws = 100000;
inline constexpr int kManipulationReachHits = 10;
// A tenth of the least share above 0 that the draws can find.
inline constexpr double kManipulationReachShareFloor = 1e-6;
inline constexpr std::uint64_t kManipulationReachSeed = 1;

// The names, in the order of manipulation_action_features' vector.
const std::vector<std::string>& manipulation_feature_names();

// Throws std::invalid_argument (the message says why) when `action_id` is not move+pick(O) or
// move+place(O,R) of the world's objects and regions, or names a context although it is in none
// of the world's skeletons (where those objects went is then unknown).
std::vector<double> manipulation_action_features(const ManipulationWorld& world, std::string_view action_id);

}  // namespace ontime::domains
