#include "planar_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ontime::domains::detail {
namespace {

double cross(const Point& o, const Point& a, const Point& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

double point_segment_distance(const Point& p, const Point& a, const Point& b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double length2 = dx * dx + dy * dy;
  const double t = length2 == 0 ? 0 : std::clamp(((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length2, 0.0, 1.0);
  return std::hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
}

bool segments_cross(const Point& a, const Point& b, const Point& c, const Point& d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

bool inside_convex(const Point& p, const std::vector<Point>& polygon) {
  if (polygon.size() < 3) return false;
  bool positive = false, negative = false;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const double side = cross(polygon[i], polygon[(i + 1) % polygon.size()], p);
    positive = positive || side > 0;
    negative = negative || side < 0;
  }
  return !(positive && negative);
}

std::vector<std::array<Point, 2>> edges(const std::vector<Point>& shape) {
  std::vector<std::array<Point, 2>> result;
  if (shape.size() == 1) return {{shape[0], shape[0]}};
  if (shape.size() == 2) return {{shape[0], shape[1]}};
  for (std::size_t i = 0; i < shape.size(); ++i) result.push_back({shape[i], shape[(i + 1) % shape.size()]});
  return result;
}

// One step of Sutherland–Hodgman: the part of `polygon` where inside(p) holds, the boundary
// crossings found by `cut(a, b)`.
template <class Inside, class Cut>
std::vector<Point> clip(const std::vector<Point>& polygon, Inside inside, Cut cut) {
  std::vector<Point> result;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Point& a = polygon[i];
    const Point& b = polygon[(i + 1) % polygon.size()];
    if (inside(a)) {
      result.push_back(a);
      if (!inside(b)) result.push_back(cut(a, b));
    } else if (inside(b)) {
      result.push_back(cut(a, b));
    }
  }
  return result;
}

}  // namespace

double convex_distance(const std::vector<Point>& a, const std::vector<Point>& b) {
  for (const Point& p : a) {
    if (inside_convex(p, b)) return 0;
  }
  for (const Point& p : b) {
    if (inside_convex(p, a)) return 0;
  }
  const auto a_edges = edges(a), b_edges = edges(b);
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& e : a_edges) {
    for (const auto& f : b_edges) {
      if (segments_cross(e[0], e[1], f[0], f[1])) return 0;
      nearest = std::min({nearest, point_segment_distance(e[0], f[0], f[1]), point_segment_distance(e[1], f[0], f[1]),
                          point_segment_distance(f[0], e[0], e[1]), point_segment_distance(f[1], e[0], e[1])});
    }
  }
  return nearest;
}

std::vector<Point> rectangle_corners(const Rectangle& rectangle) {
  const auto four = rectangle.corners();
  return {four.begin(), four.end()};
}

std::vector<Point> box_corners(double min_x, double min_y, double max_x, double max_y) {
  return {{min_x, min_y}, {max_x, min_y}, {max_x, max_y}, {min_x, max_y}};
}

double polygon_area(const std::vector<Point>& polygon) {
  double twice = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Point& a = polygon[i];
    const Point& b = polygon[(i + 1) % polygon.size()];
    twice += a[0] * b[1] - b[0] * a[1];
  }
  return std::abs(twice) / 2;
}

std::vector<Point> clip_to_box(const std::vector<Point>& polygon, double min_x, double min_y, double max_x,
                               double max_y) {
  const auto at_x = [](double x) {
    return [x](const Point& a, const Point& b) { return Point{x, a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])}; };
  };
  const auto at_y = [](double y) {
    return [y](const Point& a, const Point& b) { return Point{a[0] + (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]), y}; };
  };
  std::vector<Point> result = polygon;
  result = clip(
      result, [min_x](const Point& p) { return p[0] >= min_x; }, at_x(min_x));
  result = clip(
      result, [max_x](const Point& p) { return p[0] <= max_x; }, at_x(max_x));
  result = clip(
      result, [min_y](const Point& p) { return p[1] >= min_y; }, at_y(min_y));
  result = clip(
      result, [max_y](const Point& p) { return p[1] <= max_y; }, at_y(max_y));
  return result.size() < 3 ? std::vector<Point>{} : result;
}

}  // namespace ontime::domains::detail
