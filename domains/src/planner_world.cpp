#include "ontime/domains/planner_world.hpp"

#include <chrono>
#include <string>

#include "ontime/fitting.hpp"
#include "ontime/random.hpp"

namespace ontime::domains {

PlannerWorld::PlannerWorld(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options)
    : domain_(&domain),
      problem_(&problem),
      options_(options),
      refinements_(static_cast<std::size_t>(problem.action_count())) {}

void PlannerWorld::begin_episode(std::uint64_t seed) {
  seed_ = seed;
  for (std::unique_ptr<Refinement>& refinement : refinements_) refinement.reset();
}

Observation PlannerWorld::step(int action, Steps spent) {
  std::unique_ptr<Refinement>& refinement = refinements_.at(static_cast<std::size_t>(action));
  if (!refinement) {
    const int parent = problem_->parent(action);
    const std::string& id = problem_->action(action).id;
    const auto stream = 2 * static_cast<std::uint64_t>(action);
    Configuration start;
    if (parent < 0) {
      start = domain_->initial_configuration();
    } else if (options_.independent_starts) {
      start = domain_->fallback_start(id, stream_seed(seed_, stream + 1));
    } else {
      start = refinements_[static_cast<std::size_t>(parent)]->final_configuration();
    }
    refinement = domain_->refine(id, start, stream_seed(seed_, stream), options_.effort);
    ++started_;
  }
  const double step_seconds = problem_->step_seconds();
  const double real_start = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  const double effort_start = refinement->effort().seconds();
  const RefinementStatus status = refinement->advance(static_cast<double>(spent + 1) * step_seconds);
  const double real_end = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  nominal_clock_.count_call(real_end - real_start, refinement->effort().seconds() - effort_start);
  if (status != RefinementStatus::found) return Observation::not_yet();
  ++found_;
  return Observation::found(steps_to_complete(refinement->execution_seconds(), step_seconds));
}

const Clock* PlannerWorld::clock() const noexcept {
  return options_.effort.unit == EffortUnit::collision_checks ? &nominal_clock_ : nullptr;
}

void PlannerWorld::collect_statistics(Statistics& statistics) const {
  statistics.add("refinements_started", static_cast<double>(started_));
  statistics.add("refinements_found", static_cast<double>(found_));
}

WorldFactory planner_worlds(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options) {
  return [&domain, &problem, options] { return std::make_unique<PlannerWorld>(domain, problem, options); };
}

}  // namespace ontime::domains
