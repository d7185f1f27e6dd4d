#pragma once
// The office floor of the navigation domain (paper §VII-A) as data: rooms, doors, walls,
// furniture, the robot and the settings of planner and collection, read from a JSON world
// file (data/domains/navigation.json, format in docs/domains.md) with every rule checked.
//
// Geometry is planar, in metres and radians. Rooms are axis-aligned rectangles; every room
// edge is a wall of `wall_thickness` centred on the edge, except where a door opens it. A door
// joins two rooms whose edges touch; it is an opening of `width` centred on `center`, which lies
// on the shared edge. Furniture are rotated rectangles. The robot is a rectangular base
// (PR2-sized) that moves in SE(2).

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/world_types.hpp"

namespace ontime::domains {

struct Room {
  std::string id;
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  // Whether (x, y) lies strictly inside the room (its walls excluded).
  bool contains(double x, double y) const noexcept { return x > min_x && x < max_x && y > min_y && y < max_y; }
};

struct Door {
  std::array<std::string, 2> rooms;
  double x = 0, y = 0;            // centre, on the shared edge
  double width = 0;               // clear opening
  bool on_vertical_edge = false;  // the shared edge runs along y (rooms side by side in x)
};

struct Obstacle {
  std::string name;
  Rectangle shape;
};

struct RobotModel {
  double length = 0, width = 0;  // footprint, along and across its heading
  double clearance = 0;          // padding kept from walls and furniture while planning
  double linear_speed = 0;       // m/s, along the path
  double angular_speed = 0;      // rad/s, turning on the spot
};

struct PlannerSettings {
  double range = 0;       // RRT-Connect's longest extension, in state-space distance
  double resolution = 0;  // distance between collision checks along a motion, in metres
};

struct NavigationWorld {
  std::string source;  // the file it was read from
  std::string name, description;
  double wall_thickness = 0;
  std::vector<Room> rooms;
  std::vector<Door> doors;
  std::vector<Obstacle> obstacles;
  std::vector<Rectangle> walls;  // derived from rooms and doors
  std::string start_room, goal_room;
  Pose start;
  RobotModel robot;
  PlannerSettings planner;
  CollectionDefaults collection;
  std::vector<std::vector<std::string>> skeletons;  // move(Ri,Rj) action ids; none when the file has none

  // Index of the room with this id, or -1.
  int room_index(std::string_view id) const noexcept;
  const Room& room(std::string_view id) const;
  // The smallest rectangle holding every room (and its walls).
  std::array<double, 4> bounds() const;
  // Every path from one room to another through doors that visits no room twice, as room ids,
  // in lexicographic order of room indices along the path.
  std::vector<std::vector<std::string>> room_paths(std::string_view from, std::string_view to) const;
};

// "move(R1,R5)" -> {"R1", "R5"}; an empty result when the id has another form. A suffix "#n"
// (n >= 1), "move(R1,R5)#2", names the same move as a node of its own in a skeletons' prefix
// tree (reached after other moves, see navigation_generator.hpp): the same rooms.
std::vector<std::string> move_rooms(std::string_view action);

// Reads and checks a world file. Throws ontime::InputError naming the file, the JSON path
// (e.g. `doors[3].width`) and the rule broken.
NavigationWorld load_navigation_world(const std::filesystem::path& path);
NavigationWorld parse_navigation_world(std::string_view text, std::string_view source);

}  // namespace ontime::domains
