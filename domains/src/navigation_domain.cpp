#include <cmath>
#include <numbers>
#include <set>
#include <stdexcept>
#include <utility>

#include "navigation_refinement.hpp"
#include "ompl_support.hpp"
#include "ontime/domains/library_messages.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/navigation_collision.hpp"
#include "ontime/domains/navigation_features.hpp"
#include "ontime/domains/task_planner.hpp"
#include "ontime/util/random.hpp"

namespace ontime::domains {
namespace {

Pose pose_of(const Configuration& configuration) {
  if (configuration.size() != 3) throw std::invalid_argument("a navigation configuration is (x, y, theta)");
  return Pose{configuration[0], configuration[1], configuration[2]};
}

}  // namespace

NavigationDomain::NavigationDomain(NavigationWorld world) : world_(std::move(world)) { detail::route_ompl_messages(); }

Configuration NavigationDomain::initial_configuration() const {
  return {world_.start.x, world_.start.y, world_.start.theta};
}

std::unique_ptr<Refinement> NavigationDomain::refine(const std::string& action, const Configuration& start,
                                                     std::uint64_t seed, const EffortSettings& effort) const {
  const std::vector<std::string> rooms = move_rooms(action);
  if (rooms.size() != 2 || world_.room_index(rooms[0]) < 0 || world_.room_index(rooms[1]) < 0) {
    throw std::invalid_argument("'" + action + "' is not move(FROM,TO) between rooms of " + world_.name);
  }
  return make_navigation_refinement(*this, world_.room(rooms[0]), world_.room(rooms[1]), pose_of(start), seed, effort);
}

Configuration NavigationDomain::fallback_start(const std::string& action, std::uint64_t seed) const {
  const std::vector<std::string> rooms = move_rooms(action);
  if (rooms.size() != 2 || world_.room_index(rooms[0]) < 0) {
    throw std::invalid_argument("'" + action + "' is not move(FROM,TO) between rooms of " + world_.name);
  }
  const Room& room = world_.room(rooms[0]);
  const NavigationCollision collision(world_, world_.robot.clearance);
  SplitMix64 random(seed);
  const double half = world_.wall_thickness / 2;
  for (int attempt = 0; attempt < 1'000'000; ++attempt) {
    const Pose pose{room.min_x + half + (room.max_x - room.min_x - 2 * half) * uniform01(random),
                    room.min_y + half + (room.max_y - room.min_y - 2 * half) * uniform01(random),
                    std::numbers::pi * (2 * uniform01(random) - 1)};
    if (!collision.collides(pose)) return {pose.x, pose.y, pose.theta};
  }
  throw std::runtime_error("no collision-free pose found in room " + room.id);
}

std::vector<StandaloneAction> NavigationDomain::every_action() const {
  std::vector<StandaloneAction> actions;
  std::set<std::pair<std::string, std::string>> listed;  // two doors between two rooms: one move
  for (const Door& door : world_.doors) {
    for (const auto& [from, to] : {std::pair{door.rooms[0], door.rooms[1]}, std::pair{door.rooms[1], door.rooms[0]}}) {
      if (!listed.emplace(from, to).second) continue;
      actions.push_back(StandaloneAction{"move(" + from + "," + to + ")", from == world_.start_room});
    }
  }
  return actions;
}

const std::vector<std::string>& NavigationDomain::feature_names() const { return navigation_feature_names(); }

std::vector<double> NavigationDomain::action_features(const std::string& action) const {
  return navigation_action_features(world_, action);
}

double NavigationDomain::execution_seconds(const std::vector<Pose>& poses) const {
  return drive_seconds(poses, world_.robot.linear_speed, world_.robot.angular_speed);
}

Scene NavigationDomain::scene() const {
  Scene scene;
  scene.title = world_.name;
  for (const Room& room : world_.rooms) {
    scene.polygons.push_back(ScenePolygon{
        "room",
        room.id,
        {{room.min_x, room.min_y}, {room.max_x, room.min_y}, {room.max_x, room.max_y}, {room.min_x, room.max_y}}});
  }
  for (const Rectangle& wall : world_.walls) {
    const auto corners = wall.corners();
    scene.polygons.push_back(ScenePolygon{"wall", "", {corners.begin(), corners.end()}});
  }
  for (const Obstacle& obstacle : world_.obstacles) {
    const auto corners = obstacle.shape.corners();
    scene.polygons.push_back(ScenePolygon{"obstacle", "", {corners.begin(), corners.end()}});
  }
  scene.polygons.push_back(ScenePolygon{"robot", "", outline(initial_configuration())});
  return scene;
}

std::vector<std::array<double, 2>> NavigationDomain::trace(const std::vector<Configuration>& motion) const {
  std::vector<std::array<double, 2>> points;
  for (const Configuration& configuration : motion) {
    const Pose pose = pose_of(configuration);
    points.push_back({pose.x, pose.y});
  }
  return points;
}

std::vector<std::array<double, 2>> NavigationDomain::outline(const Configuration& configuration) const {
  const Pose pose = pose_of(configuration);
  const auto corners = Rectangle{pose.x, pose.y, world_.robot.length, world_.robot.width, pose.theta}.corners();
  return {corners.begin(), corners.end()};
}

std::vector<std::array<double, 2>> NavigationDomain::skeleton_points(const std::vector<std::string>& skeleton) const {
  return room_path_points(world_, skeleton);
}

TaskPlannerFactory NavigationDomain::task_planners(int max_skeletons) const {
  return room_path_planners(world_, max_skeletons);
}

}  // namespace ontime::domains
