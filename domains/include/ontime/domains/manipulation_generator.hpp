#pragma once
// Generated kitchens: table scenes for the manipulation domain, written as a world file of the
// kitchen's format (docs/domains.md), everything drawn from one seed, with the goal and the
// skeletons the domain's task planner streams.
//
// The room, the robot, the planner and the collection settings are the paper kitchen's
// (data/domains/manipulation.json). `tables` tables of 1.4 m x 0.7 m stand along the back wall,
// their tops 0.70-0.80 m high; `regions` placement rectangles lie on them (handed to the tables
// round in a random order: every table gets one before any gets two). Objects are cups, boxes and
// bottles (upright boxes whose sizes are drawn within their class's ranges,
// kitchen_object_classes()) standing on the tables that hold a region, at most 45 cm deep: the
// first `targets` are the goal's, each to a region drawn among all; each target gets
// `min_clutter`..`max_clutter` neighbours beside or in front of it, their circumscribed circles
// 3-8 cm from the target's (so closer than kManipulationNeighbourRadius), and closer than that to
// no other target (a target whose neighbours find no room is drawn again); the other objects stand
// anywhere else on those tables, farther than that from every target. No object stands within
// 7 cm of a region's rectangle.
//
// Skeletons: for each target in turn, clear its k nearest neighbours first (each to the region
// nearest to it other than the target's goal), k from 0 to its neighbour count, then bring the
// target to its goal: the product of (neighbours + 1) over the targets, at most 64 skeletons.
//
// Checked feasible before it is written: objects on their table tops with 2 cm to spare, at
// least 2 cm apart and clear of the regions (by construction, then by the world file's checker);
// every object within reach (a base pose on the free floor, and KDL IK for one of its grasps and
// for the approach 10 cm back, the arm clear of walls and furniture); every region with room for
// all the objects the skeletons may place there at once (a grid of their circumscribed circles)
// and reachable with each of them in the hand. A draw that breaks a rule is dropped and the whole
// scene drawn again from the next stream of the seed, at most kKitchenAttempts times; then
// UsageError names the last rule broken. Cost: a reachable object needs about 150 draws of a
// base pose (the median; a few thousand at worst), most of them rejected before their IK solve:
// 0.03-0.2 s a scene.
//
// Same options, same seed: the same file, byte for byte.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ontime/domains/manipulation_world.hpp"
#include "ontime/util/memory.hpp"

namespace ontime::domains {

struct KitchenOptions {
  int tables = 2;                                            // along the back wall
  int regions = 3;                                           // placement regions on the tables
  double region_min = 0.2, region_max = 0.35;                // sides of a region's rectangle (m)
  int targets = 2;                                           // objects the goal moves
  int min_objects = 6, max_objects = 9;                      // all objects, targets included
  int min_clutter = 1, max_clutter = 2;                      // neighbours close to each target
  std::vector<std::string> classes{"cup", "box", "bottle"};  // drawn uniformly
  std::string name;                                          // default: kitchen
};

inline constexpr int kMaxKitchenTables = 3;
inline constexpr int kMaxKitchenRegions = 6;
inline constexpr int kMaxKitchenTargets = 3;
inline constexpr int kMaxKitchenObjects = 16;
inline constexpr int kMaxKitchenClutter = 3;
inline constexpr double kMinKitchenRegionSide = 0.1, kMaxKitchenRegionSide = 0.35;
inline constexpr int kKitchenAttempts = 50;

// An object class: its footprint sides (the same for both when `square`) and height, in metres.
struct KitchenObjectClass {
  std::string_view name;
  double side_min, side_max;
  bool square;
  double height_min, height_max;
};

// cup (square, 5.5-6.5 cm, 8-12 cm high), box (4-6.5 cm by 4-6.5 cm, 10-20 cm high), bottle
// (square, 5-6.5 cm, 20-28 cm high): all fit the open gripper.
const std::vector<KitchenObjectClass>& kitchen_object_classes();

// Throws UsageError naming the option broken, as `spelling` writes it (the command line's
// --min-objects, Python's min_objects; null: parameter 'min-objects'): counts or sides out of
// range, a minimum above its maximum, fewer objects than the targets and their neighbours
// (min_objects < targets x (1 + max_clutter)), an unknown or repeated class, no class.
void check_kitchen_options(const KitchenOptions& options, const ParameterSpelling& spelling = nullptr);

// The world file's text. Throws UsageError for bad options (check_kitchen_options) and when no
// feasible scene was drawn in kKitchenAttempts.
std::string generate_kitchen_text(const KitchenOptions& options, std::uint64_t seed,
                                  const ParameterSpelling& spelling = nullptr);

// The same world, read back with the world file's checker (source: the world's name).
ManipulationWorld generate_kitchen(const KitchenOptions& options, std::uint64_t seed);

// What `ontime generate-world --domain manipulation` (ontime.domains.generate_world) wrote.
struct GeneratedKitchen {
  std::string output;
  std::string name;
  std::size_t tables = 0, regions = 0, objects = 0, skeletons = 0, actions = 0;
  std::vector<std::pair<std::string, std::string>> goal;  // object -> region
};

// Writes the world file to `output` (atomically) and reads it back with the world file's checker.
GeneratedKitchen write_generated_kitchen(const KitchenOptions& options, std::uint64_t seed,
                                         const std::filesystem::path& output,
                                         const ParameterSpelling& spelling = nullptr);

}  // namespace ontime::domains
