#include "ontime/domains/manipulation_features.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

#include "kitchen_reach.hpp"
#include "planar_geometry.hpp"

namespace ontime::domains {
namespace {

using detail::kSameHeight;
using detail::Point;

struct Surface {
  std::string furniture;
  double height = 0;
  const Box3* top = nullptr;  // the box under the subject's centre
};

// The first box of `furniture` whose top is at `height` and holds (x, y).
const Box3& top_under(const ManipulationWorld& world, const std::string& furniture, double height, double x, double y,
                      const std::string& what) {
  for (const FixedObject& fixed : world.fixed) {
    if (fixed.name != furniture) continue;
    for (const Box3& box : fixed.boxes) {
      if (std::abs(box.max[2] - height) <= kSameHeight && x >= box.min[0] && x <= box.max[0] && y >= box.min[1] &&
          y <= box.max[1]) {
        return box;
      }
    }
  }
  throw std::invalid_argument(what + " of " + world.name + " stands on no box of '" + furniture + "'");
}

// A region's rectangle as a convex shape: a polygon, or a segment or a point when it has no area.
std::vector<Point> rectangle_shape(const PlacementRegion& region) {
  if (region.max_x > region.min_x && region.max_y > region.min_y) {
    return detail::box_corners(region.min_x, region.min_y, region.max_x, region.max_y);
  }
  if (region.max_x > region.min_x || region.max_y > region.min_y) {
    return {{region.min_x, region.min_y}, {region.max_x, region.max_y}};
  }
  return {{region.min_x, region.min_y}};
}

// An edge of a surface's top: its distance from the subject's centre, and the strip between
// them, kManipulationApproachWidth wide.
struct Edge {
  double distance = 0;
  std::array<double, 4> strip{};  // min x, min y, max x, max y
  bool open = false;
};

// The four edges of `top` seen from (x, y): front (low y), back, left (low x), right.
std::array<Edge, 4> edges_of(const ManipulationWorld& world, const Box3& top, double x, double y) {
  const double side = std::max(world.robot.base_size[0], world.robot.base_size[1]);
  const double half = kManipulationApproachWidth / 2;
  std::array<Edge, 4> edges;
  edges[0] = {y - top.min[1], {x - half, top.min[1], x + half, y}};
  edges[1] = {top.max[1] - y, {x - half, y, x + half, top.max[1]}};
  edges[2] = {x - top.min[0], {top.min[0], y - half, x, y + half}};
  edges[3] = {top.max[0] - x, {x, y - half, top.max[0], y + half}};
  // Where the base would stand outside each edge.
  const std::array<std::array<double, 4>, 4> outside{{{x - side / 2, top.min[1] - side, x + side / 2, top.min[1]},
                                                      {x - side / 2, top.max[1], x + side / 2, top.max[1] + side},
                                                      {top.min[0] - side, y - side / 2, top.min[0], y + side / 2},
                                                      {top.max[0], y - side / 2, top.max[0] + side, y + side / 2}}};
  const auto& floor = world.floor;
  for (std::size_t e = 0; e < 4; ++e) {
    const auto& square = outside[e];
    bool open = square[0] >= floor[0] && square[1] >= floor[1] && square[2] <= floor[2] && square[3] <= floor[3];
    for (const FixedObject& fixed : world.fixed) {
      for (const Box3& box : fixed.boxes) {
        if (box.min[2] >= world.robot.base_size[2]) continue;
        if (box.min[0] < square[2] && box.max[0] > square[0] && box.min[1] < square[3] && box.max[1] > square[1]) {
          open = false;
        }
      }
    }
    edges[e].open = open;
  }
  return edges;
}

// The edge of `reach`: the nearest open one, else the nearest (the first of equals).
const Edge& reach_edge(const std::array<Edge, 4>& edges) {
  const Edge* best = nullptr;
  for (const Edge& edge : edges) {
    if (edge.open && (best == nullptr || edge.distance < best->distance)) best = &edge;
  }
  if (best != nullptr) return *best;
  best = &edges.front();
  for (const Edge& edge : edges) {
    if (edge.distance < best->distance) best = &edge;
  }
  return *best;
}

double covered(const std::vector<std::vector<Point>>& footprints, const std::array<double, 4>& box) {
  double area = 0;
  for (const auto& shape : footprints)
    area += detail::polygon_area(detail::clip_to_box(shape, box[0], box[1], box[2], box[3]));
  return area;
}

}  // namespace

const std::vector<std::string>& manipulation_feature_names() {
  static const std::vector<std::string> names{
      "is_place",    "object_short", "object_long",       "object_height", "surface_height",  "reach",
      "nearest_gap", "neighbours",   "approach_occupied", "region_area",   "region_occupied", "log_reach_share_v2"};
  return names;
}

std::vector<double> manipulation_action_features(const ManipulationWorld& world, std::string_view action_id) {
  const std::optional<ManipulationAction> action = parse_manipulation_action(action_id);
  const std::string text(action_id);
  if (!action || world.object_index(action->object) < 0 ||
      (action->kind == ManipulationKind::place && world.region_index(action->region) < 0)) {
    throw std::invalid_argument("'" + text +
                                "' is not move+pick(OBJECT) or move+place(OBJECT,REGION) of the objects "
                                "and regions of " +
                                world.name);
  }
  // Where the context's objects went: the prefix of the first skeleton holding the action.
  std::map<int, int> moved;  // object -> region
  std::vector<int> placed;   // the moved objects, in the order they were last placed
  bool listed = false;
  for (const auto& skeleton : world.skeletons) {
    const auto found = std::find(skeleton.begin(), skeleton.end(), text);
    if (found == skeleton.end()) continue;
    listed = true;
    for (auto it = skeleton.begin(); it != found; ++it) {
      const std::optional<ManipulationAction> before = parse_manipulation_action(*it);
      if (before && before->kind == ManipulationKind::place) {
        const int index = world.object_index(before->object);
        moved[index] = world.region_index(before->region);
        std::erase(placed, index);
        placed.push_back(index);
      }
    }
    break;
  }
  if (!listed && !action->context.empty()) {
    throw std::invalid_argument("'" + text + "' is in none of the skeletons of " + world.name +
                                ": where the objects of its context were placed is unknown");
  }
  const int subject = world.object_index(action->object);
  const MovableObject& object = world.objects[static_cast<std::size_t>(subject)];
  const bool place = action->kind == ManipulationKind::place;

  // The subject: its centre, its shape from above and its surface.
  Point centre{};
  std::vector<Point> shape;
  const PlacementRegion* region = nullptr;
  if (place) {
    region = &world.regions[static_cast<std::size_t>(world.region_index(action->region))];
    centre = {(region->min_x + region->max_x) / 2, (region->min_y + region->max_y) / 2};
    shape = rectangle_shape(*region);
  } else if (const auto went = moved.find(subject); went != moved.end()) {
    const PlacementRegion& there = world.regions[static_cast<std::size_t>(went->second)];
    centre = {(there.min_x + there.max_x) / 2, (there.min_y + there.max_y) / 2};
    shape = detail::object_footprint(object, ObjectPose{centre[0], centre[1], 0, 0});
    region = &there;
  } else {
    centre = {object.pose.x, object.pose.y};
    shape = detail::object_footprint(object, object.pose);
    region = &world.regions[static_cast<std::size_t>(world.region_index(object.region))];
  }
  const std::string what = place ? "region " + region->id : "object " + object.id;
  const Surface surface{region->surface, region->height,
                        &top_under(world, region->surface, region->height, centre[0], centre[1], what)};

  // The others: standing where they started, on the same surface.
  std::vector<std::vector<Point>> others;
  for (std::size_t j = 0; j < world.objects.size(); ++j) {
    const auto index = static_cast<int>(j);
    if (index == subject || moved.contains(index)) continue;
    const PlacementRegion& on = world.regions[static_cast<std::size_t>(world.region_index(world.objects[j].region))];
    if (!detail::same_surface(on, *region)) continue;
    others.push_back(detail::object_footprint(world.objects[j], world.objects[j].pose));
  }
  double gap = kManipulationGapCap;
  double neighbours = 0;
  for (const auto& other : others) {
    const double distance = detail::convex_distance(shape, other);
    gap = std::min(gap, distance);
    neighbours += distance <= kManipulationNeighbourRadius ? 1 : 0;
  }
  const std::array<Edge, 4> edges = edges_of(world, *surface.top, centre[0], centre[1]);  // outlives `edge`
  const Edge& edge = reach_edge(edges);
  const double strip = kManipulationApproachWidth * edge.distance;
  const double approach = strip > 0 ? std::min(1.0, covered(others, edge.strip) / strip) : 0.0;

  double region_area = 0, region_occupied = 0;
  if (place) {
    region_area = (region->max_x - region->min_x) * (region->max_y - region->min_y);
    double occupied = covered(others, {region->min_x, region->min_y, region->max_x, region->max_y});
    for (const auto& [moved_object, to] : moved) {
      if (moved_object == subject || world.regions[static_cast<std::size_t>(to)].id != region->id) continue;
      const auto& size = world.objects[static_cast<std::size_t>(moved_object)].size;
      occupied += size[0] * size[1];
    }
    region_occupied = region_area > 0 ? std::min(1.0, occupied / region_area) : (occupied > 0 ? 1.0 : 0.0);
  }

  // Whether the approaches are open, not only how crowded they are: the robot's own target draws
  // in the world the action starts in, each with the moved objects set down anew somewhere in
  // their regions (a refinement leaves them wherever its placement landed, which the world file
  // cannot say; one guess, such as the region's centre, can block an approach that is open
  // wherever else they stand).
  std::vector<ObjectPose> poses;
  poses.reserve(world.objects.size());
  for (const MovableObject& standing : world.objects) poses.push_back(standing.pose);
  std::vector<detail::MovedObject> layout;
  layout.reserve(placed.size());
  for (const int index : placed) {
    layout.push_back({static_cast<std::size_t>(index), &world.regions[static_cast<std::size_t>(moved.at(index))]});
  }
  const detail::ReachCount reach =
      detail::count_reaching_draws(world, poses, static_cast<std::size_t>(subject), place ? region : nullptr, layout,
                                   kManipulationReachHits, kManipulationReachDraws, kManipulationReachSeed);
  const double reach_share = static_cast<double>(reach.reached) / reach.drawn;
  const double log_reach_share = std::log10(std::max(reach_share, kManipulationReachShareFloor));
  return {place ? 1.0 : 0.0,
          std::min(object.size[0], object.size[1]),
          std::max(object.size[0], object.size[1]),
          object.size[2],
          surface.height,
          edge.distance,
          gap,
          neighbours,
          approach,
          region_area,
          region_occupied,
          log_reach_share};
}

}  // namespace ontime::domains
