#include "ontime/domains/navigation_world.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <stdexcept>

#include "ontime/domains/navigation_collision.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/model/skeleton_file.hpp"
#include "ontime/util/error.hpp"
#include "world_fields.hpp"

namespace ontime::domains {
namespace {

using detail::Json;
using detail::number_text;
constexpr double kTolerance = 1e-9;

// The edge two rooms share: a vertical one (x = across) when they sit side by side in x, a
// horizontal one (y = across) when one is above the other; it runs from `low` to `high`.
struct SharedEdge {
  bool vertical;
  double across, low, high;
};

std::optional<SharedEdge> shared_edge(const Room& a, const Room& b) {
  for (const bool vertical : {true, false}) {
    const double a_min = vertical ? a.min_x : a.min_y, a_max = vertical ? a.max_x : a.max_y;
    const double b_min = vertical ? b.min_x : b.min_y, b_max = vertical ? b.max_x : b.max_y;
    double across = 0;
    if (std::abs(a_max - b_min) < kTolerance) {
      across = a_max;
    } else if (std::abs(b_max - a_min) < kTolerance) {
      across = a_min;
    } else {
      continue;
    }
    const double low = std::max(vertical ? a.min_y : a.min_x, vertical ? b.min_y : b.min_x);
    const double high = std::min(vertical ? a.max_y : a.max_x, vertical ? b.max_y : b.max_x);
    if (high - low > kTolerance) return SharedEdge{vertical, across, low, high};
  }
  return std::nullopt;
}

class WorldReader : detail::WorldFields {
 public:
  explicit WorldReader(std::string source) : WorldFields(std::move(source)) {}

  NavigationWorld read(std::string_view text) {
    const Json root = detail::parse_json_strict<Json>(text, source());
    if (!root.is_object())
      fail("top level", "a world must be a JSON object (got " + detail::describe_json_type(root) + ")");
    check_keys(root, "",
               {"name", "description", "wall_thickness", "rooms", "doors", "obstacles", "robot", "start", "goal_room",
                "planner", "collection", "skeletons"});
    NavigationWorld world;
    world.source = source();
    world.name =
        root.contains("name") ? string_at(root["name"], "name") : std::filesystem::path(source()).stem().string();
    if (root.contains("description")) world.description = string_at(root["description"], "description");
    world.wall_thickness = positive(member(root, "", "wall_thickness"), "wall_thickness");
    world.robot = read_robot(member(root, "", "robot"));
    world.planner = read_planner(member(root, "", "planner"), world.wall_thickness);
    world.collection = collection(member(root, "", "collection"));
    read_rooms(member(root, "", "rooms"), world);
    read_doors(member(root, "", "doors"), world);
    if (root.contains("obstacles")) read_obstacles(root["obstacles"], world);
    world.walls = build_walls(world);
    read_start(member(root, "", "start"), world);
    world.goal_room = room_id(member(root, "", "goal_room"), "goal_room", world);
    if (world.goal_room == world.start_room) fail("goal_room", "the goal room must differ from the start room");
    check_goal_reachable(world);
    // Optional: a world may be only a map, its skeletons left to a task planner (a generated
    // building has far too many room paths to list).
    if (root.contains("skeletons")) read_skeletons(text, world);
    return world;
  }

 private:
  RobotModel read_robot(const Json& value) const {
    object_at(value, "robot");
    check_keys(value, "robot", {"footprint", "clearance", "linear_speed", "angular_speed"});
    RobotModel robot;
    const std::vector<double> footprint =
        numbers(member(value, "robot", "footprint"), "robot.footprint", 2, "length, width");
    if (!(footprint[0] > 0 && footprint[1] > 0)) fail("robot.footprint", "length and width must be positive");
    robot.length = footprint[0];
    robot.width = footprint[1];
    robot.clearance = finite(member(value, "robot", "clearance"), "robot.clearance");
    if (robot.clearance < 0) fail("robot.clearance", "must be at least 0");
    robot.linear_speed = positive(member(value, "robot", "linear_speed"), "robot.linear_speed");
    robot.angular_speed = positive(member(value, "robot", "angular_speed"), "robot.angular_speed");
    return robot;
  }

  PlannerSettings read_planner(const Json& value, double wall_thickness) const {
    object_at(value, "planner");
    check_keys(value, "planner", {"range", "resolution"});
    PlannerSettings planner;
    planner.range = positive(member(value, "planner", "range"), "planner.range");
    planner.resolution = positive(member(value, "planner", "resolution"), "planner.resolution");
    if (planner.resolution >= wall_thickness) {
      fail("planner.resolution", "must be below the wall thickness (" + number_text(wall_thickness) +
                                     " m), or a motion could jump through a wall between two checks");
    }
    return planner;
  }

  void read_rooms(const Json& value, NavigationWorld& world) const {
    if (!value.is_object()) fail("rooms", "must be an object mapping room ids to rectangles");
    if (value.size() < 2) fail("rooms", "at least two rooms are needed");
    const double smallest = std::max(world.robot.length, world.robot.width) + 2 * world.robot.clearance;
    for (const auto& [id, room_json] : value.items()) {
      const std::string path = detail::json_member("rooms", id);
      if (id.empty() || id.find_first_of("(), ") != std::string::npos) {
        fail(path, "room ids must be non-empty, without '(', ')', ',' or spaces");
      }
      object_at(room_json, path);
      check_keys(room_json, path, {"min", "max"});
      const std::vector<double> low =
          numbers(member(room_json, path, "min"), detail::json_member(path, "min"), 2, "x, y");
      const std::vector<double> high =
          numbers(member(room_json, path, "max"), detail::json_member(path, "max"), 2, "x, y");
      Room room{id, low[0], low[1], high[0], high[1]};
      if (!(room.max_x > room.min_x && room.max_y > room.min_y)) fail(path, "'max' must exceed 'min' in x and in y");
      if (std::min(room.max_x - room.min_x, room.max_y - room.min_y) - world.wall_thickness <= smallest) {
        fail(path, "too small for the robot (its footprint with clearance needs more than " + number_text(smallest) +
                       " m between the walls)");
      }
      for (const Room& other : world.rooms) {
        if (room.min_x < other.max_x - kTolerance && other.min_x < room.max_x - kTolerance &&
            room.min_y < other.max_y - kTolerance && other.min_y < room.max_y - kTolerance) {
          fail(path, "overlaps room " + other.id + " (rooms may share edges, not area)");
        }
      }
      world.rooms.push_back(room);
    }
  }

  std::string room_id(const Json& value, const std::string& path, const NavigationWorld& world) const {
    std::string id = string_at(value, path);
    if (world.room_index(id) < 0) fail(path, "unknown room '" + id + "' (not a key of 'rooms')");
    return id;
  }

  void read_doors(const Json& value, NavigationWorld& world) const {
    if (!value.is_array()) fail("doors", "must be an array of doors");
    const double passable = world.robot.width + 2 * world.robot.clearance;
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string path = detail::json_index("doors", i);
      const Json& door_json = object_at(value[i], path);
      check_keys(door_json, path, {"rooms", "center", "width"});
      const Json& rooms = member(door_json, path, "rooms");
      const std::string rooms_path = detail::json_member(path, "rooms");
      if (!rooms.is_array() || rooms.size() != 2) fail(rooms_path, "must name two rooms");
      Door door;
      door.rooms = {room_id(rooms[0], detail::json_index(rooms_path, 0), world),
                    room_id(rooms[1], detail::json_index(rooms_path, 1), world)};
      if (door.rooms[0] == door.rooms[1]) fail(rooms_path, "a door joins two different rooms");
      const std::vector<double> center =
          numbers(member(door_json, path, "center"), detail::json_member(path, "center"), 2, "x, y");
      door.x = center[0];
      door.y = center[1];
      door.width = positive(member(door_json, path, "width"), detail::json_member(path, "width"));
      if (door.width <= passable) {
        fail(detail::json_member(path, "width"),
             "narrower than the robot (" + number_text(passable) + " m with clearance); it could never pass");
      }
      const Room& a = world.room(door.rooms[0]);
      const Room& b = world.room(door.rooms[1]);
      const std::optional<SharedEdge> edge = shared_edge(a, b);
      if (!edge) fail(rooms_path, "rooms " + a.id + " and " + b.id + " share no edge");
      door.on_vertical_edge = edge->vertical;
      const double across = edge->vertical ? door.x : door.y;
      const double along = edge->vertical ? door.y : door.x;
      if (std::abs(across - edge->across) > kTolerance) {
        fail(detail::json_member(path, "center"), std::string("not on the edge ") + (edge->vertical ? "x" : "y") +
                                                      " = " + number_text(edge->across) + " that rooms " + a.id +
                                                      " and " + b.id + " share");
      }
      const double along_low = edge->low, along_high = edge->high;
      if (along - door.width / 2 < along_low + world.wall_thickness / 2 - kTolerance ||
          along + door.width / 2 > along_high - world.wall_thickness / 2 + kTolerance) {
        fail(path, "the opening does not fit within the edge that rooms " + a.id + " and " + b.id + " share");
      }
      world.doors.push_back(door);
    }
  }

  void read_obstacles(const Json& value, NavigationWorld& world) const {
    if (!value.is_array()) fail("obstacles", "must be an array of obstacles");
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string path = detail::json_index("obstacles", i);
      const Json& obstacle_json = object_at(value[i], path);
      check_keys(obstacle_json, path, {"name", "center", "size", "angle"});
      Obstacle obstacle;
      obstacle.name = string_at(member(obstacle_json, path, "name"), detail::json_member(path, "name"));
      const std::vector<double> center =
          numbers(member(obstacle_json, path, "center"), detail::json_member(path, "center"), 2, "x, y");
      const std::vector<double> size =
          numbers(member(obstacle_json, path, "size"), detail::json_member(path, "size"), 2, "length, width");
      if (!(size[0] > 0 && size[1] > 0)) fail(detail::json_member(path, "size"), "length and width must be positive");
      const double angle =
          obstacle_json.contains("angle") ? finite(obstacle_json["angle"], detail::json_member(path, "angle")) : 0.0;
      obstacle.shape = Rectangle{center[0], center[1], size[0], size[1], angle};
      if (std::none_of(world.rooms.begin(), world.rooms.end(),
                       [&](const Room& room) { return room.contains(center[0], center[1]); })) {
        fail(detail::json_member(path, "center"), "not inside any room");
      }
      world.obstacles.push_back(obstacle);
    }
  }

  void read_start(const Json& value, NavigationWorld& world) const {
    object_at(value, "start");
    check_keys(value, "start", {"room", "pose"});
    world.start_room = room_id(member(value, "start", "room"), "start.room", world);
    const std::vector<double> pose = numbers(member(value, "start", "pose"), "start.pose", 3, "x, y, theta");
    world.start = Pose{pose[0], pose[1], pose[2]};
    if (!world.room(world.start_room).contains(pose[0], pose[1])) {
      fail("start.pose", "not inside the start room " + world.start_room);
    }
    if (NavigationCollision(world, world.robot.clearance).collides(world.start)) {
      fail("start.pose", "the robot (with its clearance) collides with a wall or furniture there");
    }
  }

  // Through the doors, the goal room must be reachable from the start room: otherwise no room
  // path exists, and every episode would fail before the first motion is planned.
  void check_goal_reachable(const NavigationWorld& world) const {
    std::vector<std::vector<int>> neighbours(world.rooms.size());
    for (const Door& door : world.doors) {
      const int a = world.room_index(door.rooms[0]), b = world.room_index(door.rooms[1]);
      neighbours[static_cast<std::size_t>(a)].push_back(b);
      neighbours[static_cast<std::size_t>(b)].push_back(a);
    }
    std::vector<bool> reached(world.rooms.size(), false);
    std::vector<int> frontier{world.room_index(world.start_room)};
    reached[static_cast<std::size_t>(frontier.front())] = true;
    while (!frontier.empty()) {
      const int room = frontier.back();
      frontier.pop_back();
      for (const int next : neighbours[static_cast<std::size_t>(room)]) {
        if (!reached[static_cast<std::size_t>(next)]) {
          reached[static_cast<std::size_t>(next)] = true;
          frontier.push_back(next);
        }
      }
    }
    if (!reached[static_cast<std::size_t>(world.room_index(world.goal_room))]) {
      fail("goal_room", world.goal_room + " cannot be reached from the start room " + world.start_room);
    }
  }

  void read_skeletons(std::string_view text, NavigationWorld& world) const {
    world.skeletons = parse_skeleton_file(text, source()).skeletons;
    std::set<std::pair<std::string, std::string>> joined;
    for (const Door& door : world.doors) {
      joined.emplace(door.rooms[0], door.rooms[1]);
      joined.emplace(door.rooms[1], door.rooms[0]);
    }
    for (std::size_t k = 0; k < world.skeletons.size(); ++k) {
      std::string at = world.start_room;
      const std::vector<std::string>& skeleton = world.skeletons[k];
      for (std::size_t l = 0; l < skeleton.size(); ++l) {
        const std::string place = detail::json_index(detail::json_index("skeletons", k), l);
        const std::vector<std::string> rooms = move_rooms(skeleton[l]);
        if (rooms.size() != 2 || world.room_index(rooms[0]) < 0 || world.room_index(rooms[1]) < 0) {
          fail(place, "'" + skeleton[l] + "' is not move(FROM,TO) between rooms of this world");
        }
        if (rooms[0] != at) fail(place, "'" + skeleton[l] + "' starts in " + rooms[0] + " but the robot is in " + at);
        if (!joined.contains({rooms[0], rooms[1]})) fail(place, "no door joins " + rooms[0] + " and " + rooms[1]);
        at = rooms[1];
      }
      if (at != world.goal_room) {
        fail(detail::json_index("skeletons", k), "ends in " + at + ", not in the goal room " + world.goal_room);
      }
    }
  }

  // Room edges become walls, merged where rooms share them and cut open at doors.
  static std::vector<Rectangle> build_walls(const NavigationWorld& world) {
    struct Interval {
      double low, high;
      bool low_is_door, high_is_door;
    };
    // (vertical edge?, coordinate across) -> intervals along the edge
    std::map<std::pair<bool, double>, std::vector<Interval>> lines;
    for (const Room& room : world.rooms) {
      lines[{false, room.min_y}].push_back({room.min_x, room.max_x, false, false});
      lines[{false, room.max_y}].push_back({room.min_x, room.max_x, false, false});
      lines[{true, room.min_x}].push_back({room.min_y, room.max_y, false, false});
      lines[{true, room.max_x}].push_back({room.min_y, room.max_y, false, false});
    }
    const double t = world.wall_thickness;
    std::vector<Rectangle> walls;
    for (auto& [line, intervals] : lines) {
      std::sort(intervals.begin(), intervals.end(), [](const Interval& a, const Interval& b) { return a.low < b.low; });
      std::vector<Interval> merged;
      for (const Interval& interval : intervals) {
        if (!merged.empty() && interval.low <= merged.back().high + kTolerance) {
          merged.back().high = std::max(merged.back().high, interval.high);
        } else {
          merged.push_back(interval);
        }
      }
      for (const Door& door : world.doors) {
        if (door.on_vertical_edge != line.first) continue;
        const double across = door.on_vertical_edge ? door.x : door.y;
        if (std::abs(across - line.second) > kTolerance) continue;
        const double along = door.on_vertical_edge ? door.y : door.x;
        const double open_low = along - door.width / 2, open_high = along + door.width / 2;
        std::vector<Interval> cut;
        for (const Interval& interval : merged) {
          if (open_high <= interval.low || open_low >= interval.high) {
            cut.push_back(interval);
            continue;
          }
          if (open_low > interval.low) cut.push_back({interval.low, open_low, interval.low_is_door, true});
          if (open_high < interval.high) cut.push_back({open_high, interval.high, true, interval.high_is_door});
        }
        merged = std::move(cut);
      }
      for (const Interval& interval : merged) {
        // Wall ends away from doors reach over the corner so that corners close.
        const double low = interval.low - (interval.low_is_door ? 0.0 : t / 2);
        const double high = interval.high + (interval.high_is_door ? 0.0 : t / 2);
        if (line.first) {
          walls.push_back(Rectangle{line.second, (low + high) / 2, t, high - low, 0.0});
        } else {
          walls.push_back(Rectangle{(low + high) / 2, line.second, high - low, t, 0.0});
        }
      }
    }
    return walls;
  }
};

}  // namespace

int NavigationWorld::room_index(std::string_view id) const noexcept {
  for (std::size_t i = 0; i < rooms.size(); ++i) {
    if (rooms[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

const Room& NavigationWorld::room(std::string_view id) const {
  const int index = room_index(id);
  if (index < 0) throw std::invalid_argument("unknown room '" + std::string(id) + "'");
  return rooms[static_cast<std::size_t>(index)];
}

std::array<double, 4> NavigationWorld::bounds() const {
  std::array<double, 4> box{rooms.at(0).min_x, rooms.at(0).min_y, rooms.at(0).max_x, rooms.at(0).max_y};
  for (const Room& room : rooms) {
    box = {std::min(box[0], room.min_x), std::min(box[1], room.min_y), std::max(box[2], room.max_x),
           std::max(box[3], room.max_y)};
  }
  const double half = wall_thickness / 2;
  return {box[0] - half, box[1] - half, box[2] + half, box[3] + half};
}

std::vector<std::vector<std::string>> NavigationWorld::room_paths(std::string_view from, std::string_view to) const {
  const std::size_t count = rooms.size();
  std::vector<std::vector<std::size_t>> neighbours(count);
  for (const Door& door : doors) {
    const auto a = static_cast<std::size_t>(room_index(door.rooms[0]));
    const auto b = static_cast<std::size_t>(room_index(door.rooms[1]));
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  const int first = room_index(from), last = room_index(to);
  if (first < 0 || last < 0) throw std::invalid_argument("unknown room");
  std::vector<std::vector<std::string>> paths;
  std::vector<std::size_t> path{static_cast<std::size_t>(first)};
  std::vector<char> visited(count, 0);
  visited[path[0]] = 1;
  const std::function<void()> extend = [&] {
    if (path.back() == static_cast<std::size_t>(last)) {
      std::vector<std::string>& ids = paths.emplace_back();
      for (const std::size_t room : path) ids.push_back(rooms[room].id);
      return;
    }
    for (const std::size_t next : neighbours[path.back()]) {
      if (visited[next] != 0) continue;
      visited[next] = 1;
      path.push_back(next);
      extend();
      path.pop_back();
      visited[next] = 0;
    }
  };
  extend();
  return paths;
}

std::vector<std::string> move_rooms(std::string_view action) {
  static const std::regex pattern(R"(move\(([^(), ]+),([^(), ]+)\)(#[1-9][0-9]*)?)");
  std::cmatch match;
  if (!std::regex_match(action.begin(), action.end(), match, pattern)) return {};
  return {match[1].str(), match[2].str()};
}

NavigationWorld parse_navigation_world(std::string_view text, std::string_view source) {
  return WorldReader(std::string(source)).read(text);
}

NavigationWorld load_navigation_world(const std::filesystem::path& path) {
  return parse_navigation_world(read_input_file(path, "world"), path.string());
}

}  // namespace ontime::domains
