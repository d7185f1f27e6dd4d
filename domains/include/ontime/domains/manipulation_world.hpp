#pragma once
// The kitchen of the manipulation domain (paper §VII-B, Appendix A) as data: walls, fixed
// furniture (shelf, table, worktop, ...) made of axis-aligned boxes, placement regions on their
// tops, movable boxes B1..Bn on them, a PR2-like mobile manipulator (SE(2) base, torso at a fixed
// lift, 7-joint left arm: pr2_arm.hpp), the settings of planner and collection, and the plan
// skeletons; read from a JSON world file (data/domains/manipulation.json, format in
// docs/domains.md) with every rule checked.
//
// Metres and radians; x, y on the floor, z up. Movable objects stand upright (a pose is x, y,
// z of the centre and a yaw); an object rests `planner.placement_gap` above the surface it
// stands on, so that lifting it does not begin in contact.
//
// Action ids: `move+pick(O)` and `move+place(O,R)`, each followed by `[O1,O2,...]` when objects
// were moved (picked and placed) before it in its skeleton, in that order: an abstract action
// after a different prefix is a different refinement problem and gets its own id, e.g.
// `move+pick(B1)` and `move+pick(B1)[B3,B4]` (B1 picked after B3 and B4 were cleared away).

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/pr2_arm.hpp"
#include "ontime/domains/world_types.hpp"

namespace ontime::domains {

struct Box3 {
  std::array<double, 3> min{}, max{};
};

// A piece of furniture: boxes that never move.
struct FixedObject {
  std::string name;
  std::vector<Box3> boxes;
};

// Where objects may be placed: a rectangle (of object centres) on top of a fixed object. Objects
// that start "on" a region stand on its surface, not necessarily within its rectangle.
struct PlacementRegion {
  std::string id;       // e.g. C1, R1
  std::string surface;  // the fixed object it lies on
  double height = 0;    // the top of the surface
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  double yaw_low = 0, yaw_high = 0;  // placements are drawn with a yaw in [low, high]
  // Whether (x, y) lies in the rectangle, its edges included.
  bool contains(double x, double y) const noexcept { return x >= min_x && x <= max_x && y >= min_y && y <= max_y; }
};

struct ObjectPose {
  double x = 0, y = 0, z = 0, yaw = 0;
  bool operator==(const ObjectPose&) const = default;
};

struct MovableObject {
  std::string id;
  std::array<double, 3> size{};  // along its own x, y and z
  std::string region;            // the region whose surface it starts on
  ObjectPose pose;               // where it starts
};

struct ManipulationRobot {
  std::array<double, 3> base_size{};  // footprint length, width, and height of the base box
  double linear_speed = 0;            // m/s of the base
  double angular_speed = 0;           // rad/s of the base, turning on the spot
  double torso_lift = 0;              // m, fixed
  double arm_speed = 0;               // fraction of the PR2's joint velocity limits used
  double gripper_seconds = 0;         // closing or opening the gripper
  double clearance = 0;               // padding kept around the robot while planning
  ArmJoints carry{};                  // the arm while the base drives
};

struct ManipulationPlanner {
  double arm_range = 0;                   // RRT-Connect's longest extension in joint space (rad)
  double arm_resolution = 0;              // joint-space distance between collision checks (rad)
  double base_range = 0;                  // as navigation's: SE(2) state-space distance
  double base_resolution = 0;             // metres of SE(2) state-space distance between checks
  std::array<double, 2> base_distance{};  // base positions are drawn this far from the target (m)
  double base_heading_spread = 0;         // base heading: facing the target, +- this (rad)
  double approach_distance = 0;           // the gripper's last stretch to a grasp or placement, along its axis (m)
  int ik_checks = 0;                      // effort of one IK solve, in collision checks
  int target_checks = 0;                  // effort spent on one target before drawing another
  double placement_gap = 0;               // objects rest this far above their surface (m)
  // Backtracking (docs/spec.md §7): a place gives up and blames the pick before it after this
  // many placements in a row that the arm cannot reach with the grasp it holds (IK, collisions
  // at the placement and along the approach); 0 (the default): it never gives up.
  int placement_draws = 0;
};

struct ManipulationWorld {
  std::string source;
  std::string name, description;
  std::array<double, 4> floor{};  // min x, min y, max x, max y (inside the walls)
  double wall_thickness = 0;
  double wall_height = 0;
  std::vector<Box3> walls;  // derived from the floor
  std::vector<FixedObject> fixed;
  std::vector<PlacementRegion> regions;
  std::vector<MovableObject> objects;
  std::vector<std::pair<std::string, std::string>> goal;  // object -> region
  ManipulationRobot robot;
  Pose start;  // the base; the arm starts at `robot.carry`
  ManipulationPlanner planner;
  CollectionDefaults collection;
  std::vector<std::vector<std::string>> skeletons;

  // The index of the movable object with this id, or -1.
  int object_index(std::string_view id) const noexcept;
  // The index of the placement region with this id, or -1.
  int region_index(std::string_view id) const noexcept;
  // The resting height of an object's centre on a region.
  double resting_z(std::size_t object, const PlacementRegion& region) const noexcept {
    return region.height + planner.placement_gap + objects[object].size[2] / 2;
  }
};

enum class ManipulationKind { pick, place };

// A parsed action id.
struct ManipulationAction {
  ManipulationKind kind = ManipulationKind::pick;
  std::string object;
  std::string region;                // place only
  std::vector<std::string> context;  // objects moved before, in order
  std::string abstract() const;      // the id without its context, e.g. move+place(B1,R1)
};

// Parses `move+pick(O)[...]` or `move+place(O,R)[...]`; nullopt for another form.
std::optional<ManipulationAction> parse_manipulation_action(std::string_view id);

// Reads and checks a world file. Throws ontime::InputError naming the file, the JSON path and
// the rule broken.
ManipulationWorld load_manipulation_world(const std::filesystem::path& path);
ManipulationWorld parse_manipulation_world(std::string_view text, std::string_view source);

}  // namespace ontime::domains
