#include "ontime/domains/navigation_generator.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "ontime/domains/navigation_collision.hpp"
#include "ontime/domains/task_planner.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "planar_geometry.hpp"

namespace ontime::domains {
namespace {

using detail::Point;

// The robot and the planner and collection settings of the office floor
// (data/domains/navigation.json): the generated buildings are refined by the same robot with the
// same planner, and their instances have the same step and nominal checker speed; only the
// deadline grows with the building (deadline() below).
constexpr double kWallThickness = 0.1;
constexpr double kRobotSide = 0.668;  // PR2 base footprint, square
constexpr double kClearance = 0.02;
constexpr double kPassable = kRobotSide + 2 * kClearance;
constexpr Steps kOfficeDeadline = 22;

// Door widths (BuildingOptions): by default narrow ones a few centimetres wider than the robot
// with its clearance (the office floor's narrow doors are 0.78 m and 0.84 m), comfortable ones
// 1.0–1.2 m.
static_assert(kMinBuildingDoorWidth > kPassable, "every door must let the robot pass");

// The clear zones. The side pose of a door is kSideDistance from the wall's centre line: far
// enough for the padded footprint (half-diagonal 0.50 m) to turn on the spot clear of the wall
// (0.05 m thick on that side). A corridor of kCorridorRadius (wider than the padded footprint,
// 0.708 m, and than its half-diagonal) runs from the door's centre to the side pose and on to the
// room's centre: it holds the drive through the door, the turn at the side pose and the drive to
// the centre; there the centre disc holds another turn. So furniture keeps a disc of
// kCorridorRadius clear around each door centre, on both sides.
constexpr double kSideDistance = 0.6;
constexpr double kCorridorRadius = 0.55;
constexpr double kCentreDiscRadius = 0.8;
// Door centres stay this far from the ends of their edge, so the side pose turns clear of the
// walls across the ends.
constexpr double kDoorEndMargin = 1.0;
// Furniture pieces are at least this far apart, so the robot (0.708 m with clearance) can pass
// between any two and no free pocket is closed off by furniture alone.
constexpr double kFurnitureGap = 0.75;
// Furniture keeps this far from the walls' inner faces (or stands against them).
constexpr double kWallGap = 0.02;

constexpr int kPlacementTries = 200;

double centimetres(double value) {
  const double rounded = std::round(value * 100.0) / 100.0;
  return rounded == 0.0 ? 0.0 : rounded;  // no "-0"
}

// Shortest text that reads back to the same double: the same on every platform.
std::string number(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
}

std::string pair_text(double x, double y) {
  std::string text = "[";
  text += number(x);
  text += ", ";
  text += number(y);
  text += "]";
  return text;
}

std::string json_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

double uniform(SplitMix64& random, double low, double high) { return low + (high - low) * uniform01(random); }

std::size_t below(SplitMix64& random, std::size_t count) {
  return std::min(count - 1, static_cast<std::size_t>(uniform01(random) * static_cast<double>(count)));
}

using detail::convex_distance;

std::vector<Point> corners(const Rectangle& rectangle) { return detail::rectangle_corners(rectangle); }

// ---- the building

struct Cell {
  int row = 0, col = 0;
};

// A shape furniture must stay `radius` away from: a disc (one point) or a capsule (a segment).
struct ClearZone {
  std::vector<Point> shape;
  double radius = 0;
};

struct DoorPlan {
  int a = 0, b = 0;  // room indices, a left of or below b
  bool vertical = false;
  double x = 0, y = 0, width = 0;
  bool narrow = false;
};

struct Piece {
  std::string name;
  Rectangle shape;
};

class Generator {
 public:
  explicit Generator(const BuildingOptions& options) : options_(options) {
    if (options.rows < 1 || options.cols < 1 || options.rows > kMaxBuildingSide || options.cols > kMaxBuildingSide) {
      throw std::invalid_argument("rows and cols must be between 1 and " + std::to_string(kMaxBuildingSide));
    }
    if (options.rows * options.cols < 2) throw std::invalid_argument("a building needs at least two rooms");
    if (!(options.room_size >= kMinBuildingRoomSize && options.room_size <= kMaxBuildingRoomSize)) {
      throw std::invalid_argument("the room size must be between " + number(kMinBuildingRoomSize) + " and " +
                                  number(kMaxBuildingRoomSize) + " m");
    }
    if (!(options.door_density >= 0 && options.door_density <= 1)) {
      throw std::invalid_argument("the door density must be between 0 and 1");
    }
    if (!(options.narrow_door_share >= 0 && options.narrow_door_share <= 1)) {
      throw std::invalid_argument("the share of narrow doors must be between 0 and 1");
    }
    check_widths("narrow", options.narrow_width_min, options.narrow_width_max);
    check_widths("wide", options.wide_width_min, options.wide_width_max);
    if (!(options.empty_room_share >= 0 && options.empty_room_share <= 1)) {
      throw std::invalid_argument("the share of empty rooms must be between 0 and 1");
    }
    if (!(options.cluttered_room_share >= 0 && options.cluttered_room_share <= 1)) {
      throw std::invalid_argument("the share of cluttered rooms must be between 0 and 1");
    }
    if (options.empty_room_share + options.cluttered_room_share > 1) {
      throw std::invalid_argument("the shares of empty and cluttered rooms must sum to at most 1");
    }
    if (options.min_boxes < 0 || options.max_boxes > kMaxBuildingBoxes || options.min_boxes > options.max_boxes) {
      throw std::invalid_argument("the boxes of a cluttered room must be a range within 0.." +
                                  std::to_string(kMaxBuildingBoxes));
    }
    size_ = centimetres(options.room_size);
    name_ = options.name.empty() ? "building-" + std::to_string(options.rows) + "x" + std::to_string(options.cols)
                                 : options.name;
  }

  static void check_widths(const std::string& kind, double low, double high) {
    if (!(low >= kMinBuildingDoorWidth && high <= kMaxBuildingDoorWidth && low <= high)) {
      throw std::invalid_argument("the " + kind + " doors' widths must be a range within " +
                                  number(kMinBuildingDoorWidth) + ".." + number(kMaxBuildingDoorWidth) + " m");
    }
  }

  std::string text() {
    plan_doors();
    for (int room = 0; room < room_count(); ++room) furnish(room);
    return write({});
  }

  // The same building with these skeletons (room paths of its task planner).
  std::string text_with(const std::vector<std::vector<std::string>>& skeletons) const { return write(skeletons); }

 private:
  int room_count() const { return options_.rows * options_.cols; }
  Cell cell(int room) const { return Cell{room / options_.cols, room % options_.cols}; }
  static std::string room_id(int room) {
    std::string id = "R";
    id += std::to_string(room + 1);
    return id;
  }
  double low_x(int room) const { return centimetres(cell(room).col * size_); }
  double low_y(int room) const { return centimetres(cell(room).row * size_); }
  double high_x(int room) const { return centimetres((cell(room).col + 1) * size_); }
  double high_y(int room) const { return centimetres((cell(room).row + 1) * size_); }
  Point centre(int room) const {
    return {centimetres((low_x(room) + high_x(room)) / 2), centimetres((low_y(room) + high_y(room)) / 2)};
  }

  // A random spanning tree (Kruskal's algorithm over the neighbour pairs in random order), then
  // the pairs the tree left out, in the same order, until the density is reached.
  void plan_doors() {
    std::vector<std::array<int, 2>> pairs;
    for (int room = 0; room < room_count(); ++room) {
      const Cell at = cell(room);
      if (at.col + 1 < options_.cols) pairs.push_back({room, room + 1});
      if (at.row + 1 < options_.rows) pairs.push_back({room, room + options_.cols});
    }
    std::vector<std::size_t> order(pairs.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    SplitMix64 shuffle(stream_seed(options_.seed, 0));
    for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[below(shuffle, i)]);

    std::vector<int> parent(static_cast<std::size_t>(room_count()));
    std::iota(parent.begin(), parent.end(), 0);
    const auto root = [&parent](int room) {
      while (parent[static_cast<std::size_t>(room)] != room) {
        room = parent[static_cast<std::size_t>(room)] =
            parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(room)])];
      }
      return room;
    };
    std::vector<char> chosen(pairs.size(), 0);
    std::vector<std::size_t> left_out;
    std::size_t doors = 0;
    for (const std::size_t p : order) {
      const int a = root(pairs[p][0]), b = root(pairs[p][1]);
      if (a == b) {
        left_out.push_back(p);
        continue;
      }
      parent[static_cast<std::size_t>(a)] = b;
      chosen[p] = 1;
      ++doors;
    }
    const auto wanted =
        static_cast<std::size_t>(std::llround(options_.door_density * static_cast<double>(pairs.size())));
    for (std::size_t i = 0; i < left_out.size() && doors < wanted; ++i, ++doors) chosen[left_out[i]] = 1;

    // Each door draws its width and place from its own stream: the doors a density adds do not
    // move the others.
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      if (chosen[p] == 0) continue;
      SplitMix64 random(stream_seed(stream_seed(options_.seed, 1), p));
      DoorPlan door;
      door.a = pairs[p][0];
      door.b = pairs[p][1];
      door.vertical = door.b == door.a + 1;  // side by side in x: the shared edge runs along y
      door.narrow = uniform01(random) < options_.narrow_door_share;
      door.width = centimetres(door.narrow ? uniform(random, options_.narrow_width_min, options_.narrow_width_max)
                                           : uniform(random, options_.wide_width_min, options_.wide_width_max));
      const double reach = std::max(0.0, size_ / 2 - kDoorEndMargin);
      const double offset = centimetres(uniform(random, -reach, reach));
      if (door.vertical) {
        door.x = high_x(door.a);
        door.y = centimetres(centre(door.a)[1] + offset);
      } else {
        door.x = centimetres(centre(door.a)[0] + offset);
        door.y = high_y(door.a);
      }
      doors_.push_back(door);
    }
  }

  // The side pose of a door in `room` (one of its two rooms) and the direction into the room.
  static Point side_point(const DoorPlan& door, int room) {
    const double sign = room == door.b ? 1.0 : -1.0;
    return door.vertical ? Point{door.x + sign * kSideDistance, door.y} : Point{door.x, door.y + sign * kSideDistance};
  }

  std::vector<ClearZone> clear_zones(int room) const {
    std::vector<ClearZone> zones{{{centre(room)}, kCentreDiscRadius}};
    for (const DoorPlan& door : doors_) {
      if (door.a != room && door.b != room) continue;
      zones.push_back({{{door.x, door.y}, side_point(door, room)}, kCorridorRadius});
      zones.push_back({{side_point(door, room), centre(room)}, kCorridorRadius});
    }
    return zones;
  }

  bool fits(const Rectangle& shape, int room, const std::vector<ClearZone>& zones,
            const std::vector<Piece>& placed) const {
    const std::vector<Point> outline = corners(shape);
    const double inner = kWallThickness / 2 + kWallGap;
    for (const Point& p : outline) {
      if (p[0] < low_x(room) + inner || p[0] > high_x(room) - inner || p[1] < low_y(room) + inner ||
          p[1] > high_y(room) - inner) {
        return false;
      }
    }
    for (const ClearZone& zone : zones) {
      if (convex_distance(outline, zone.shape) < zone.radius) return false;
    }
    for (const Piece& piece : placed) {
      if (convex_distance(outline, corners(piece.shape)) < kFurnitureGap) return false;
    }
    return true;
  }

  // Empty (by default a quarter of the rooms), furnished against the walls (two fifths) or
  // cluttered with turned boxes (the rest).
  void furnish(int room) {
    SplitMix64 random(stream_seed(stream_seed(options_.seed, 2), static_cast<std::uint64_t>(room)));
    const std::vector<ClearZone> zones = clear_zones(room);
    std::vector<Piece> placed;
    const double kind = uniform01(random);
    if (kind < options_.empty_room_share) return;
    const double inner = kWallThickness / 2 + kWallGap;
    if (kind < 1 - options_.cluttered_room_share) {
      struct Furniture {
        const char* name;
        double length, width;
      };
      static constexpr std::array<Furniture, 7> catalogue{{{"desk", 1.4, 0.7},
                                                           {"shelf", 1.8, 0.4},
                                                           {"table", 1.2, 0.8},
                                                           {"cabinet", 1.0, 0.45},
                                                           {"sofa", 1.8, 0.8},
                                                           {"plant", 0.5, 0.5},
                                                           {"chair", 0.5, 0.5}}};
      const std::size_t count = 1 + below(random, 3);
      for (std::size_t k = 0; k < count; ++k) {
        const Furniture& item = catalogue[below(random, catalogue.size())];
        for (int attempt = 0; attempt < kPlacementTries; ++attempt) {
          // Against one of the four walls, its long side along it.
          const std::size_t wall = below(random, 4);
          const bool along_x = wall < 2;
          const double half_across = item.width / 2, half_along = item.length / 2;
          Rectangle shape{0, 0, item.length, item.width, along_x ? 0.0 : std::numbers::pi / 2};
          if (along_x) {
            shape.x = uniform(random, low_x(room) + inner + half_along, high_x(room) - inner - half_along);
            shape.y = wall == 0 ? low_y(room) + inner + half_across : high_y(room) - inner - half_across;
          } else {
            shape.y = uniform(random, low_y(room) + inner + half_along, high_y(room) - inner - half_along);
            shape.x = wall == 2 ? low_x(room) + inner + half_across : high_x(room) - inner - half_across;
          }
          shape.x = centimetres(shape.x);
          shape.y = centimetres(shape.y);
          shape.angle = centimetres(shape.angle);
          if (!fits(shape, room, zones, placed)) continue;
          placed.push_back(Piece{room_id(room) + " " + item.name, shape});
          break;
        }
      }
    } else {
      const auto fewest = static_cast<std::size_t>(options_.min_boxes);
      const std::size_t count = fewest + below(random, static_cast<std::size_t>(options_.max_boxes) - fewest + 1);
      for (std::size_t k = 0; k < count; ++k) {
        for (int attempt = 0; attempt < kPlacementTries; ++attempt) {
          const Rectangle shape{centimetres(uniform(random, low_x(room), high_x(room))),
                                centimetres(uniform(random, low_y(room), high_y(room))),
                                centimetres(uniform(random, 0.3, 1.0)), centimetres(uniform(random, 0.3, 0.8)),
                                centimetres(uniform(random, 0.0, std::numbers::pi))};
          if (!fits(shape, room, zones, placed)) continue;
          placed.push_back(Piece{room_id(room) + " box " + std::to_string(placed.size() + 1), shape});
          break;
        }
      }
    }
    furniture_.insert(furniture_.end(), placed.begin(), placed.end());
  }

  // The office's 22 steps cover its 4 moves; a shortest path here has rows + cols - 2 moves of
  // about 3 steps of execution and 1-2 of planning each: 5 steps a move, at least the office's.
  Steps deadline() const {
    return std::max<Steps>(kOfficeDeadline, 5 * static_cast<Steps>(options_.rows + options_.cols - 2));
  }

  // The door widths and furniture when they are not the defaults (the default building's text
  // is unchanged by their existence).
  std::string family_text() const {
    const BuildingOptions defaults;
    const BuildingOptions& o = options_;
    if (o.narrow_width_min == defaults.narrow_width_min && o.narrow_width_max == defaults.narrow_width_max &&
        o.wide_width_min == defaults.wide_width_min && o.wide_width_max == defaults.wide_width_max &&
        o.empty_room_share == defaults.empty_room_share && o.cluttered_room_share == defaults.cluttered_room_share &&
        o.min_boxes == defaults.min_boxes && o.max_boxes == defaults.max_boxes) {
      return "";
    }
    return " Narrow doors " + number(o.narrow_width_min) + "-" + number(o.narrow_width_max) + " m, others " +
           number(o.wide_width_min) + "-" + number(o.wide_width_max) + " m; empty-room share " +
           number(o.empty_room_share) + ", cluttered-room share " + number(o.cluttered_room_share) + " (" +
           std::to_string(o.min_boxes) + "-" + std::to_string(o.max_boxes) + " boxes).";
  }

  std::string write(const std::vector<std::vector<std::string>>& skeletons) const {
    const int goal = room_count() - 1;
    std::size_t narrow = 0;
    for (const DoorPlan& door : doors_) narrow += door.narrow ? 1 : 0;
    const std::string description =
        "Generated office building of " + std::to_string(options_.rows) + " x " + std::to_string(options_.cols) +
        " rooms of " + number(size_) + " m x " + number(size_) + " m (seed " + std::to_string(options_.seed) +
        ", door density " + number(options_.door_density) + ", narrow-door share " +
        number(options_.narrow_door_share) + "): " + std::to_string(doors_.size()) + " doors (" +
        std::to_string(narrow) + " narrow), " + std::to_string(furniture_.size()) + " pieces of furniture; start in " +
        room_id(0) + " (bottom left), goal " + room_id(goal) + " (top right). " +
        (skeletons.empty() ? std::string("No skeletons: collect every doorway move on its own.")
                           : "Skeletons: the " + std::to_string(skeletons.size()) + " shortest room paths.") +
        family_text();
    const Point start = centre(0);
    std::string out = "{\n";
    out += "  \"name\": " + json_string(name_) + ",\n";
    out += "  \"description\": " + json_string(description) + ",\n";
    out += "  \"wall_thickness\": " + number(kWallThickness) + ",\n";
    out += "  \"robot\": {\"footprint\": " + pair_text(kRobotSide, kRobotSide) +
           ", \"clearance\": " + number(kClearance) + ", \"linear_speed\": 1.0, \"angular_speed\": 1.0},\n";
    out += "  \"start\": {\"room\": " + json_string(room_id(0)) + ", \"pose\": [" + number(start[0]) + ", " +
           number(start[1]) + ", 0]},\n";
    out += "  \"goal_room\": " + json_string(room_id(goal)) + ",\n";
    out += "  \"planner\": {\"range\": 1.0, \"resolution\": 0.02},\n";
    out += "  \"collection\": {\"deadline\": " + std::to_string(deadline()) +
           ", \"step_seconds\": 3.0, \"checks_per_second\": 1200},\n";
    out += "  \"rooms\": {\n";
    for (int room = 0; room < room_count(); ++room) {
      out += "    " + json_string(room_id(room)) + ": {\"min\": " + pair_text(low_x(room), low_y(room)) +
             ", \"max\": " + pair_text(high_x(room), high_y(room)) + "}" + (room + 1 < room_count() ? ",\n" : "\n");
    }
    out += "  },\n  \"doors\": [\n";
    for (std::size_t i = 0; i < doors_.size(); ++i) {
      const DoorPlan& door = doors_[i];
      out += "    {\"rooms\": [" + json_string(room_id(door.a)) + ", " + json_string(room_id(door.b)) +
             "], \"center\": " + pair_text(door.x, door.y) + ", \"width\": " + number(door.width) + "}" +
             (i + 1 < doors_.size() ? ",\n" : "\n");
    }
    out += "  ],\n  \"obstacles\": [";
    for (std::size_t i = 0; i < furniture_.size(); ++i) {
      const Rectangle& shape = furniture_[i].shape;
      out += std::string(i == 0 ? "\n" : ",\n") + "    {\"name\": " + json_string(furniture_[i].name) +
             ", \"center\": " + pair_text(shape.x, shape.y) + ", \"size\": " + pair_text(shape.length, shape.width) +
             ", \"angle\": " + number(shape.angle) + "}";
    }
    out += furniture_.empty() ? "]" : "\n  ]";
    if (!skeletons.empty()) {
      out += ",\n  \"skeletons\": [";
      for (std::size_t k = 0; k < skeletons.size(); ++k) {
        out += std::string(k == 0 ? "\n" : ",\n") + "    [";
        for (std::size_t l = 0; l < skeletons[k].size(); ++l) {
          out += (l == 0 ? "" : ", ") + json_string(skeletons[k][l]);
        }
        out += "]";
      }
      out += "\n  ]";
    }
    out += "\n}\n";
    return out;
  }

  BuildingOptions options_;
  double size_ = 0;
  std::string name_;
  std::vector<DoorPlan> doors_;
  std::vector<Piece> furniture_;
};

// Appends poses from `from` to `to` (heading `theta`), at most `spacing` apart, `from` excluded.
void drive(std::vector<Pose>& route, const Point& from, const Point& to, double theta, double spacing) {
  const double length = std::hypot(to[0] - from[0], to[1] - from[1]);
  const auto steps = std::max<long>(1, std::lround(std::ceil(length / spacing)));
  for (long i = 1; i <= steps; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(steps);
    route.push_back(Pose{from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1]), theta});
  }
}

// Appends a whole turn on the spot at `at`, from heading `theta`, 0.1 rad or less a step.
void turn(std::vector<Pose>& route, const Point& at, double theta) {
  const int steps = static_cast<int>(std::ceil(2 * std::numbers::pi / 0.1));
  for (int i = 1; i <= steps; ++i) route.push_back(Pose{at[0], at[1], theta + 2 * std::numbers::pi * i / steps});
}

}  // namespace

std::string generate_navigation_world_text(const BuildingOptions& options) {
  if (options.skeletons < 0 || options.skeletons > kMaxBuildingSkeletons) {
    throw std::invalid_argument("the skeletons must be between 0 and " + std::to_string(kMaxBuildingSkeletons));
  }
  Generator generator(options);
  std::string text = generator.text();
  // The world as read back must keep every promise: each door's routes free of collisions.
  const NavigationWorld world = parse_navigation_world(text, "generated world");
  const NavigationCollision collision(world, world.robot.clearance);
  for (const Door& door : world.doors) {
    for (const std::string& room : door.rooms) {
      for (const Pose& pose : door_route(world, door, room)) {
        if (collision.collides(pose)) {
          throw std::logic_error("generated world: the route through the door " + door.rooms[0] + "-" + door.rooms[1] +
                                 " into " + room + " is blocked");
        }
      }
    }
  }
  if (options.skeletons > 0) {
    const std::unique_ptr<TaskPlanner> planner = room_path_planners(world, options.skeletons)();
    std::vector<std::vector<std::string>> skeletons;
    // An instance's actions form a prefix tree (SPEC §1): a move reached after other moves than
    // before is a node of its own, named as the streaming TAMP loop names it (planner_world.hpp):
    // the move's id followed by "#2", "#3", ...
    std::map<std::pair<std::string, std::string>, std::string> node_of;  // (parent node, move) -> node
    std::set<std::string> taken;
    for (int k = 0; k < options.skeletons; ++k) {
      std::optional<std::vector<std::string>> path = planner->next();
      if (!path) break;  // a small building has fewer simple paths
      std::vector<std::string> skeleton;
      std::string parent;
      for (const std::string& move : *path) {
        auto [node, added] = node_of.try_emplace({parent, move}, move);
        if (added) {
          for (int copy = 2; taken.contains(node->second); ++copy) node->second = move + "#" + std::to_string(copy);
          taken.insert(node->second);
        }
        skeleton.push_back(node->second);
        parent = node->second;
      }
      skeletons.push_back(std::move(skeleton));
    }
    text = generator.text_with(skeletons);
  }
  return text;
}

NavigationWorld generate_navigation_world(const BuildingOptions& options) {
  NavigationWorld world = parse_navigation_world(generate_navigation_world_text(options), "generated world");
  world.source = world.name;
  return world;
}

GeneratedWorld write_generated_world(const BuildingOptions& options, const std::filesystem::path& output) {
  std::string text;
  try {
    text = generate_navigation_world_text(options);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());
  }
  write_file_atomically(output, text);
  const NavigationWorld world = parse_navigation_world(text, output.string());
  return GeneratedWorld{output.string(),        world.name,       world.rooms.size(), world.doors.size(),
                        world.obstacles.size(), world.start_room, world.goal_room};
}

std::vector<Pose> door_route(const NavigationWorld& world, const Door& door, std::string_view room_id, double spacing) {
  if (room_id != door.rooms[0] && room_id != door.rooms[1]) {
    throw std::invalid_argument("room " + std::string(room_id) + " is not one of the door's rooms");
  }
  if (!(spacing > 0)) throw std::invalid_argument("the spacing must be positive");
  const Room& room = world.room(room_id);
  const Point door_centre{door.x, door.y};
  // Into the room: towards its side of the shared edge.
  const double sign =
      door.on_vertical_edge ? (room.max_x > door.x + 1e-9 ? 1.0 : -1.0) : (room.max_y > door.y + 1e-9 ? 1.0 : -1.0);
  const double across = door.on_vertical_edge ? (sign > 0 ? 0.0 : std::numbers::pi)
                                              : (sign > 0 ? std::numbers::pi / 2 : -std::numbers::pi / 2);
  const Point side = door.on_vertical_edge ? Point{door.x + sign * kSideDistance, door.y}
                                           : Point{door.x, door.y + sign * kSideDistance};
  const Point middle{(room.min_x + room.max_x) / 2, (room.min_y + room.max_y) / 2};
  std::vector<Pose> route{Pose{door.x, door.y, across}};
  drive(route, door_centre, side, across, spacing);
  turn(route, side, across);
  const double heading = std::atan2(middle[1] - side[1], middle[0] - side[0]);
  drive(route, side, middle, heading, spacing);
  turn(route, middle, heading);
  return route;
}

}  // namespace ontime::domains
