#include "ontime/domains/manipulation_world.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <regex>
#include <sstream>

#include "ontime/domains/manipulation_collision.hpp"
#include "ontime/model/skeleton_file.hpp"
#include "world_fields.hpp"

namespace ontime::domains {
namespace {

using detail::Json;
using detail::number_text;
constexpr double kTolerance = 1e-9;

bool plain_id(std::string_view id) { return !id.empty() && id.find_first_of("()[], +") == std::string_view::npos; }

class KitchenReader : detail::WorldFields {
 public:
  explicit KitchenReader(std::string source) : WorldFields(std::move(source)) {}

  ManipulationWorld read(std::string_view text) {
    const Json root = detail::parse_json_strict<Json>(text, source());
    if (!root.is_object())
      fail("top level", "a world must be a JSON object (got " + detail::describe_json_type(root) + ")");
    check_keys(root, "",
               {"name", "description", "floor", "walls", "fixed", "regions", "objects", "goal", "robot", "start",
                "planner", "collection", "skeletons"});
    ManipulationWorld world;
    world.source = source();
    world.name =
        root.contains("name") ? string_at(root["name"], "name") : std::filesystem::path(source()).stem().string();
    if (root.contains("description")) world.description = string_at(root["description"], "description");
    read_floor(member(root, "", "floor"), member(root, "", "walls"), world);
    read_robot(member(root, "", "robot"), world);
    read_planner(member(root, "", "planner"), world);
    world.collection = collection(member(root, "", "collection"));
    read_fixed(member(root, "", "fixed"), world);
    read_regions(member(root, "", "regions"), world);
    read_objects(member(root, "", "objects"), world);
    read_goal(member(root, "", "goal"), world);
    read_start(member(root, "", "start"), world);
    read_skeletons(text, world);
    return world;
  }

 private:
  std::array<double, 2> pair(const Json& value, const std::string& path, const char* what) const {
    const std::vector<double> values = numbers(value, path, 2, what);
    return {values[0], values[1]};
  }

  double non_negative(const Json& value, const std::string& path) const {
    const double result = finite(value, path);
    if (result < 0) fail(path, "must be at least 0");
    return result;
  }

  int whole(const Json& value, const std::string& path, int low, int high) const {
    const std::optional<std::int64_t> number = ontime::detail::json_whole_number(value, low, high);
    if (!number) fail(path, "must be a whole number between " + std::to_string(low) + " and " + std::to_string(high));
    return static_cast<int>(*number);
  }

  void read_floor(const Json& floor, const Json& walls, ManipulationWorld& world) const {
    object_at(floor, "floor");
    check_keys(floor, "floor", {"min", "max"});
    const auto low = pair(member(floor, "floor", "min"), "floor.min", "x, y");
    const auto high = pair(member(floor, "floor", "max"), "floor.max", "x, y");
    if (!(high[0] > low[0] && high[1] > low[1])) fail("floor", "'max' must exceed 'min' in x and in y");
    world.floor = {low[0], low[1], high[0], high[1]};
    object_at(walls, "walls");
    check_keys(walls, "walls", {"thickness", "height"});
    world.wall_thickness = positive(member(walls, "walls", "thickness"), "walls.thickness");
    world.wall_height = positive(member(walls, "walls", "height"), "walls.height");
    // Four walls just outside the floor, overlapping at the corners.
    const double t = world.wall_thickness, h = world.wall_height;
    const auto& f = world.floor;
    world.walls = {
        Box3{{f[0] - t, f[1] - t, 0}, {f[0], f[3] + t, h}}, Box3{{f[2], f[1] - t, 0}, {f[2] + t, f[3] + t, h}},
        Box3{{f[0] - t, f[1] - t, 0}, {f[2] + t, f[1], h}}, Box3{{f[0] - t, f[3], 0}, {f[2] + t, f[3] + t, h}}};
  }

  void read_robot(const Json& value, ManipulationWorld& world) const {
    object_at(value, "robot");
    check_keys(value, "robot", {"base", "torso_lift", "arm_speed", "gripper_seconds", "clearance", "carry"});
    ManipulationRobot& robot = world.robot;
    const Json& base = object_at(member(value, "robot", "base"), "robot.base");
    check_keys(base, "robot.base", {"size", "linear_speed", "angular_speed"});
    const std::vector<double> size =
        numbers(member(base, "robot.base", "size"), "robot.base.size", 3, "length, width, height");
    if (!(size[0] > 0 && size[1] > 0 && size[2] > 0)) fail("robot.base.size", "every size must be positive");
    robot.base_size = {size[0], size[1], size[2]};
    robot.linear_speed = positive(member(base, "robot.base", "linear_speed"), "robot.base.linear_speed");
    robot.angular_speed = positive(member(base, "robot.base", "angular_speed"), "robot.base.angular_speed");
    robot.torso_lift = finite(member(value, "robot", "torso_lift"), "robot.torso_lift");
    if (robot.torso_lift < 0 || robot.torso_lift > 0.33)
      fail("robot.torso_lift", "the PR2's torso lifts by 0 to 0.33 m");
    robot.arm_speed = positive(member(value, "robot", "arm_speed"), "robot.arm_speed");
    if (robot.arm_speed > 1) fail("robot.arm_speed", "a fraction of the joint velocity limits, at most 1");
    robot.gripper_seconds = non_negative(member(value, "robot", "gripper_seconds"), "robot.gripper_seconds");
    robot.clearance = non_negative(member(value, "robot", "clearance"), "robot.clearance");
    const std::vector<double> carry =
        numbers(member(value, "robot", "carry"), "robot.carry", kArmJointCount, "arm joints");
    std::copy(carry.begin(), carry.end(), robot.carry.begin());
    for (std::size_t j = 0; j < kArmJointCount; ++j) {
      const ArmJointSpec& joint = pr2_left_arm_joints()[j];
      if (carry[j] < joint.lower || carry[j] > joint.upper) {
        fail(detail::json_index("robot.carry", j), std::string(joint.name) + " must lie within [" +
                                                       number_text(joint.lower) + ", " + number_text(joint.upper) +
                                                       "]");
      }
    }
  }

  void read_planner(const Json& value, ManipulationWorld& world) const {
    object_at(value, "planner");
    check_keys(value, "planner",
               {"arm_range", "arm_resolution", "base_range", "base_resolution", "base_distance", "base_heading_spread",
                "approach_distance", "ik_checks", "target_checks", "placement_gap", "placement_draws"});
    ManipulationPlanner& planner = world.planner;
    planner.arm_range = positive(member(value, "planner", "arm_range"), "planner.arm_range");
    planner.arm_resolution = positive(member(value, "planner", "arm_resolution"), "planner.arm_resolution");
    planner.base_range = positive(member(value, "planner", "base_range"), "planner.base_range");
    planner.base_resolution = positive(member(value, "planner", "base_resolution"), "planner.base_resolution");
    if (planner.base_resolution >= world.wall_thickness) {
      fail("planner.base_resolution", "must be below the wall thickness (" + number_text(world.wall_thickness) +
                                          " m), or a motion could jump through a wall between two checks");
    }
    planner.base_distance =
        pair(member(value, "planner", "base_distance"), "planner.base_distance", "nearest, farthest");
    if (!(planner.base_distance[0] > 0 && planner.base_distance[1] > planner.base_distance[0])) {
      fail("planner.base_distance", "must be two distances with 0 < nearest < farthest");
    }
    planner.base_heading_spread =
        non_negative(member(value, "planner", "base_heading_spread"), "planner.base_heading_spread");
    planner.approach_distance =
        non_negative(member(value, "planner", "approach_distance"), "planner.approach_distance");
    planner.ik_checks = whole(member(value, "planner", "ik_checks"), "planner.ik_checks", 0, 1'000'000);
    planner.target_checks = whole(member(value, "planner", "target_checks"), "planner.target_checks", 1, 1'000'000'000);
    planner.placement_gap = positive(member(value, "planner", "placement_gap"), "planner.placement_gap");
    if (value.contains("placement_draws")) {
      planner.placement_draws = whole(value["placement_draws"], "planner.placement_draws", 0, 1'000'000'000);
    }
  }

  Box3 read_box(const Json& value, const std::string& path, const ManipulationWorld& world) const {
    object_at(value, path);
    check_keys(value, path, {"min", "max"});
    const std::vector<double> low = numbers(member(value, path, "min"), detail::json_member(path, "min"), 3, "x, y, z");
    const std::vector<double> high =
        numbers(member(value, path, "max"), detail::json_member(path, "max"), 3, "x, y, z");
    Box3 box{{low[0], low[1], low[2]}, {high[0], high[1], high[2]}};
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (!(box.max[axis] > box.min[axis])) fail(path, "'max' must exceed 'min' in x, y and z");
    }
    const auto& f = world.floor;
    if (box.min[2] < -kTolerance || box.min[0] < f[0] - kTolerance || box.min[1] < f[1] - kTolerance ||
        box.max[0] > f[2] + kTolerance || box.max[1] > f[3] + kTolerance) {
      fail(path, "must stand within the floor (between the walls, z at least 0)");
    }
    return box;
  }

  void read_fixed(const Json& value, ManipulationWorld& world) const {
    if (!value.is_object() || value.empty())
      fail("fixed", "must be an object mapping furniture names to arrays of boxes");
    for (const auto& [name, boxes] : value.items()) {
      const std::string path = detail::json_member("fixed", name);
      if (name.empty()) fail(path, "furniture names must be non-empty");
      if (!boxes.is_array() || boxes.empty()) fail(path, "must be a non-empty array of boxes");
      FixedObject fixed{name, {}};
      for (std::size_t i = 0; i < boxes.size(); ++i)
        fixed.boxes.push_back(read_box(boxes[i], detail::json_index(path, i), world));
      world.fixed.push_back(std::move(fixed));
    }
  }

  void read_regions(const Json& value, ManipulationWorld& world) const {
    if (!value.is_object() || value.empty()) fail("regions", "must be an object mapping region ids to regions");
    for (const auto& [id, region_json] : value.items()) {
      const std::string path = detail::json_member("regions", id);
      if (!plain_id(id)) fail(path, "region ids must be non-empty, without '(', ')', '[', ']', ',', '+' or spaces");
      object_at(region_json, path);
      check_keys(region_json, path, {"on", "height", "min", "max", "yaw"});
      PlacementRegion region;
      region.id = id;
      region.surface = string_at(member(region_json, path, "on"), detail::json_member(path, "on"));
      const auto fixed = std::find_if(world.fixed.begin(), world.fixed.end(),
                                      [&](const FixedObject& candidate) { return candidate.name == region.surface; });
      if (fixed == world.fixed.end())
        fail(detail::json_member(path, "on"), "unknown furniture '" + region.surface + "'");
      region.height = finite(member(region_json, path, "height"), detail::json_member(path, "height"));
      const auto low = pair(member(region_json, path, "min"), detail::json_member(path, "min"), "x, y");
      const auto high = pair(member(region_json, path, "max"), detail::json_member(path, "max"), "x, y");
      region.min_x = low[0];
      region.min_y = low[1];
      region.max_x = high[0];
      region.max_y = high[1];
      if (!(region.max_x >= region.min_x && region.max_y >= region.min_y)) fail(path, "'max' must not be below 'min'");
      region.yaw_low = -std::numbers::pi;
      region.yaw_high = std::numbers::pi;
      if (region_json.contains("yaw")) {
        const auto yaw = pair(region_json["yaw"], detail::json_member(path, "yaw"), "lowest, highest");
        if (yaw[1] < yaw[0]) fail(detail::json_member(path, "yaw"), "the highest yaw must not be below the lowest");
        region.yaw_low = yaw[0];
        region.yaw_high = yaw[1];
      }
      const bool supported = std::any_of(fixed->boxes.begin(), fixed->boxes.end(), [&](const Box3& box) {
        return std::abs(box.max[2] - region.height) <= kTolerance && box.min[0] <= region.min_x + kTolerance &&
               box.min[1] <= region.min_y + kTolerance && box.max[0] >= region.max_x - kTolerance &&
               box.max[1] >= region.max_y - kTolerance;
      });
      if (!supported) {
        fail(path, "no box of '" + region.surface + "' has its top at height " + number_text(region.height) +
                       " under the whole rectangle");
      }
      world.regions.push_back(region);
    }
  }

  void read_objects(const Json& value, ManipulationWorld& world) const {
    if (!value.is_object() || value.empty()) fail("objects", "must be an object mapping object ids to movable objects");
    // Every grasp must fit: the open fingers and the palm keep their clearance around the object.
    const double widest = 2 * (std::min(kGripperOpening / 2, -kPalmFront) - world.robot.clearance);
    for (const auto& [id, object_json] : value.items()) {
      const std::string path = detail::json_member("objects", id);
      if (!plain_id(id)) fail(path, "object ids must be non-empty, without '(', ')', '[', ']', ',', '+' or spaces");
      if (world.region_index(id) >= 0) fail(path, "an object cannot share its id with a region");
      object_at(object_json, path);
      check_keys(object_json, path, {"size", "on", "pose"});
      MovableObject object;
      object.id = id;
      const std::vector<double> size =
          numbers(member(object_json, path, "size"), detail::json_member(path, "size"), 3, "x, y, z");
      if (!(size[0] > 0 && size[1] > 0 && size[2] > 0))
        fail(detail::json_member(path, "size"), "every size must be positive");
      if (size[0] >= widest || size[1] >= widest) {
        fail(detail::json_member(path, "size"),
             "x and y must be below " + number_text(widest) +
                 " m, or the gripper could not close around the object with its clearance");
      }
      if (size[2] <= 2 * kTopGraspDepth)
        fail(detail::json_member(path, "size"), "z must exceed " + number_text(2 * kTopGraspDepth) + " m");
      object.size = {size[0], size[1], size[2]};
      object.region = string_at(member(object_json, path, "on"), detail::json_member(path, "on"));
      const int region = world.region_index(object.region);
      if (region < 0) fail(detail::json_member(path, "on"), "unknown region '" + object.region + "'");
      const std::vector<double> pose =
          numbers(member(object_json, path, "pose"), detail::json_member(path, "pose"), 3, "x, y, yaw");
      const PlacementRegion& on = world.regions[static_cast<std::size_t>(region)];
      // Objects start on the region's surface (the rectangle is where placements are drawn).
      const FixedObject& surface = *std::find_if(world.fixed.begin(), world.fixed.end(),
                                                 [&](const FixedObject& fixed) { return fixed.name == on.surface; });
      if (std::none_of(surface.boxes.begin(), surface.boxes.end(), [&](const Box3& box) {
            return std::abs(box.max[2] - on.height) <= kTolerance && pose[0] >= box.min[0] && pose[0] <= box.max[0] &&
                   pose[1] >= box.min[1] && pose[1] <= box.max[1];
          })) {
        fail(detail::json_member(path, "pose"), "does not stand on the surface of region " + on.id + " (" + on.surface +
                                                    " at height " + number_text(on.height) + ")");
      }
      world.objects.push_back(object);
      world.objects.back().pose = ObjectPose{pose[0], pose[1], world.resting_z(world.objects.size() - 1, on), pose[2]};
    }
  }

  void read_goal(const Json& value, ManipulationWorld& world) const {
    if (!value.is_object() || value.empty()) fail("goal", "must map objects to the regions they must end in");
    for (const auto& [object, region] : value.items()) {
      const std::string path = detail::json_member("goal", object);
      if (world.object_index(object) < 0) fail(path, "unknown object '" + object + "'");
      const std::string id = string_at(region, path);
      if (world.region_index(id) < 0) fail(path, "unknown region '" + id + "'");
      world.goal.emplace_back(object, id);
    }
  }

  void read_start(const Json& value, ManipulationWorld& world) const {
    object_at(value, "start");
    check_keys(value, "start", {"base"});
    const std::vector<double> base = numbers(member(value, "start", "base"), "start.base", 3, "x, y, theta");
    world.start = Pose{base[0], base[1], base[2]};
    const auto& f = world.floor;
    if (!(base[0] > f[0] && base[0] < f[2] && base[1] > f[1] && base[1] < f[3])) fail("start.base", "not on the floor");
    const Pr2Arm arm(world.robot.torso_lift);
    std::vector<ObjectPose> poses;
    for (const MovableObject& object : world.objects) poses.push_back(object.pose);
    for (std::size_t i = 0; i < world.objects.size(); ++i) {
      const ManipulationCollision alone(world, arm, poses, static_cast<int>(i), Transform::Identity(), 0.0);
      if (alone.held_object_collides(poses[i])) {
        fail(detail::json_member("objects", world.objects[i].id),
             "overlaps a wall, a piece of furniture or another object");
      }
    }
    const ManipulationCollision collision(world, arm, poses, -1, Transform::Identity(), world.robot.clearance);
    if (collision.collides(world.start, world.robot.carry)) {
      fail("start.base", "the robot with its arm at 'robot.carry' (and its clearance) collides there");
    }
  }

  void read_skeletons(std::string_view text, ManipulationWorld& world) const {
    world.skeletons = parse_skeleton_file(text, source()).skeletons;
    for (std::size_t k = 0; k < world.skeletons.size(); ++k) {
      std::vector<std::string> moved;
      std::vector<std::string> where;
      for (const MovableObject& object : world.objects) where.push_back(object.region);
      std::string held;
      const std::vector<std::string>& skeleton = world.skeletons[k];
      for (std::size_t l = 0; l < skeleton.size(); ++l) {
        const std::string place = detail::json_index(detail::json_index("skeletons", k), l);
        const std::optional<ManipulationAction> action = parse_manipulation_action(skeleton[l]);
        if (!action)
          fail(place, "'" + skeleton[l] + "' is neither move+pick(OBJECT)[...] nor move+place(OBJECT,REGION)[...]");
        const int object = world.object_index(action->object);
        if (object < 0) fail(place, "unknown object '" + action->object + "'");
        if (action->context != moved) {
          fail(place, "its context must list the objects moved before it: [" + join(moved) + "], not [" +
                          join(action->context) + "]");
        }
        if (action->kind == ManipulationKind::pick) {
          if (!held.empty()) fail(place, "the hand already holds " + held);
          held = action->object;
        } else {
          if (world.region_index(action->region) < 0) fail(place, "unknown region '" + action->region + "'");
          if (held != action->object)
            fail(place, held.empty() ? "the hand is empty" : "the hand holds " + held + ", not " + action->object);
          held.clear();
          where[static_cast<std::size_t>(object)] = action->region;
          moved.push_back(action->object);
        }
      }
      if (!held.empty()) fail(detail::json_index("skeletons", k), "ends with " + held + " in the hand");
      for (const auto& [object, region] : world.goal) {
        if (where[static_cast<std::size_t>(world.object_index(object))] != region) {
          fail(detail::json_index("skeletons", k), "does not bring " + object + " to " + region);
        }
      }
    }
  }

  static std::string join(const std::vector<std::string>& ids) {
    std::string text;
    for (const std::string& id : ids) text += (text.empty() ? "" : ",") + id;
    return text;
  }
};

}  // namespace

int ManipulationWorld::object_index(std::string_view id) const noexcept {
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

int ManipulationWorld::region_index(std::string_view id) const noexcept {
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (regions[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

std::string ManipulationAction::abstract() const {
  return kind == ManipulationKind::pick ? "move+pick(" + object + ")" : "move+place(" + object + "," + region + ")";
}

std::optional<ManipulationAction> parse_manipulation_action(std::string_view id) {
  static const std::regex pattern(R"(move\+(pick|place)\(([^()\[\], +]+)(?:,([^()\[\], +]+))?\)(?:\[([^\[\]]*)\])?)");
  std::cmatch match;
  if (!std::regex_match(id.begin(), id.end(), match, pattern)) return std::nullopt;
  ManipulationAction action;
  action.kind = match[1].str() == "pick" ? ManipulationKind::pick : ManipulationKind::place;
  action.object = match[2].str();
  if (action.kind == ManipulationKind::pick && match[3].matched) return std::nullopt;
  if (action.kind == ManipulationKind::place) {
    if (!match[3].matched) return std::nullopt;
    action.region = match[3].str();
  }
  if (match[4].matched) {
    std::stringstream list(match[4].str());
    std::string object;
    while (std::getline(list, object, ',')) {
      if (!plain_id(object)) return std::nullopt;
      action.context.push_back(object);
    }
    if (action.context.empty() || match[4].str().back() == ',') return std::nullopt;
  }
  return action;
}

ManipulationWorld parse_manipulation_world(std::string_view text, std::string_view source) {
  return KitchenReader(std::string(source)).read(text);
}

ManipulationWorld load_manipulation_world(const std::filesystem::path& path) {
  return parse_manipulation_world(read_input_file(path, "world"), path.string());
}

}  // namespace ontime::domains
