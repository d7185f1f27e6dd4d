#pragma once
// Types every domain's world shares: the pose of a mobile base in the plane (and the time to
// drive a path of them), a turned rectangle (footprints, furniture seen from above) and the
// defaults a world file gives the collection. Metres and radians.

#include <array>
#include <vector>

#include "ontime/model/distribution.hpp"

namespace ontime::domains {

// A mobile base in SE(2): position and heading.
struct Pose {
  double x = 0, y = 0, theta = 0;
};

// The time a base needs to drive through these poses in straight segments: length over
// `linear_speed` plus rotation (shortest angle at each segment) over `angular_speed`.
double drive_seconds(const std::vector<Pose>& poses, double linear_speed, double angular_speed);

// A rectangle of size `length` x `width` (along its own x and y axes), centred at (x, y),
// turned by `angle` radians.
struct Rectangle {
  double x = 0, y = 0, length = 0, width = 0, angle = 0;
  // The four corners (x, y), counterclockwise from the one at (-length/2, -width/2) in the rectangle's axes.
  std::array<std::array<double, 2>, 4> corners() const;
};

// The settings of `ontime collect` a world file carries.
struct CollectionDefaults {
  Steps deadline = 1;
  double step_seconds = 1;
  double checks_per_second = 1000;  // nominal collision-checker speed of the checks unit
};

}  // namespace ontime::domains
