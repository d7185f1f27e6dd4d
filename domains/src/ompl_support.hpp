#pragma once
// Internal: pieces that the domains' OMPL planners share.
//
// - Seeded state samplers. OMPL's default samplers draw from OMPL's RNG, whose seeds come from
//   one process-wide sequence in the order samplers are created: with several threads the same
//   refinement would get other samples from run to run. These draw from a SplitMix64 stream of
//   the refinement's own seed instead, so a refinement's result depends on its seed only.
// - GreedyShortcut: the deterministic path shortening of every domain (OMPL's PathSimplifier
//   draws from a random generator it does not let a caller seed). From each waypoint it keeps
//   the farthest later waypoint reachable in one straight collision-free motion, testing one
//   candidate per call so that the work can be cut into slices of effort.
// - ResumableRrtConnect: OMPL's RRT-Connect between two states, run slice by slice (each run
//   continues the same trees) until the effort meter reaches a limit.

#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <numbers>
#include <utility>
#include <vector>

#include "ontime/domains/effort.hpp"
#include "ontime/domains/world_types.hpp"
#include "ontime/util/random.hpp"

namespace ontime::domains::detail {

// A base pose to and from a state of an SE(2) state space.
inline Pose se2_pose(const ompl::base::State* state) {
  const auto* pose = state->as<ompl::base::SE2StateSpace::StateType>();
  return Pose{pose->getX(), pose->getY(), pose->getYaw()};
}

inline void set_se2_pose(ompl::base::State* state, const Pose& pose) {
  auto* se2 = state->as<ompl::base::SE2StateSpace::StateType>();
  se2->setXY(pose.x, pose.y);
  se2->setYaw(pose.theta);
}

// Uniform poses (x, y within `bounds` = {min x, min y, max x, max y}, heading uniform) in an
// SE(2) state space.
class SeededPoseSampler final : public ompl::base::StateSampler {
 public:
  SeededPoseSampler(const ompl::base::StateSpace* space, std::array<double, 4> bounds, std::uint64_t seed)
      : ompl::base::StateSampler(space), bounds_(bounds), random_(seed) {}

  void sampleUniform(ompl::base::State* state) override {
    set(state, uniform(bounds_[0], bounds_[2]), uniform(bounds_[1], bounds_[3]),
        uniform(-std::numbers::pi, std::numbers::pi));
  }

  // Not used by RRT-Connect; uniform within `distance` of `near` in x, y and heading.
  void sampleUniformNear(ompl::base::State* state, const ompl::base::State* near, double distance) override {
    const auto* centre = near->as<ompl::base::SE2StateSpace::StateType>();
    set(state, std::clamp(centre->getX() + uniform(-distance, distance), bounds_[0], bounds_[2]),
        std::clamp(centre->getY() + uniform(-distance, distance), bounds_[1], bounds_[3]),
        centre->getYaw() + uniform(-distance, distance));
  }

  // Not used by RRT-Connect; approximated by the uniform draw of the same spread.
  void sampleGaussian(ompl::base::State* state, const ompl::base::State* mean, double standard_deviation) override {
    sampleUniformNear(state, mean, standard_deviation);
  }

 private:
  double uniform(double low, double high) { return low + (high - low) * uniform01(random_); }

  void set(ompl::base::State* state, double x, double y, double yaw) const {
    auto* pose = state->as<ompl::base::SE2StateSpace::StateType>();
    pose->setXY(x, y);
    pose->setYaw(std::remainder(yaw, 2 * std::numbers::pi));
    space_->enforceBounds(state);
  }

  std::array<double, 4> bounds_;
  SplitMix64 random_;
};

// Uniform vectors within the bounds of a real-vector state space (a joint space).
class SeededVectorSampler final : public ompl::base::StateSampler {
 public:
  SeededVectorSampler(const ompl::base::StateSpace* space, std::uint64_t seed)
      : ompl::base::StateSampler(space),
        bounds_(space->as<ompl::base::RealVectorStateSpace>()->getBounds()),
        random_(seed) {}

  void sampleUniform(ompl::base::State* state) override {
    auto* values = state->as<ompl::base::RealVectorStateSpace::StateType>();
    for (std::size_t i = 0; i < bounds_.low.size(); ++i) values->values[i] = uniform(bounds_.low[i], bounds_.high[i]);
  }

  // Not used by RRT-Connect; uniform within `distance` of `near` in every coordinate.
  void sampleUniformNear(ompl::base::State* state, const ompl::base::State* near, double distance) override {
    auto* values = state->as<ompl::base::RealVectorStateSpace::StateType>();
    const auto* centre = near->as<ompl::base::RealVectorStateSpace::StateType>();
    for (std::size_t i = 0; i < bounds_.low.size(); ++i) {
      values->values[i] = std::clamp(centre->values[i] + uniform(-distance, distance), bounds_.low[i], bounds_.high[i]);
    }
  }

  // Not used by RRT-Connect; approximated by the uniform draw of the same spread.
  void sampleGaussian(ompl::base::State* state, const ompl::base::State* mean, double standard_deviation) override {
    sampleUniformNear(state, mean, standard_deviation);
  }

 private:
  double uniform(double low, double high) { return low + (high - low) * uniform01(random_); }

  ompl::base::RealVectorBounds bounds_;
  SplitMix64 random_;
};

// Greedy shortcutting of a path of `count` waypoints, one candidate motion at a time:
//   while (!shortcut.done()) shortcut.report(shortcut.adjacent() || motion_is_free(candidate()));
// kept() lists the indices of the waypoints that remain, first and last included.
class GreedyShortcut {
 public:
  GreedyShortcut() = default;
  explicit GreedyShortcut(std::size_t count) : kept_{0}, to_(count == 0 ? 0 : count - 1), last_(to_) {}

  bool done() const noexcept { return from_ == last_; }
  // The motion to test: from waypoint `first` straight to waypoint `second`.
  std::pair<std::size_t, std::size_t> candidate() const noexcept { return {from_, to_}; }
  // Consecutive waypoints: the planner's own segment, known to be free.
  bool adjacent() const noexcept { return to_ == from_ + 1; }

  void report(bool free) {
    if (free) {
      kept_.push_back(to_);
      from_ = to_;
      to_ = last_;
    } else {
      --to_;
    }
  }

  const std::vector<std::size_t>& kept() const noexcept { return kept_; }

 private:
  std::vector<std::size_t> kept_{0};
  std::size_t from_ = 0, to_ = 0, last_ = 0;
};

// RRT-Connect from `from` to `to` (both valid states of `information`), with the given range.
class ResumableRrtConnect {
 public:
  ResumableRrtConnect(const ompl::base::SpaceInformationPtr& information, const ompl::base::State* from,
                      const ompl::base::State* to, double range);

  // Plans until a path is found (true) or `stop()` holds (false); a later call continues with
  // the same trees. `meter` counts the planner's checks: the planner stopping without spending
  // any is a defect (start and goal are checked before planning), std::logic_error.
  bool run(const EffortMeter& meter, const std::function<bool()>& stop);

  // Once run() returned true: the waypoints of the path found, start and goal included.
  std::vector<const ompl::base::State*> path() const;

 private:
  ompl::base::ProblemDefinitionPtr problem_;
  std::shared_ptr<ompl::geometric::RRTConnect> planner_;
};

}  // namespace ontime::domains::detail
