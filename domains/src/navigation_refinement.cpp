#include "navigation_refinement.hpp"

#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "ontime/domains/navigation_collision.hpp"
#include "ontime/random.hpp"

namespace ontime::domains {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

// Uniform poses in the planning bounds, drawn from a seeded SplitMix64. Written here instead of
// OMPL's default sampler because that one draws from OMPL's RNG, whose seeds come from one
// process-wide sequence in the order samplers are created: with several threads the same
// refinement would get other samples from run to run.
class SeededPoseSampler final : public ob::StateSampler {
 public:
  SeededPoseSampler(const ob::StateSpace* space, std::array<double, 4> bounds, std::uint64_t seed)
      : ob::StateSampler(space), bounds_(bounds), random_(seed) {}

  void sampleUniform(ob::State* state) override {
    set(state, uniform(bounds_[0], bounds_[2]), uniform(bounds_[1], bounds_[3]),
        uniform(-std::numbers::pi, std::numbers::pi));
  }

  // Not used by RRT-Connect; uniform within `distance` of `near` in x, y and heading.
  void sampleUniformNear(ob::State* state, const ob::State* near, double distance) override {
    const auto* centre = near->as<ob::SE2StateSpace::StateType>();
    set(state, std::clamp(centre->getX() + uniform(-distance, distance), bounds_[0], bounds_[2]),
        std::clamp(centre->getY() + uniform(-distance, distance), bounds_[1], bounds_[3]),
        centre->getYaw() + uniform(-distance, distance));
  }

  // Not used by RRT-Connect; approximated by the uniform draw of the same spread.
  void sampleGaussian(ob::State* state, const ob::State* mean, double standard_deviation) override {
    sampleUniformNear(state, mean, standard_deviation);
  }

 private:
  double uniform(double low, double high) { return low + (high - low) * uniform01(random_); }

  void set(ob::State* state, double x, double y, double yaw) const {
    auto* pose = state->as<ob::SE2StateSpace::StateType>();
    pose->setXY(x, y);
    pose->setYaw(std::remainder(yaw, 2 * std::numbers::pi));
    space_->enforceBounds(state);
  }

  std::array<double, 4> bounds_;
  SplitMix64 random_;
};

Pose pose_of(const ob::State* state) {
  const auto* pose = state->as<ob::SE2StateSpace::StateType>();
  return Pose{pose->getX(), pose->getY(), pose->getYaw()};
}

void set_pose(ob::State* state, const Pose& pose) {
  auto* se2 = state->as<ob::SE2StateSpace::StateType>();
  se2->setXY(pose.x, pose.y);
  se2->setYaw(pose.theta);
}

class NavigationRefinement final : public Refinement {
 public:
  NavigationRefinement(const NavigationDomain& domain, const Room& source, const Room& target, const Pose& start,
                       std::uint64_t seed, const EffortSettings& effort)
      : domain_(domain),
        target_(target),
        start_(start),
        meter_(effort),
        goal_random_(stream_seed(seed, 0)),
        collision_(domain.world(), domain.world().robot.clearance) {
    const NavigationWorld& world = domain.world();
    if (!source.contains(start_.x, start_.y)) throw std::invalid_argument("the start pose is not in room " + source.id);
    if (collision_.collides(start_)) throw std::invalid_argument("the start pose is in collision");
    const double half = world.wall_thickness / 2;
    const std::array<double, 4> bounds{std::min(source.min_x, target.min_x) - half, std::min(source.min_y, target.min_y) - half,
                                       std::max(source.max_x, target.max_x) + half, std::max(source.max_y, target.max_y) + half};
    auto space = std::make_shared<ob::SE2StateSpace>();
    ob::RealVectorBounds limits(2);
    limits.setLow(0, bounds[0]);
    limits.setLow(1, bounds[1]);
    limits.setHigh(0, bounds[2]);
    limits.setHigh(1, bounds[3]);
    space->setBounds(limits);
    const std::uint64_t sampler_seed = stream_seed(seed, 1);
    space->setStateSamplerAllocator([bounds, sampler_seed](const ob::StateSpace* owner) {
      return std::make_shared<SeededPoseSampler>(owner, bounds, sampler_seed);
    });
    information_ = std::make_shared<ob::SpaceInformation>(space);
    information_->setStateValidityChecker([this](const ob::State* state) {
      meter_.count_check();
      return !collision_.collides(pose_of(state));
    });
    // One check every `resolution` of state-space distance (metres, plus half a metre per radian).
    information_->setStateValidityCheckingResolution(world.planner.resolution / space->getMaximumExtent());
    information_->setup();
  }

  RefinementStatus advance(double limit_seconds) override {
    meter_.start_working();
    while (phase_ != Phase::done && !meter_.reached(limit_seconds)) {
      switch (phase_) {
        case Phase::goal:
          sample_goal();
          break;
        case Phase::plan:
          plan(limit_seconds);
          break;
        case Phase::shorten:
          shorten_one();
          break;
        case Phase::done:
          break;
      }
    }
    meter_.stop_working();
    return status();
  }

  RefinementStatus status() const override { return phase_ == Phase::done ? RefinementStatus::found : RefinementStatus::working; }
  const EffortMeter& effort() const override { return meter_; }

  double execution_seconds() const override {
    require_found();
    return domain_.execution_seconds(shortened_);
  }

  Configuration final_configuration() const override {
    require_found();
    return {goal_.x, goal_.y, goal_.theta};
  }

  std::vector<Configuration> motion() const override {
    require_found();
    std::vector<Configuration> result;
    for (const Pose& pose : shortened_) result.push_back({pose.x, pose.y, pose.theta});
    return result;
  }

 private:
  enum class Phase { goal, plan, shorten, done };

  void require_found() const {
    if (phase_ != Phase::done) throw std::logic_error("the refinement has not found a motion yet");
  }

  double uniform(double low, double high) { return low + (high - low) * uniform01(goal_random_); }

  void sample_goal() {
    const double half = domain_.world().wall_thickness / 2;
    const Pose candidate{uniform(target_.min_x + half, target_.max_x - half), uniform(target_.min_y + half, target_.max_y - half),
                         uniform(-std::numbers::pi, std::numbers::pi)};
    meter_.count_check();
    if (collision_.collides(candidate)) return;
    goal_ = candidate;
    problem_ = std::make_shared<ob::ProblemDefinition>(information_);
    ob::ScopedState<ob::SE2StateSpace> from(information_), to(information_);
    set_pose(from.get(), start_);
    set_pose(to.get(), goal_);
    problem_->setStartAndGoalStates(from, to);
    planner_ = std::make_shared<og::RRTConnect>(information_);
    planner_->setRange(domain_.world().planner.range);
    planner_->setProblemDefinition(problem_);
    planner_->setup();
    phase_ = Phase::plan;
  }

  void plan(double limit_seconds) {
    problem_->clearSolutionPaths();
    const std::uint64_t checks_before = meter_.checks();
    const ob::PlannerTerminationCondition stop([this, limit_seconds] { return meter_.reached(limit_seconds); });
    const ob::PlannerStatus result = planner_->solve(stop);
    if (result == ob::PlannerStatus::EXACT_SOLUTION) {
      const auto* path = problem_->getSolutionPath()->as<og::PathGeometric>();
      for (unsigned i = 0; i < path->getStateCount(); ++i) path_.push_back(pose_of(path->getState(i)));
      shortened_ = {path_.front()};
      from_ = 0;
      to_ = path_.size() - 1;
      planner_.reset();  // the trees are no longer needed
      phase_ = path_.size() < 2 ? Phase::done : Phase::shorten;
    } else if ((result != ob::PlannerStatus::TIMEOUT && result != ob::PlannerStatus::APPROXIMATE_SOLUTION) ||
               meter_.checks() == checks_before) {
      // Start and goal are checked before planning, so this is a defect, not bad input.
      throw std::logic_error("RRT-Connect stopped without progress, with status " + result.asString());
    }
  }

  // One step of the greedy shortcut: is the straight motion path_[from_] -> path_[to_] free?
  void shorten_one() {
    const bool adjacent = to_ == from_ + 1;  // the planner's own segment, known to be free
    ob::ScopedState<ob::SE2StateSpace> a(information_), b(information_);
    set_pose(a.get(), path_[from_]);
    set_pose(b.get(), path_[to_]);
    if (adjacent || information_->checkMotion(a.get(), b.get())) {
      shortened_.push_back(path_[to_]);
      from_ = to_;
      to_ = path_.size() - 1;
      if (from_ == to_) phase_ = Phase::done;
    } else {
      --to_;
    }
  }

  const NavigationDomain& domain_;
  Room target_;
  Pose start_, goal_;
  EffortMeter meter_;
  SplitMix64 goal_random_;
  NavigationCollision collision_;
  ob::SpaceInformationPtr information_;
  ob::ProblemDefinitionPtr problem_;
  std::shared_ptr<og::RRTConnect> planner_;
  Phase phase_ = Phase::goal;
  std::vector<Pose> path_, shortened_;
  std::size_t from_ = 0, to_ = 0;
};

}  // namespace

std::unique_ptr<Refinement> make_navigation_refinement(const NavigationDomain& domain, const Room& source, const Room& target,
                                                       const Pose& start, std::uint64_t seed, const EffortSettings& effort) {
  return std::make_unique<NavigationRefinement>(domain, source, target, start, seed, effort);
}

}  // namespace ontime::domains
