#include "manipulation_refinement.hpp"

#include <ompl/base/ScopedState.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SE2StateSpace.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "ompl_support.hpp"
#include "ontime/domains/manipulation_collision.hpp"
#include "ontime/util/random.hpp"
#include "phased_refinement.hpp"

namespace ontime::domains {
namespace {

namespace ob = ompl::base;
using std::numbers::pi;

ArmJoints joints_of(const ob::State* state) {
  const auto* values = state->as<ob::RealVectorStateSpace::StateType>();
  ArmJoints joints{};
  for (std::size_t j = 0; j < kArmJointCount; ++j) joints[j] = values->values[j];
  return joints;
}

void set_joints(ob::State* state, const ArmJoints& joints) {
  auto* values = state->as<ob::RealVectorStateSpace::StateType>();
  for (std::size_t j = 0; j < kArmJointCount; ++j) values->values[j] = joints[j];
}

using detail::se2_pose;
using detail::set_se2_pose;

// The arm's joint space: a box of joint limits in which the continuous joints wrap around
// (distance and interpolation take the short way, pr2_arm.hpp), so that a path never turns a
// wrist or forearm the long way round.
class ArmJointSpace final : public ob::RealVectorStateSpace {
 public:
  ArmJointSpace() : ob::RealVectorStateSpace(kArmJointCount) {
    ob::RealVectorBounds limits(kArmJointCount);
    for (std::size_t j = 0; j < kArmJointCount; ++j) {
      limits.setLow(static_cast<unsigned>(j), pr2_left_arm_joints()[j].lower);
      limits.setHigh(static_cast<unsigned>(j), pr2_left_arm_joints()[j].upper);
    }
    setBounds(limits);
  }

  double distance(const ob::State* a, const ob::State* b) const override {
    return joint_distance(joints_of(a), joints_of(b));
  }

  void interpolate(const ob::State* from, const ob::State* to, double t, ob::State* state) const override {
    set_joints(state, interpolate_joints(joints_of(from), joints_of(to), t));
  }

  double getMaximumExtent() const override {
    double sum = 0;
    for (const ArmJointSpec& joint : pr2_left_arm_joints()) {
      sum += joint.continuous ? pi * pi : std::pow(joint.upper - joint.lower, 2);
    }
    return std::sqrt(sum);
  }
};

// A path being shortened: its waypoints, the space its motions are checked in, the shortcut.
template <class Waypoint>
struct Leg {
  ob::SpaceInformationPtr information;
  std::vector<Waypoint> waypoints;
  detail::GreedyShortcut shortcut;
  std::vector<Waypoint> shortened;
};

class ManipulationRefinement final : public detail::PhasedRefinement {
 public:
  ManipulationRefinement(const ManipulationDomain& domain, const ManipulationAction& action, const KitchenState& start,
                         std::uint64_t seed, const EffortSettings& effort)
      : PhasedRefinement(effort),
        domain_(domain),
        world_(domain.world()),
        action_(action),
        object_(static_cast<std::size_t>(world_.object_index(action.object))),
        start_(start),
        seed_(seed),
        random_(stream_seed(seed, 0)),
        arm_(world_.robot.torso_lift) {
    if (world_.object_index(action.object) < 0) throw std::invalid_argument("unknown object " + action.object);
    if (action.kind == ManipulationKind::pick && start.held >= 0) {
      throw std::invalid_argument("cannot pick " + action.object + " while holding " + world_.objects[start.held].id);
    }
    if (action.kind == ManipulationKind::place) {
      if (start.held != static_cast<int>(object_))
        throw std::invalid_argument("cannot place " + action.object + " without holding it");
      const int region = world_.region_index(action.region);
      if (region < 0) throw std::invalid_argument("unknown region " + action.region);
      region_ = &world_.regions[static_cast<std::size_t>(region)];
    }
    if (start.held >= 0) {
      // The grasp (tool frame -> object) follows from the arm and the object's pose at pick-up.
      grasp_ = tool_in_world(start.base, start.arm).inverse() *
               object_transform(start.objects[static_cast<std::size_t>(start.held)]);
    }
    const double clearance = world_.robot.clearance;
    collision_ = std::make_unique<ManipulationCollision>(world_, arm_, start.objects, start.held, grasp_, clearance);
    // The world once the action is done, for the configuration the next action starts from.
    after_ = std::make_unique<ManipulationCollision>(
        world_, arm_, start.objects, action.kind == ManipulationKind::pick ? static_cast<int>(object_) : -1,
        Transform::Identity(), clearance);
    if (collision_->collides(start.base, start.arm))
      throw std::invalid_argument("the start configuration is in collision");
    grasps_ = box_grasps(world_.objects[object_].size);
    if (start.arm != world_.robot.carry) phase_ = Phase::retreat;
  }

  void work(double limit_seconds) override {
    switch (phase_) {
      case Phase::retreat:
        retreat();
        break;
      case Phase::retract:
        if (planner_->run(meter_, [this, limit_seconds] { return meter_.reached(limit_seconds); })) {
          if (retreated_) retract_.waypoints.push_back(start_.arm);
          const std::vector<ArmJoints> path = arm_path();
          retract_.waypoints.insert(retract_.waypoints.end(), path.begin(), path.end());
          phase_ = Phase::target;
        }
        break;
      case Phase::target:
        draw_target();
        break;
      case Phase::approach:
      case Phase::drive:
        plan_to_target(limit_seconds);
        break;
      case Phase::shorten:
        shorten_one();
        break;
    }
  }

  double execution_seconds() const override {
    require_found();
    return domain_.arm_seconds(retract_.shortened) + domain_.drive_seconds(drive_.shortened) +
           domain_.arm_seconds(approach_.shortened) + world_.robot.gripper_seconds;
  }

  Configuration final_configuration() const override {
    require_found();
    return ManipulationDomain::configuration(end_state());
  }

  std::vector<Configuration> motion() const override {
    require_found();
    std::vector<Configuration> result;
    KitchenState state = start_;
    for (const ArmJoints& joints : retract_.shortened) {
      state.arm = joints;
      result.push_back(ManipulationDomain::configuration(state));
    }
    state.arm = world_.robot.carry;
    for (const Pose& pose : drive_.shortened) {
      state.base = pose;
      result.push_back(ManipulationDomain::configuration(state));
    }
    for (const ArmJoints& joints : approach_.shortened) {
      state.arm = joints;
      result.push_back(ManipulationDomain::configuration(state));
    }
    result.push_back(ManipulationDomain::configuration(end_state()));
    return result;
  }

 private:
  enum class Phase { retreat, retract, target, approach, drive, shorten };

  double uniform(double low, double high) { return low + (high - low) * uniform01(random_); }

  Transform tool_in_world(const Pose& base, const ArmJoints& joints) const {
    return base_transform(base) * arm_.torso() * arm_.tool(joints);
  }

  KitchenState end_state() const {
    KitchenState state = start_;
    state.base = target_base_;
    state.arm = target_arm_;
    if (action_.kind == ManipulationKind::pick) {
      state.held = static_cast<int>(object_);
    } else {
      state.held = -1;
      state.objects[object_] = placement_;
    }
    return state;
  }

  // The tool frame `approach_distance` back along the gripper's axis from `tool`.
  Transform backed_off(const Transform& tool) const {
    Transform back = Transform::Identity();
    back.translation().x() = -world_.planner.approach_distance;
    return tool * back;
  }

  // The first stretch of the retract: straight back along the gripper's axis (out of the shelf,
  // away from the object just placed), when that motion is free; the rest is planned.
  void retreat() {
    retract_.information = arm_space(start_.base, stream_seed(seed_, 1));
    ArmJoints from = start_.arm;
    meter_.count_checks(static_cast<std::uint64_t>(world_.planner.ik_checks));
    const std::optional<ArmJoints> back = arm_.inverse(backed_off(arm_.tool(start_.arm)), start_.arm);
    if (back) {
      ob::ScopedState<> a(retract_.information), b(retract_.information);
      set(a.get(), start_.arm);
      set(b.get(), *back);
      if (retract_.information->isValid(b.get()) && retract_.information->checkMotion(a.get(), b.get())) {
        retreated_ = true;
        from = *back;
      }
    }
    planner_ = make_planner(retract_.information, from, world_.robot.carry, world_.planner.arm_range);
    phase_ = Phase::retract;
  }

  // The arm's joint space at a fixed base pose; `seed` seeds its sampler.
  ob::SpaceInformationPtr arm_space(const Pose& base, std::uint64_t seed) {
    auto space = std::make_shared<ArmJointSpace>();
    space->setStateSamplerAllocator(
        [seed](const ob::StateSpace* owner) { return std::make_shared<detail::SeededVectorSampler>(owner, seed); });
    auto information = std::make_shared<ob::SpaceInformation>(space);
    information->setStateValidityChecker([this, base](const ob::State* state) {
      meter_.count_check();
      return !collision_->collides(base, joints_of(state));
    });
    information->setStateValidityCheckingResolution(world_.planner.arm_resolution / space->getMaximumExtent());
    information->setup();
    return information;
  }

  // The floor in SE(2) with the arm carried; `seed` seeds its sampler.
  ob::SpaceInformationPtr base_space(std::uint64_t seed) {
    auto space = std::make_shared<ob::SE2StateSpace>();
    const std::array<double, 4> floor = world_.floor;
    ob::RealVectorBounds bounds(2);
    bounds.setLow(0, floor[0]);
    bounds.setLow(1, floor[1]);
    bounds.setHigh(0, floor[2]);
    bounds.setHigh(1, floor[3]);
    space->setBounds(bounds);
    space->setStateSamplerAllocator([floor, seed](const ob::StateSpace* owner) {
      return std::make_shared<detail::SeededPoseSampler>(owner, floor, seed);
    });
    auto information = std::make_shared<ob::SpaceInformation>(space);
    information->setStateValidityChecker([this](const ob::State* state) {
      meter_.count_check();
      return !collision_->collides(se2_pose(state), world_.robot.carry);
    });
    // One check every `base_resolution` of state-space distance (metres, plus half a metre per radian).
    information->setStateValidityCheckingResolution(world_.planner.base_resolution / space->getMaximumExtent());
    information->setup();
    return information;
  }

  template <class Waypoint>
  std::unique_ptr<detail::ResumableRrtConnect> make_planner(const ob::SpaceInformationPtr& information,
                                                            const Waypoint& from, const Waypoint& to,
                                                            double range) const {
    ob::ScopedState<> a(information), b(information);
    set(a.get(), from);
    set(b.get(), to);
    return std::make_unique<detail::ResumableRrtConnect>(information, a.get(), b.get(), range);
  }

  static void set(ob::State* state, const ArmJoints& joints) { set_joints(state, joints); }
  static void set(ob::State* state, const Pose& pose) { set_se2_pose(state, pose); }

  std::vector<ArmJoints> arm_path() const {
    std::vector<ArmJoints> path;
    for (const ob::State* state : planner_->path()) path.push_back(joints_of(state));
    return path;
  }

  // One draw of a target; a place gives up (backtracks to the pick that chose its grasp) after
  // `placement_draws` draws in a row without one, when the world sets that budget.
  void draw_target() {
    if (draw_one_target()) {
      misses_ = 0;
    } else if (action_.kind == ManipulationKind::place && world_.planner.placement_draws > 0 &&
               ++misses_ >= static_cast<std::uint64_t>(world_.planner.placement_draws)) {
      give_up();
    }
  }

  // One draw of a target: a grasp or a placement, a base pose, an IK solution; true when it is
  // reachable and planning towards it starts. Each draw costs at least one check, so that
  // rejections consume effort.
  bool draw_one_target() {
    Transform tool;
    if (action_.kind == ManipulationKind::pick) {
      const Transform& grasp =
          grasps_[static_cast<std::size_t>(uniform01(random_) * static_cast<double>(grasps_.size()))];
      tool = object_transform(start_.objects[object_]) * grasp;
      after_->set_grasp(grasp.inverse());
    } else {
      placement_ = ObjectPose{uniform(region_->min_x, region_->max_x), uniform(region_->min_y, region_->max_y),
                              world_.resting_z(object_, *region_), uniform(region_->yaw_low, region_->yaw_high)};
      meter_.count_check();
      if (collision_->held_object_collides(placement_)) return false;
      tool = object_transform(placement_) * grasp_.inverse();
      after_->set_object_pose(object_, placement_);
    }
    const double distance = uniform(world_.planner.base_distance[0], world_.planner.base_distance[1]);
    const double around = uniform(-pi, pi);
    const double x = tool.translation().x() + distance * std::cos(around);
    const double y = tool.translation().y() + distance * std::sin(around);
    const double heading = std::atan2(tool.translation().y() - y, tool.translation().x() - x) +
                           uniform(-world_.planner.base_heading_spread, world_.planner.base_heading_spread);
    const Pose base{x, y, std::remainder(heading, 2 * pi)};
    ArmJoints guess{};
    for (std::size_t j = 0; j < kArmJointCount; ++j)
      guess[j] = uniform(pr2_left_arm_joints()[j].lower, pr2_left_arm_joints()[j].upper);
    meter_.count_check();
    const auto& floor = world_.floor;
    if (!(x > floor[0] && x < floor[2] && y > floor[1] && y < floor[3])) return false;
    if (collision_->collides(base, world_.robot.carry)) return false;
    // The next action retracts to the carry configuration here, with or without the object.
    meter_.count_check();
    if (after_->collides(base, world_.robot.carry)) return false;
    const Transform torso = base_transform(base) * arm_.torso();
    if (!arm_.may_reach(torso.inverse() * tool) || !arm_.may_reach(torso.inverse() * backed_off(tool))) return false;
    meter_.count_checks(static_cast<std::uint64_t>(world_.planner.ik_checks));
    const std::optional<ArmJoints> joints = arm_.inverse(torso.inverse() * tool, guess);
    if (!joints) return false;
    meter_.count_check();
    if (collision_->collides(base, *joints)) return false;
    // The last stretch is straight along the gripper's axis, from `approach_distance` back.
    meter_.count_checks(static_cast<std::uint64_t>(world_.planner.ik_checks));
    const std::optional<ArmJoints> before = arm_.inverse(torso.inverse() * backed_off(tool), *joints);
    if (!before) return false;
    ++targets_;
    approach_ = Leg<ArmJoints>{};
    approach_.information = arm_space(base, stream_seed(seed_, 2 * targets_));
    ob::ScopedState<> near(approach_.information), at(approach_.information);
    set(near.get(), *before);
    set(at.get(), *joints);
    if (!approach_.information->isValid(near.get()) || !approach_.information->checkMotion(near.get(), at.get()))
      return false;
    target_base_ = base;
    target_arm_ = *joints;
    target_started_ = meter_.checks();
    planner_ = make_planner(approach_.information, world_.robot.carry, *before, world_.planner.arm_range);
    phase_ = Phase::approach;
    return true;
  }

  // Approach, then drive, until both are found, the limit is reached, or the target has had
  // its share of effort (then another target is drawn).
  void plan_to_target(double limit_seconds) {
    const auto cap = target_started_ + static_cast<std::uint64_t>(world_.planner.target_checks);
    const auto stop = [this, limit_seconds, cap] { return meter_.reached(limit_seconds) || meter_.checks() >= cap; };
    if (!planner_->run(meter_, stop)) {
      if (meter_.checks() >= cap) {
        planner_.reset();
        phase_ = Phase::target;
      }
      return;
    }
    if (phase_ == Phase::approach) {
      approach_.waypoints = arm_path();
      approach_.waypoints.push_back(target_arm_);
      drive_ = Leg<Pose>{};
      drive_.information = base_space(stream_seed(seed_, 2 * targets_ + 1));
      planner_ = make_planner(drive_.information, start_.base, target_base_, world_.planner.base_range);
      phase_ = Phase::drive;
      return;
    }
    for (const ob::State* state : planner_->path()) drive_.waypoints.push_back(se2_pose(state));
    planner_.reset();
    start_shortening();
  }

  void start_shortening() {
    retract_.shortcut = detail::GreedyShortcut(retract_.waypoints.size());
    drive_.shortcut = detail::GreedyShortcut(drive_.waypoints.size());
    approach_.shortcut = detail::GreedyShortcut(approach_.waypoints.size());
    phase_ = Phase::shorten;
    finish_legs();
  }

  // One step of the greedy shortcut of the first leg not yet shortened.
  void shorten_one() {
    if (!retract_.shortcut.done()) {
      shorten_step(retract_);
    } else if (!drive_.shortcut.done()) {
      shorten_step(drive_);
    } else {
      shorten_step(approach_);
    }
    finish_legs();
  }

  template <class Waypoint>
  void shorten_step(Leg<Waypoint>& leg) {
    const auto [from, to] = leg.shortcut.candidate();
    bool free = leg.shortcut.adjacent();
    if (!free) {
      ob::ScopedState<> a(leg.information), b(leg.information);
      set(a.get(), leg.waypoints[from]);
      set(b.get(), leg.waypoints[to]);
      free = leg.information->checkMotion(a.get(), b.get());
    }
    leg.shortcut.report(free);
  }

  void finish_legs() {
    if (!retract_.shortcut.done() || !drive_.shortcut.done() || !approach_.shortcut.done()) return;
    for (const std::size_t i : retract_.shortcut.kept()) {
      if (i < retract_.waypoints.size()) retract_.shortened.push_back(retract_.waypoints[i]);
    }
    for (const std::size_t i : drive_.shortcut.kept()) drive_.shortened.push_back(drive_.waypoints[i]);
    for (const std::size_t i : approach_.shortcut.kept()) approach_.shortened.push_back(approach_.waypoints[i]);
    found();
  }

  const ManipulationDomain& domain_;
  const ManipulationWorld& world_;
  ManipulationAction action_;
  std::size_t object_;
  const PlacementRegion* region_ = nullptr;
  KitchenState start_;
  std::uint64_t seed_;
  SplitMix64 random_;
  Pr2Arm arm_;
  Transform grasp_ = Transform::Identity();  // object in the tool frame, while held
  std::vector<Transform> grasps_;
  std::unique_ptr<ManipulationCollision> collision_, after_;
  std::unique_ptr<detail::ResumableRrtConnect> planner_;
  Phase phase_ = Phase::target;
  Pose target_base_;
  ArmJoints target_arm_{};
  ObjectPose placement_;
  std::uint64_t targets_ = 0, target_started_ = 0;
  std::uint64_t misses_ = 0;  // target draws in a row without a target
  bool retreated_ = false;
  Leg<ArmJoints> retract_, approach_;
  Leg<Pose> drive_;
};

}  // namespace

std::unique_ptr<Refinement> make_manipulation_refinement(const ManipulationDomain& domain,
                                                         const ManipulationAction& action, const KitchenState& start,
                                                         std::uint64_t seed, const EffortSettings& effort) {
  return std::make_unique<ManipulationRefinement>(domain, action, start, seed, effort);
}

}  // namespace ontime::domains
