#pragma once
// Generated navigation worlds: an office building of rows x cols square rooms, written as a world
// file of the existing format (docs/domains.md), everything drawn from one seed.
//
// Doors: a random spanning tree of the grid of rooms (every room reachable) plus extra doors
// between other neighbours until `door_density` of all neighbour pairs have one, so that many
// room paths of about the same length lead from the start room (bottom left) to the goal room
// (top right, the opposite corner). A share of the doors is narrow (a little wider than the
// robot with its clearance: slow to refine), the others comfortable.
//
// Furniture varies by room: some rooms stay empty, some get a few pieces against the walls,
// some are cluttered with turned boxes. Every room keeps clear a disc around each of its doors,
// a corridor from each door to the room's centre and a disc at the centre, and any two pieces
// of furniture are far enough apart for the robot to pass between them; the generator then
// checks with the collision checker that the robot can drive every door_route, so every door
// is passable and every room can be crossed from any of its doors to any other.
//
// Same options, same seed: the same file, byte for byte.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/navigation_world.hpp"

namespace ontime::domains {

struct BuildingOptions {
  int rows = 6;                    // rooms along y
  int cols = 5;                    // rooms along x
  double room_size = 4.0;          // metres, every room square; at least kMinBuildingRoomSize
  double door_density = 0.8;       // share of neighbour pairs joined by a door (at least a spanning tree)
  double narrow_door_share = 0.2;  // share of doors that are narrow
  // Door widths in metres, drawn uniformly in [min, max]: narrow ones a few centimetres wider
  // than the robot with its clearance (slow to refine), the others comfortable. Every width is
  // above kMinBuildingDoorWidth and at most kMaxBuildingDoorWidth.
  double narrow_width_min = 0.76, narrow_width_max = 0.86;
  double wide_width_min = 1.0, wide_width_max = 1.2;
  // Rooms by furniture: a share left empty, a share cluttered with boxes (min_boxes to max_boxes
  // of them), the rest furnished against the walls. The shares sum to at most 1.
  double empty_room_share = 0.25;
  double cluttered_room_share = 0.35;
  int min_boxes = 4, max_boxes = 7;
  // Skeletons written into the file: the first `skeletons` room paths of the task planner (the
  // shortest simple paths from the start room to the goal room, task_planner.hpp), so that the
  // world has an instance of its own (collect, predict, solve); fewer when the building has fewer.
  // A move reached after other moves than in an earlier path is an action of its own, its id
  // followed by "#2", "#3", ... (as the streaming TAMP loop names it). 0: none, every doorway
  // move is left to collect on its own or to a task planner. At most kMaxBuildingSkeletons.
  int skeletons = 0;
  std::uint64_t seed = 1;
  std::string name;  // default: building-ROWSxCOLS
};

// The clear zones around doors and the centre need this much room (metres).
inline constexpr double kMinBuildingRoomSize = 3.0;
inline constexpr double kMaxBuildingRoomSize = 20.0;
inline constexpr int kMaxBuildingSide = 50;
// A door is wider than the robot's footprint with its clearance (0.708 m) and at most twice the
// margin kept from the ends of its edge (so it fits in the smallest room).
inline constexpr double kMinBuildingDoorWidth = 0.71;
inline constexpr double kMaxBuildingDoorWidth = 2.0;
inline constexpr int kMaxBuildingBoxes = 20;
inline constexpr int kMaxBuildingSkeletons = 64;

// The world file's text. Throws std::invalid_argument for options out of range (rows or cols
// below 1 or above kMaxBuildingSide, a single room, a room size out of range, shares outside
// [0, 1] or room shares summing above 1, door widths out of range or a minimum above its maximum,
// box counts outside 0..kMaxBuildingBoxes or a minimum above the maximum).
std::string generate_navigation_world_text(const BuildingOptions& options);

// The same world, read back with the world file's checker (source: the world's name).
NavigationWorld generate_navigation_world(const BuildingOptions& options);

// What `ontime generate-world` (ontime.domains.generate_world) wrote: the file and what it holds.
struct GeneratedWorld {
  std::string output;
  std::string name;
  std::size_t rooms = 0, doors = 0, furniture = 0;
  std::string start_room, goal_room;
};

// Writes the world file of these options to `output` (atomically: all or nothing) and reads it
// back with the world file's checker. Throws UsageError (not std::invalid_argument) for options
// out of range.
GeneratedWorld write_generated_world(const BuildingOptions& options, const std::filesystem::path& output);

// The route the generator keeps free for `door` and one of its two rooms, `room`: from the door's
// centre straight into the room (facing across the door) to a pose 0.6 m from the wall, a turn on
// the spot there, a straight drive to the room's centre and a turn on the spot there; poses at
// most `spacing` metres (or 0.1 rad) apart. Throws std::invalid_argument when `room` is not one of
// the door's rooms.
std::vector<Pose> door_route(const NavigationWorld& world, const Door& door, std::string_view room,
                             double spacing = 0.05);

}  // namespace ontime::domains
