#pragma once
// The interface between a TAMP domain (a world, a robot, a motion planner) and the collection
// pipeline (collection.hpp) that turns it into planner logs and instances.
//
// A domain names its plan skeletons (sequences of abstract actions) and refines one abstract
// action at a time: from a start configuration, with all randomness drawn from a seed, in
// slices of effort that resume the same planner, so that an allocator may interleave actions.
// It also turns itself and its motions into 2D drawing primitives for the map pictures, and
// names the task planner that streams its skeletons in the TAMP loop (tamp.hpp).
//
// A second domain implements the same two classes (Domain, Refinement); nothing else in the
// pipeline knows about rooms, arms or OMPL.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ontime/domains/effort.hpp"

namespace ontime::domains {

// A robot configuration in the domain's own coordinates (navigation: x, y, theta).
using Configuration = std::vector<double>;

// `backtrack`: the attempt gave up because of the motion chosen for the action before it (a
// grasp with which no placement is reachable), SeSamE's rule (docs/spec.md §7): that action is
// to be refined anew, and this one after it, from where its new motion ends.
enum class RefinementStatus { working, found, backtrack };

// One attempt to refine one abstract action.
class Refinement {
 public:
  virtual ~Refinement() = default;

  // Continues the attempt until a motion is found, the attempt gives up (backtrack), or the total
  // effort reaches `limit_seconds` (checked between planner iterations, so it may overshoot by
  // one iteration). Calling it again with a larger limit resumes the same planner where it
  // stopped; once found or given up, it returns at once.
  virtual RefinementStatus advance(double limit_seconds) = 0;

  // Where the attempt stands: working, found or backtrack (given up).
  virtual RefinementStatus status() const = 0;
  // The effort the attempt has spent so far.
  virtual const EffortMeter& effort() const = 0;

  // Once found: the seconds the robot needs to execute the motion, the configuration it ends
  // in, and the motion itself (waypoints, executed in straight segments).
  virtual double execution_seconds() const = 0;
  virtual Configuration final_configuration() const = 0;
  virtual std::vector<Configuration> motion() const = 0;
};

// 2D drawing primitives (metres), drawn by python/plot_map.py.
struct ScenePolygon {
  std::string kind;   // "room", "wall", "obstacle", "region", "object", "robot"
  std::string label;  // drawn when not empty
  std::vector<std::array<double, 2>> points;
  std::string view = "top";  // "top" (x, y seen from above) or "front" (x, z seen from the front)
};

struct Scene {
  std::string title;
  std::vector<ScenePolygon> polygons;
};

// An action of Domain::every_action(), and where a refinement of it may start without an action
// before it: at the domain's initial configuration, or at a start drawn by fallback_start().
struct StandaloneAction {
  std::string action;
  bool from_initial_configuration = false;
};

// A task planner streams plan skeletons: a sequence-before-satisfy TAMP system finds skeletons
// one after another while their actions are being refined (task_planner.hpp has the room-path
// planner of navigation worlds).
class TaskPlanner {
 public:
  virtual ~TaskPlanner() = default;
  // Starts over: the next call to next() returns the first skeleton again.
  virtual void restart() = 0;
  // The next skeleton, as the domain's action ids, or nullopt when there is none left.
  virtual std::optional<std::vector<std::string>> next() = 0;
};

// Makes one task planner per episode runner thread; planners of one factory share their work.
using TaskPlannerFactory = std::function<std::unique_ptr<TaskPlanner>()>;

class Domain {
 public:
  virtual ~Domain() = default;

  // The domain's name: "navigation", "manipulation".
  virtual const std::string& name() const = 0;
  // Plan skeletons, as action ids; actions shared by a common prefix are refined once.
  virtual const std::vector<std::vector<std::string>>& skeletons() const = 0;
  // Where the robot starts, before the first action of every skeleton.
  virtual Configuration initial_configuration() const = 0;

  // Starts refining `action` from `start`; every random choice comes from `seed`.
  // Throws std::invalid_argument for an unknown action or an invalid start.
  virtual std::unique_ptr<Refinement> refine(const std::string& action, const Configuration& start, std::uint64_t seed,
                                             const EffortSettings& effort) const = 0;

  // A start for `action` drawn from `seed` when no refinement of the action before it
  // succeeded (so there is no end configuration to start from).
  virtual Configuration fallback_start(const std::string& action, std::uint64_t seed) const = 0;

  // Every action the domain can refine, each on its own (no skeleton needed), so that a
  // collection of them covers any skeleton a task planner may produce later (navigation: one
  // move per door and direction). Empty when the domain cannot list them (the default).
  virtual std::vector<StandaloneAction> every_action() const;

  // What a conditional time model sees of an action in this world (docs/learning.md,
  // "Features"): a vector of feature_names().size() numbers from the world's geometry alone, the
  // same length for every action and world of the domain. Throws std::invalid_argument for an
  // action the world does not have. A domain without features (the default) has no names and
  // throws std::invalid_argument.
  virtual const std::vector<std::string>& feature_names() const;
  virtual std::vector<double> action_features(const std::string& action) const;

  // The world, and a motion as a polyline of the robot's reference point (seen from above).
  virtual Scene scene() const = 0;
  virtual std::vector<std::array<double, 2>> trace(const std::vector<Configuration>& motion) const = 0;
  // The robot's outline at a configuration.
  virtual std::vector<std::array<double, 2>> outline(const Configuration& configuration) const = 0;
  // A short caption of a skeleton for pictures; by default its action ids.
  virtual std::string describe(const std::vector<std::string>& skeleton) const;
  // A skeleton drawn from above as a polyline (for pictures of a TAMP episode); by default none
  // (empty). Navigation: the room path through the doors' centres.
  virtual std::vector<std::array<double, 2>> skeleton_points(const std::vector<std::string>& skeleton) const;

  // The task planner of the TAMP loop, finding at most `max_skeletons` skeletons (at least 1);
  // the domain must outlive the planners. By default the domain's fixed skeletons in their order;
  // navigation: room paths in order of length.
  virtual TaskPlannerFactory task_planners(int max_skeletons) const;
};

}  // namespace ontime::domains
