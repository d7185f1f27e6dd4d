#pragma once
// The navigation domain (paper §VII-A): a PR2-sized base on an office floor. `move(Ri,Rj)`
// samples a collision-free goal pose uniformly in room Rj, plans to it from the current pose
// (which must lie in Ri) with OMPL's RRT-Connect in SE(2), sampling within the two rooms'
// bounding box (collision checks with FCL), shortens the path, and reports
// its execution time: path length over the linear speed plus total rotation over the angular
// speed. Planning is resumable: each call to advance() continues the same planner, trees kept.

#include "ontime/domains/domain.hpp"
#include "ontime/domains/navigation_world.hpp"

namespace ontime::domains {

class NavigationDomain final : public Domain {
 public:
  // The domain of `world`, a world file already read and checked.
  explicit NavigationDomain(NavigationWorld world);

  const std::string& name() const override { return name_; }
  const std::vector<std::vector<std::string>>& skeletons() const override { return world_.skeletons; }
  Configuration initial_configuration() const override;
  std::unique_ptr<Refinement> refine(const std::string& action, const Configuration& start, std::uint64_t seed,
                                     const EffortSettings& effort) const override;
  Configuration fallback_start(const std::string& action, std::uint64_t seed) const override;
  // move(A,B) and move(B,A) for every pair of rooms a door joins, in the order of the doors; the
  // moves out of the start room start at the start pose.
  std::vector<StandaloneAction> every_action() const override;
  const std::vector<std::string>& feature_names() const override;
  std::vector<double> action_features(const std::string& action) const override;
  Scene scene() const override;
  std::vector<std::array<double, 2>> trace(const std::vector<Configuration>& motion) const override;
  std::vector<std::array<double, 2>> outline(const Configuration& configuration) const override;
  // The room path through the doors' centres (room_path_points, task_planner.hpp).
  std::vector<std::array<double, 2>> skeleton_points(const std::vector<std::string>& skeleton) const override;
  // Room paths in order of length (room_path_planners, task_planner.hpp).
  TaskPlannerFactory task_planners(int max_skeletons) const override;

  // The world the domain refines in.
  const NavigationWorld& world() const noexcept { return world_; }

  // The execution time of a motion through these poses (drive_seconds at the robot's speeds).
  double execution_seconds(const std::vector<Pose>& poses) const;

 private:
  std::string name_ = "navigation";
  NavigationWorld world_;
};

}  // namespace ontime::domains
