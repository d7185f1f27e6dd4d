#pragma once
// Internal: planar geometry of convex shapes given by their vertices, for the world generators and
// the feature extractors (footprints seen from above). A shape is 1 point, 2 (a segment) or more
// vertices in order (a convex polygon). Exact arithmetic on doubles in a fixed order, no
// tolerances: the same inputs give the same numbers on every machine. Each call is O(n m) in the
// vertex counts.

#include <array>
#include <vector>

#include "ontime/domains/world_types.hpp"

namespace ontime::domains::detail {

using Point = std::array<double, 2>;

// The distance between two convex shapes: 0 when they touch or overlap.
double convex_distance(const std::vector<Point>& a, const std::vector<Point>& b);

// The corners of a turned rectangle, in order.
std::vector<Point> rectangle_corners(const Rectangle& rectangle);

// The corners of the axis-aligned rectangle [min_x, max_x] x [min_y, max_y], in order.
std::vector<Point> box_corners(double min_x, double min_y, double max_x, double max_y);

// The area of a polygon (its vertices in order, either way round): the shoelace formula.
double polygon_area(const std::vector<Point>& polygon);

// The part of a convex polygon inside the axis-aligned rectangle [min_x, max_x] x [min_y, max_y]
// (Sutherland–Hodgman clipping); empty when they do not overlap.
std::vector<Point> clip_to_box(const std::vector<Point>& polygon, double min_x, double min_y, double max_x,
                               double max_y);

}  // namespace ontime::domains::detail
