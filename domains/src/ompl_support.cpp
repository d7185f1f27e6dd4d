#include "ompl_support.hpp"

#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ScopedState.h>
#include <ompl/util/Console.h>

#include <mutex>
#include <stdexcept>

namespace ontime::domains::detail {

namespace ob = ompl::base;
namespace og = ompl::geometric;

ResumableRrtConnect::ResumableRrtConnect(const ob::SpaceInformationPtr& information, const ob::State* from,
                                         const ob::State* to, double range)
    : problem_(std::make_shared<ob::ProblemDefinition>(information)),
      planner_(std::make_shared<og::RRTConnect>(information)) {
  const ob::ScopedState<> start(information->getStateSpace(), from);
  const ob::ScopedState<> goal(information->getStateSpace(), to);
  problem_->setStartAndGoalStates(start, goal);
  planner_->setRange(range);
  planner_->setProblemDefinition(problem_);
  planner_->setup();
}

bool ResumableRrtConnect::run(const EffortMeter& meter, const std::function<bool()>& stop) {
  problem_->clearSolutionPaths();
  const std::uint64_t checks_before = meter.checks();
  const ob::PlannerStatus result = planner_->solve(ob::PlannerTerminationCondition(stop));
  if (result == ob::PlannerStatus::EXACT_SOLUTION) return true;
  if ((result != ob::PlannerStatus::TIMEOUT && result != ob::PlannerStatus::APPROXIMATE_SOLUTION) ||
      meter.checks() == checks_before) {
    throw std::logic_error("RRT-Connect stopped without progress, with status " + result.asString());
  }
  return false;
}

std::vector<const ob::State*> ResumableRrtConnect::path() const {
  const auto* path = problem_->getSolutionPath()->as<og::PathGeometric>();
  std::vector<const ob::State*> states;
  for (unsigned i = 0; i < path->getStateCount(); ++i) states.push_back(path->getState(i));
  return states;
}

}  // namespace ontime::domains::detail
