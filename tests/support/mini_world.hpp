#pragma once
// A small, valid navigation world for tests: rooms A | B | C in a row with D above B, doors
// A-B, B-C and B-D, a box in C, one skeleton A -> B -> C. Bad worlds are made by editing it.

#include <string>

namespace ontime::testing {

inline const std::string kMiniWorld = R"json({
  "name": "mini",
  "wall_thickness": 0.1,
  "robot": {"footprint": [0.668, 0.668], "clearance": 0.02, "linear_speed": 1.0, "angular_speed": 1.0},
  "start": {"room": "A", "pose": [1.5, 1.5, 0.0]},
  "goal_room": "C",
  "planner": {"range": 1.0, "resolution": 0.02},
  "collection": {"deadline": 10, "step_seconds": 3.0, "checks_per_second": 1200},
  "rooms": {
    "A": {"min": [0, 0], "max": [3, 3]},
    "B": {"min": [3, 0], "max": [6, 3]},
    "C": {"min": [6, 0], "max": [9, 3]},
    "D": {"min": [3, 3], "max": [6, 6]}
  },
  "doors": [
    {"rooms": ["A", "B"], "center": [3, 1.5], "width": 1.0},
    {"rooms": ["B", "C"], "center": [6, 1.5], "width": 1.0},
    {"rooms": ["B", "D"], "center": [4.5, 3], "width": 1.0}
  ],
  "obstacles": [
    {"name": "box", "center": [7.5, 2.5], "size": [1.0, 0.5], "angle": 0.3}
  ],
  "skeletons": [["move(A,B)", "move(B,C)"]]
})json";

}  // namespace ontime::testing
