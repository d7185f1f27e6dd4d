#pragma once
// The manipulation domain (paper §VII-B, Appendix A): a PR2-like mobile manipulator in a kitchen
// must bring objects to regions (B1 from the shelf and B2 from the table to the worktop).
//
// The actions combine a move and a pick or a place, as the paper does. Refining one, from a
// configuration of robot and world:
//   1. retract: the arm plans from where it is to its carry configuration (OMPL RRT-Connect in
//      joint space, the held object attached), unless it is there already;
//   2. target: draws a grasp of the object (pick) or a placement in the region with the held
//      object's grasp (place), a base pose near it, and solves the arm's IK with KDL from a
//      random initial guess; a draw that collides or has no IK solution is rejected and another
//      drawn;
//   3. approach: plans the arm from the carry configuration to the IK solution at that base pose
//      (joint space, held object attached for place);
//   4. drive: plans the base from its pose to the target's with the arm carried (SE(2));
//   5. shorten: greedy shortcutting of the three paths.
// A target whose approach and drive take more than `planner.target_checks` checks is dropped
// for a new draw. When the world sets `planner.placement_draws`, a place that has drawn that many
// targets in a row without one (every placement unreachable with the grasp held) gives up and
// blames the pick before it (RefinementStatus::backtrack, docs/spec.md §7): the pick is refined
// anew, with another grasp. Every collision check is effort, and so is every IK solve (`planner.ik_checks`
// checks each). Planning is resumable: advance() continues the same planners, trees kept.
// Execution: the arm paths at `robot.arm_speed` times the PR2's joint velocity limits (each
// segment as long as its slowest joint), the base path as navigation's, and the gripper.
//
// A configuration is the robot and the world (a world state, below): the robot's base and arm
// and every object's pose, so that an action starts from the world the actions before it left.

#include <cstddef>
#include <vector>

#include "ontime/domains/domain.hpp"
#include "ontime/domains/manipulation_world.hpp"

namespace ontime::domains {

// Robot and objects. The held object's pose is where it was when it was grasped; with the arm
// in the configuration of that moment, it fixes the grasp (tool frame -> object).
struct KitchenState {
  Pose base;
  ArmJoints arm{};
  int held = -1;  // object index, -1: the hand is empty
  std::vector<ObjectPose> objects;
};

class ManipulationDomain final : public Domain {
 public:
  // The domain of `world`, a world file already read and checked.
  explicit ManipulationDomain(ManipulationWorld world);

  const std::string& name() const override { return name_; }
  const std::vector<std::vector<std::string>>& skeletons() const override { return world_.skeletons; }
  Configuration initial_configuration() const override;
  std::unique_ptr<Refinement> refine(const std::string& action, const Configuration& start, std::uint64_t seed,
                                     const EffortSettings& effort) const override;
  // The world of the skeleton prefix before `action` with the moved objects placed at poses
  // drawn in their regions, the robot at the start pose with its arm carried (and, before a
  // place, holding the object with a side grasp).
  Configuration fallback_start(const std::string& action, std::uint64_t seed) const override;
  // Top view (walls, furniture, regions, objects, the robot) and front view (furniture, regions
  // and objects from the front, x and z).
  Scene scene() const override;
  std::vector<std::array<double, 2>> trace(const std::vector<Configuration>& motion) const override;
  std::vector<std::array<double, 2>> outline(const Configuration& configuration) const override;
  // The moves of a skeleton, e.g. "B3→C1, B4→C1, B1→R1, B2→R2".
  std::string describe(const std::vector<std::string>& skeleton) const override;
  // The features of manipulation_features.hpp.
  const std::vector<std::string>& feature_names() const override;
  std::vector<double> action_features(const std::string& action) const override;

  // The world the domain refines in.
  const ManipulationWorld& world() const noexcept { return world_; }

  // Configuration <-> state: [x, y, theta, 7 arm joints, held, then x, y, z, yaw per object].
  KitchenState state(const Configuration& configuration) const;
  static Configuration configuration(const KitchenState& state);

  // Execution time of an arm path (each segment as long as its slowest joint) and of a base path.
  double arm_seconds(const std::vector<ArmJoints>& path) const;
  double drive_seconds(const std::vector<Pose>& path) const;

 private:
  std::string name_ = "manipulation";
  ManipulationWorld world_;
};

}  // namespace ontime::domains
