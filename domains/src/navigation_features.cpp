#include "ontime/domains/navigation_features.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ontime::domains {
namespace {

std::array<double, 2> centre(const Room& room) {
  return {(room.min_x + room.max_x) / 2, (room.min_y + room.max_y) / 2};
}

double area(const Room& room) { return (room.max_x - room.min_x) * (room.max_y - room.min_y); }

// Distance from a point to a turned rectangle (0 inside it): the point in the rectangle's own
// frame, clamped to its half sizes.
double distance_to(const Rectangle& shape, double x, double y) {
  const double c = std::cos(shape.angle), s = std::sin(shape.angle);
  const double dx = x - shape.x, dy = y - shape.y;
  const double along = std::abs(c * dx + s * dy) - shape.length / 2;
  const double across = std::abs(-s * dx + c * dy) - shape.width / 2;
  return std::hypot(std::max(along, 0.0), std::max(across, 0.0));
}

struct RoomFurniture {
  double pieces = 0, occupied = 0;
};

RoomFurniture furniture_of(const NavigationWorld& world, const Room& room) {
  RoomFurniture furniture;
  for (const Obstacle& obstacle : world.obstacles) {
    if (!room.contains(obstacle.shape.x, obstacle.shape.y)) continue;
    furniture.pieces += 1;
    furniture.occupied += obstacle.shape.length * obstacle.shape.width;
  }
  furniture.occupied /= area(room);
  return furniture;
}

}  // namespace

const std::vector<std::string>& navigation_feature_names() {
  static const std::vector<std::string> names{"door_width",      "door_slack",    "door_furniture", "source_area",
                                              "target_area",     "source_pieces", "target_pieces",  "source_occupied",
                                              "target_occupied", "route_length",  "sampling_area"};
  return names;
}

std::vector<double> navigation_action_features(const NavigationWorld& world, std::string_view action) {
  const std::vector<std::string> rooms = move_rooms(action);
  if (rooms.size() != 2 || world.room_index(rooms[0]) < 0 || world.room_index(rooms[1]) < 0) {
    throw std::invalid_argument("'" + std::string(action) + "' is not move(FROM,TO) between rooms of " + world.name);
  }
  const Door* door = nullptr;
  for (const Door& candidate : world.doors) {
    const bool joins = (candidate.rooms[0] == rooms[0] && candidate.rooms[1] == rooms[1]) ||
                       (candidate.rooms[0] == rooms[1] && candidate.rooms[1] == rooms[0]);
    if (joins && (door == nullptr || candidate.width > door->width)) door = &candidate;
  }
  if (door == nullptr)
    throw std::invalid_argument("no door of " + world.name + " joins " + rooms[0] + " and " + rooms[1]);
  const Room& source = world.room(rooms[0]);
  const Room& target = world.room(rooms[1]);

  double nearest = kFeatureDistanceCap;
  for (const Obstacle& obstacle : world.obstacles) {
    if (!source.contains(obstacle.shape.x, obstacle.shape.y) && !target.contains(obstacle.shape.x, obstacle.shape.y)) {
      continue;
    }
    nearest = std::min(nearest, distance_to(obstacle.shape, door->x, door->y));
  }
  const RoomFurniture from = furniture_of(world, source), to = furniture_of(world, target);
  const auto [sx, sy] = centre(source);
  const auto [tx, ty] = centre(target);
  const double route = std::hypot(door->x - sx, door->y - sy) + std::hypot(tx - door->x, ty - door->y);
  const double box = (std::max(source.max_x, target.max_x) - std::min(source.min_x, target.min_x)) *
                     (std::max(source.max_y, target.max_y) - std::min(source.min_y, target.min_y));
  return {door->width,  door->width - (world.robot.width + 2 * world.robot.clearance),
          nearest,      area(source),
          area(target), from.pieces,
          to.pieces,    from.occupied,
          to.occupied,  route,
          box};
}

}  // namespace ontime::domains
