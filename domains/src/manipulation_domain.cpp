#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "manipulation_refinement.hpp"
#include "ompl_support.hpp"
#include "ontime/domains/library_messages.hpp"
#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/manipulation_collision.hpp"
#include "ontime/domains/manipulation_features.hpp"
#include "ontime/domains/world_types.hpp"
#include "ontime/util/random.hpp"

namespace ontime::domains {
namespace {

constexpr std::size_t kRobotValues = 3 + kArmJointCount + 1;  // base, arm, held
constexpr std::size_t kObjectValues = 4;                      // x, y, z, yaw

ManipulationAction action_of(const std::string& id, const ManipulationWorld& world) {
  const std::optional<ManipulationAction> action = parse_manipulation_action(id);
  if (!action || world.object_index(action->object) < 0 ||
      (action->kind == ManipulationKind::place && world.region_index(action->region) < 0)) {
    throw std::invalid_argument("'" + id + "' is not move+pick(OBJECT) or move+place(OBJECT,REGION) of " + world.name);
  }
  return *action;
}

std::vector<std::array<double, 2>> rectangle(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

// The outline, seen from above, of a box of `length` x `width` centred at (x, y), turned by `yaw`.
std::vector<std::array<double, 2>> turned_rectangle(double x, double y, double length, double width, double yaw) {
  const auto corners = Rectangle{x, y, length, width, yaw}.corners();
  return {corners.begin(), corners.end()};
}

// A thick segment from a to b seen from the front (x, z), for the arm's links.
std::vector<std::array<double, 2>> bar(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double width) {
  Eigen::Vector2d along(b.x() - a.x(), b.z() - a.z());
  if (along.norm() < 1e-9) along = Eigen::Vector2d(1, 0);
  const Eigen::Vector2d side = Eigen::Vector2d(-along.y(), along.x()).normalized() * (width / 2);
  return {{a.x() + side.x(), a.z() + side.y()},
          {b.x() + side.x(), b.z() + side.y()},
          {b.x() - side.x(), b.z() - side.y()},
          {a.x() - side.x(), a.z() - side.y()}};
}

}  // namespace

ManipulationDomain::ManipulationDomain(ManipulationWorld world) : world_(std::move(world)) {
  detail::route_ompl_messages();
}

KitchenState ManipulationDomain::state(const Configuration& configuration) const {
  if (configuration.size() != kRobotValues + kObjectValues * world_.objects.size()) {
    throw std::invalid_argument("a manipulation configuration holds " +
                                std::to_string(kRobotValues + kObjectValues * world_.objects.size()) + " values");
  }
  KitchenState state;
  state.base = Pose{configuration[0], configuration[1], configuration[2]};
  std::copy_n(configuration.begin() + 3, kArmJointCount, state.arm.begin());
  const double held = configuration[kRobotValues - 1];
  if (held != std::floor(held) || held < -1 || held >= static_cast<double>(world_.objects.size())) {
    throw std::invalid_argument("the held object of a manipulation configuration is an object index or -1");
  }
  state.held = static_cast<int>(held);
  for (std::size_t i = 0; i < world_.objects.size(); ++i) {
    const auto at = configuration.begin() + static_cast<std::ptrdiff_t>(kRobotValues + kObjectValues * i);
    state.objects.push_back(ObjectPose{at[0], at[1], at[2], at[3]});
  }
  return state;
}

Configuration ManipulationDomain::configuration(const KitchenState& state) {
  Configuration values{state.base.x, state.base.y, state.base.theta};
  values.insert(values.end(), state.arm.begin(), state.arm.end());
  values.push_back(static_cast<double>(state.held));
  for (const ObjectPose& pose : state.objects) values.insert(values.end(), {pose.x, pose.y, pose.z, pose.yaw});
  return values;
}

Configuration ManipulationDomain::initial_configuration() const {
  KitchenState state;
  state.base = world_.start;
  state.arm = world_.robot.carry;
  for (const MovableObject& object : world_.objects) state.objects.push_back(object.pose);
  return configuration(state);
}

std::unique_ptr<Refinement> ManipulationDomain::refine(const std::string& action, const Configuration& start,
                                                       std::uint64_t seed, const EffortSettings& effort) const {
  return make_manipulation_refinement(*this, action_of(action, world_), state(start), seed, effort);
}

Configuration ManipulationDomain::fallback_start(const std::string& action, std::uint64_t seed) const {
  const ManipulationAction parsed = action_of(action, world_);
  std::vector<std::string> prefix;
  for (const auto& skeleton : world_.skeletons) {
    const auto found = std::find(skeleton.begin(), skeleton.end(), action);
    if (found != skeleton.end()) {
      prefix.assign(skeleton.begin(), found);
      break;
    }
  }
  SplitMix64 random(seed);
  const auto uniform = [&random](double low, double high) { return low + (high - low) * uniform01(random); };
  const Pr2Arm arm(world_.robot.torso_lift);
  KitchenState state = this->state(initial_configuration());
  // Objects that the prefix moved stand somewhere in their regions.
  for (const std::string& id : prefix) {
    const ManipulationAction before = action_of(id, world_);
    if (before.kind != ManipulationKind::place) continue;
    const auto object = static_cast<std::size_t>(world_.object_index(before.object));
    const PlacementRegion& region = world_.regions[static_cast<std::size_t>(world_.region_index(before.region))];
    const ManipulationCollision collision(world_, arm, state.objects, static_cast<int>(object), Transform::Identity(),
                                          0.0);
    for (int attempt = 0;; ++attempt) {
      if (attempt == 100'000) throw std::runtime_error("no free placement found in region " + region.id);
      const ObjectPose pose{uniform(region.min_x, region.max_x), uniform(region.min_y, region.max_y),
                            world_.resting_z(object, region), uniform(region.yaw_low, region.yaw_high)};
      if (!collision.held_object_collides(pose)) {
        state.objects[object] = pose;
        break;
      }
    }
  }
  Transform grasp = Transform::Identity();  // object in the tool frame
  const auto tool = [&](const Pose& base) { return base_transform(base) * arm.torso() * arm.tool(state.arm); };
  const auto upright = [](const Transform& object) {
    const Eigen::Vector3d x = object.linear().col(0);
    return ObjectPose{object.translation().x(), object.translation().y(), object.translation().z(),
                      std::atan2(x.y(), x.x())};
  };
  if (parsed.kind == ManipulationKind::place) {
    // The grasp that holds the object most nearly upright with the arm carried; the object is
    // then stood exactly upright, and the grasp follows from that pose (as a refinement sees it).
    state.held = world_.object_index(parsed.object);
    const auto held = static_cast<std::size_t>(state.held);
    double best = -2;
    for (const Transform& candidate : box_grasps(world_.objects[held].size)) {
      const double up = (tool(state.base) * candidate.inverse()).linear().col(2).z();
      if (up > best) {
        best = up;
        grasp = candidate.inverse();
      }
    }
    grasp = tool(state.base).inverse() * object_transform(upright(tool(state.base) * grasp));
  }
  const ManipulationCollision collision(world_, arm, state.objects, state.held, grasp, world_.robot.clearance);
  const auto& floor = world_.floor;
  for (int attempt = 0;; ++attempt) {
    if (attempt == 100'000) throw std::runtime_error("no free base pose found on the floor");
    if (!collision.collides(state.base, state.arm)) break;
    state.base =
        Pose{uniform(floor[0], floor[2]), uniform(floor[1], floor[3]), uniform(-std::numbers::pi, std::numbers::pi)};
  }
  if (state.held >= 0) state.objects[static_cast<std::size_t>(state.held)] = upright(tool(state.base) * grasp);
  return configuration(state);
}

double ManipulationDomain::arm_seconds(const std::vector<ArmJoints>& path) const {
  double seconds = 0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    double slowest = 0;
    for (std::size_t j = 0; j < kArmJointCount; ++j) {
      const double speed = world_.robot.arm_speed * pr2_left_arm_joints()[j].velocity;
      slowest = std::max(slowest, std::abs(joint_difference(j, path[i - 1][j], path[i][j])) / speed);
    }
    seconds += slowest;
  }
  return seconds;
}

double ManipulationDomain::drive_seconds(const std::vector<Pose>& path) const {
  return domains::drive_seconds(path, world_.robot.linear_speed, world_.robot.angular_speed);
}

Scene ManipulationDomain::scene() const {
  Scene scene;
  scene.title = world_.name;
  const auto& f = world_.floor;
  scene.polygons.push_back(ScenePolygon{"room", "", rectangle(f[0], f[1], f[2], f[3]), "top"});
  for (const Box3& wall : world_.walls) {
    scene.polygons.push_back(
        ScenePolygon{"wall", "", rectangle(wall.min[0], wall.min[1], wall.max[0], wall.max[1]), "top"});
  }
  // Seen from the front: the floor up to the walls' height, and the back wall's extent.
  scene.polygons.push_back(ScenePolygon{"room", "", rectangle(f[0], 0, f[2], world_.wall_height), "front"});
  for (const FixedObject& fixed : world_.fixed) {
    Box3 extent = fixed.boxes.front();
    for (const Box3& box : fixed.boxes) {
      for (std::size_t axis = 0; axis < 3; ++axis) {
        extent.min[axis] = std::min(extent.min[axis], box.min[axis]);
        extent.max[axis] = std::max(extent.max[axis], box.max[axis]);
      }
      scene.polygons.push_back(
          ScenePolygon{"obstacle", "", rectangle(box.min[0], box.min[1], box.max[0], box.max[1]), "top"});
      scene.polygons.push_back(
          ScenePolygon{"obstacle", "", rectangle(box.min[0], box.min[2], box.max[0], box.max[2]), "front"});
    }
    // The name, once per piece of furniture, just beneath it in the front view.
    scene.polygons.push_back(
        ScenePolygon{"caption", fixed.name,
                     rectangle(extent.min[0], extent.min[2] - 0.12, extent.max[0], extent.min[2] - 0.02), "front"});
  }
  for (const PlacementRegion& region : world_.regions) {
    scene.polygons.push_back(
        ScenePolygon{"region", region.id, rectangle(region.min_x, region.min_y, region.max_x, region.max_y), "top"});
    scene.polygons.push_back(ScenePolygon{
        "region", region.id, rectangle(region.min_x, region.height, region.max_x, region.height + 0.012), "front"});
  }
  for (const MovableObject& object : world_.objects) {
    const ObjectPose& pose = object.pose;
    scene.polygons.push_back(ScenePolygon{
        "object", object.id, turned_rectangle(pose.x, pose.y, object.size[0], object.size[1], pose.yaw), "top"});
    const double half =
        (std::abs(std::cos(pose.yaw)) * object.size[0] + std::abs(std::sin(pose.yaw)) * object.size[1]) / 2;
    scene.polygons.push_back(ScenePolygon{
        "object", object.id,
        rectangle(pose.x - half, pose.z - object.size[2] / 2, pose.x + half, pose.z + object.size[2] / 2), "front"});
  }
  const KitchenState start = state(initial_configuration());
  scene.polygons.push_back(ScenePolygon{"robot", "", outline(initial_configuration()), "top"});
  const Pr2Arm arm(world_.robot.torso_lift);
  const Transform torso = base_transform(start.base) * arm.torso();
  const auto& size = world_.robot.base_size;
  const double reach =
      (std::abs(std::cos(start.base.theta)) * size[0] + std::abs(std::sin(start.base.theta)) * size[1]) / 2;
  scene.polygons.push_back(
      ScenePolygon{"robot", "", rectangle(start.base.x - reach, 0, start.base.x + reach, size[2]), "front"});
  const ArmFrames frames = arm.frames(start.arm);
  const Eigen::Vector3d shoulder = torso * frames[1].translation(), elbow = torso * frames[3].translation();
  const Eigen::Vector3d wrist = torso * frames[5].translation(), tool = torso * frames[kArmJointCount].translation();
  scene.polygons.push_back(ScenePolygon{"robot", "", bar(shoulder, elbow, 0.13), "front"});
  scene.polygons.push_back(ScenePolygon{"robot", "", bar(elbow, wrist, 0.10), "front"});
  scene.polygons.push_back(ScenePolygon{"robot", "", bar(wrist, tool, 0.08), "front"});
  return scene;
}

std::vector<std::array<double, 2>> ManipulationDomain::trace(const std::vector<Configuration>& motion) const {
  std::vector<std::array<double, 2>> points;
  for (const Configuration& configuration : motion) {
    if (configuration.size() < 2)
      throw std::invalid_argument("a manipulation configuration starts with the base's x, y");
    if (!points.empty() && points.back()[0] == configuration[0] && points.back()[1] == configuration[1]) continue;
    points.push_back({configuration[0], configuration[1]});
  }
  return points;
}

std::vector<std::array<double, 2>> ManipulationDomain::outline(const Configuration& configuration) const {
  const KitchenState at = state(configuration);
  return turned_rectangle(at.base.x, at.base.y, world_.robot.base_size[0], world_.robot.base_size[1], at.base.theta);
}

const std::vector<std::string>& ManipulationDomain::feature_names() const { return manipulation_feature_names(); }

std::vector<double> ManipulationDomain::action_features(const std::string& action) const {
  return manipulation_action_features(world_, action);
}

std::string ManipulationDomain::describe(const std::vector<std::string>& skeleton) const {
  std::string text;
  for (const std::string& id : skeleton) {
    const std::optional<ManipulationAction> action = parse_manipulation_action(id);
    if (!action || action->kind != ManipulationKind::place) continue;
    text += (text.empty() ? "" : ", ") + action->object + "→" + action->region;
  }
  return text;
}

}  // namespace ontime::domains
