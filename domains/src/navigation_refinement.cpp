#include "navigation_refinement.hpp"

#include <ompl/base/ScopedState.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/spaces/SE2StateSpace.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "ompl_support.hpp"
#include "ontime/domains/navigation_collision.hpp"
#include "ontime/util/random.hpp"
#include "phased_refinement.hpp"

namespace ontime::domains {
namespace {

namespace ob = ompl::base;

using detail::se2_pose;
using detail::set_se2_pose;

class NavigationRefinement final : public detail::PhasedRefinement {
 public:
  NavigationRefinement(const NavigationDomain& domain, const Room& source, const Room& target, const Pose& start,
                       std::uint64_t seed, const EffortSettings& effort)
      : PhasedRefinement(effort),
        domain_(domain),
        target_(target),
        start_(start),
        goal_random_(stream_seed(seed, 0)),
        collision_(domain.world(), domain.world().robot.clearance) {
    const NavigationWorld& world = domain.world();
    if (!source.contains(start_.x, start_.y)) throw std::invalid_argument("the start pose is not in room " + source.id);
    if (collision_.collides(start_)) throw std::invalid_argument("the start pose is in collision");
    const double half = world.wall_thickness / 2;
    const std::array<double, 4> bounds{
        std::min(source.min_x, target.min_x) - half, std::min(source.min_y, target.min_y) - half,
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
      return std::make_shared<detail::SeededPoseSampler>(owner, bounds, sampler_seed);
    });
    information_ = std::make_shared<ob::SpaceInformation>(space);
    information_->setStateValidityChecker([this](const ob::State* state) {
      meter_.count_check();
      return !collision_.collides(se2_pose(state));
    });
    // One check every `resolution` of state-space distance (metres, plus half a metre per radian).
    information_->setStateValidityCheckingResolution(world.planner.resolution / space->getMaximumExtent());
    information_->setup();
  }

  void work(double limit_seconds) override {
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
    }
  }

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
  enum class Phase { goal, plan, shorten };

  double uniform(double low, double high) { return low + (high - low) * uniform01(goal_random_); }

  void sample_goal() {
    const double half = domain_.world().wall_thickness / 2;
    const Pose candidate{uniform(target_.min_x + half, target_.max_x - half),
                         uniform(target_.min_y + half, target_.max_y - half),
                         uniform(-std::numbers::pi, std::numbers::pi)};
    meter_.count_check();
    if (collision_.collides(candidate)) return;
    goal_ = candidate;
    ob::ScopedState<ob::SE2StateSpace> from(information_), to(information_);
    set_se2_pose(from.get(), start_);
    set_se2_pose(to.get(), goal_);
    planner_ = std::make_unique<detail::ResumableRrtConnect>(information_, from.get(), to.get(),
                                                             domain_.world().planner.range);
    phase_ = Phase::plan;
  }

  void plan(double limit_seconds) {
    if (!planner_->run(meter_, [this, limit_seconds] { return meter_.reached(limit_seconds); })) return;
    for (const ob::State* state : planner_->path()) path_.push_back(se2_pose(state));
    shortcut_ = detail::GreedyShortcut(path_.size());
    planner_.reset();  // the trees are no longer needed
    phase_ = Phase::shorten;
    finish_if_shortened();
  }

  // One step of the greedy shortcut: is the straight motion between its candidate waypoints free?
  void shorten_one() {
    const auto [from, to] = shortcut_.candidate();
    ob::ScopedState<ob::SE2StateSpace> a(information_), b(information_);
    set_se2_pose(a.get(), path_[from]);
    set_se2_pose(b.get(), path_[to]);
    shortcut_.report(shortcut_.adjacent() || information_->checkMotion(a.get(), b.get()));
    finish_if_shortened();
  }

  void finish_if_shortened() {
    if (!shortcut_.done()) return;
    for (const std::size_t index : shortcut_.kept()) shortened_.push_back(path_[index]);
    found();
  }

  const NavigationDomain& domain_;
  Room target_;
  Pose start_, goal_;
  SplitMix64 goal_random_;
  NavigationCollision collision_;
  ob::SpaceInformationPtr information_;
  std::unique_ptr<detail::ResumableRrtConnect> planner_;
  Phase phase_ = Phase::goal;
  std::vector<Pose> path_, shortened_;
  detail::GreedyShortcut shortcut_;
};

}  // namespace

std::unique_ptr<Refinement> make_navigation_refinement(const NavigationDomain& domain, const Room& source,
                                                       const Room& target, const Pose& start, std::uint64_t seed,
                                                       const EffortSettings& effort) {
  return std::make_unique<NavigationRefinement>(domain, source, target, start, seed, effort);
}

}  // namespace ontime::domains
