#include "ontime/domains/planner_world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "ontime/learn/fitting.hpp"
#include "ontime/util/random.hpp"

namespace ontime::domains {

PlannerWorld::PlannerWorld(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options)
    : domain_(&domain), step_seconds_(problem.step_seconds()), options_(options), nominal_clock_(options.thinking) {
  for (int a = 0; a < problem.action_count(); ++a)
    actions_.push_back(TreeAction{problem.action(a).id, problem.parent(a)});
  refinements_.resize(actions_.size());
  attempts_.resize(actions_.size());
}

PlannerWorld::PlannerWorld(const Domain& domain, const StreamingWorldOptions& streaming,
                           const PlannerWorldOptions& options)
    : domain_(&domain), step_seconds_(0), options_(options), streaming_(streaming), nominal_clock_(options.thinking) {
  if (streaming.library == nullptr) throw std::invalid_argument("a streaming world needs a library of actions");
  if (!streaming.task_planners) throw std::invalid_argument("a streaming world needs a task planner");
  if (!(streaming.seconds_per_skeleton >= 0) || std::isinf(streaming.seconds_per_skeleton)) {
    throw std::invalid_argument("the search charge per skeleton must be a finite time >= 0");
  }
  step_seconds_ = streaming.library->step_seconds();
  task_planner_ = streaming.task_planners();
}

void PlannerWorld::begin_episode(std::uint64_t seed) {
  seed_ = seed;
  // Every episode's modelled time starts from 0, so that its sums do not depend on the episodes
  // this world ran before (which depend on the thread count).
  nominal_clock_.restart();
  for (std::unique_ptr<Refinement>& refinement : refinements_) refinement.reset();
  std::fill(attempts_.begin(), attempts_.end(), 0);
  if (task_planner_) {
    task_planner_->restart();
    actions_.clear();
    node_ids_.clear();
    refinements_.clear();
    attempts_.clear();
    committed_.clear();
  }
}

void PlannerWorld::commit(const std::vector<int>& executed) {
  committed_.clear();
  for (const int action : executed) committed_.push_back(actions_.at(static_cast<std::size_t>(action)).action);
}

std::optional<FoundSkeleton> PlannerWorld::next_skeleton() {
  if (!task_planner_) return std::nullopt;
  std::optional<std::vector<std::string>> moves = task_planner_->next();
  // After a commit, only skeletons through what the robot executed: the paths in order of length
  // that begin with it are that prefix followed by the shortest paths from where it ends.
  while (moves &&
         (moves->size() < committed_.size() || !std::equal(committed_.begin(), committed_.end(), moves->begin()))) {
    moves = task_planner_->next();
  }
  if (!moves) return std::nullopt;
  FoundSkeleton found;
  found.charged_seconds = streaming_.seconds_per_skeleton;
  int parent = -1;
  for (const std::string& move : *moves) {
    int node = -1;
    for (std::size_t a = 0; a < actions_.size() && node < 0; ++a) {
      if (actions_[a].parent == parent && actions_[a].action == move) node = static_cast<int>(a);
    }
    if (node < 0) {
      const int known = streaming_.library->find_action(move);
      if (known < 0) {
        throw std::invalid_argument("the task planner's action '" + move + "' is not in the library " +
                                    streaming_.library->name());
      }
      std::string id = move;
      for (int copy = 2; std::find(node_ids_.begin(), node_ids_.end(), id) != node_ids_.end(); ++copy) {
        id = move + "#" + std::to_string(copy);
      }
      Action action = streaming_.library->action(known);
      action.id = id;
      found.new_actions.push_back(std::move(action));
      node = static_cast<int>(actions_.size());
      actions_.push_back(TreeAction{move, parent});
      node_ids_.push_back(id);
      refinements_.emplace_back();
      attempts_.push_back(0);
    }
    found.action_ids.push_back(node_ids_[static_cast<std::size_t>(node)]);
    parent = node;
  }
  return found;
}

void PlannerWorld::set_library(const Problem& library) {
  if (!task_planner_) throw std::invalid_argument("set_library: this planner world does not stream skeletons");
  if (std::abs(library.step_seconds() - step_seconds_) > 1e-9 * step_seconds_) {
    throw std::invalid_argument("set_library: the library's step differs from the world's");
  }
  streaming_.library = &library;
}

const Refinement* PlannerWorld::refinement(int action) const {
  return refinements_.at(static_cast<std::size_t>(action)).get();
}

Observation PlannerWorld::step(int action, Steps spent) {
  std::unique_ptr<Refinement>& refinement = refinements_.at(static_cast<std::size_t>(action));
  if (!refinement) {
    const int parent = actions_[static_cast<std::size_t>(action)].parent;
    const std::string& id = actions_[static_cast<std::size_t>(action)].action;
    const auto stream = 2 * static_cast<std::uint64_t>(action);
    Configuration start;
    if (parent < 0) {
      start = domain_->initial_configuration();
    } else if (options_.independent_starts) {
      start = domain_->fallback_start(id, stream_seed(seed_, stream + 1));
    } else {
      start = refinements_[static_cast<std::size_t>(parent)]->final_configuration();
    }
    // A first attempt draws from stream 2a; attempt n > 0 (after backtracks) from sub-stream n of it.
    const std::uint64_t attempt = attempts_[static_cast<std::size_t>(action)];
    const std::uint64_t seed =
        attempt == 0 ? stream_seed(seed_, stream) : stream_seed(stream_seed(seed_, stream), attempt);
    refinement = domain_->refine(id, start, seed, options_.effort);
    ++started_;
  }
  const double step_seconds = step_seconds_;
  const double real_start = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  const double effort_start = refinement->effort().seconds();
  const RefinementStatus status = refinement->advance(static_cast<double>(spent + 1) * step_seconds);
  const double real_end = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  nominal_clock_.count_call(real_end - real_start, refinement->effort().seconds() - effort_start);
  if (status == RefinementStatus::backtrack) {
    // SeSamE's rule: the action before is to blame. A first action has none; it is then stuck,
    // as an attempt that never ends.
    const int culprit = actions_[static_cast<std::size_t>(action)].parent;
    if (culprit < 0) return Observation::not_yet();
    discard_from(culprit);
    ++backtracks_;
    return Observation::backtracked(culprit);
  }
  if (status != RefinementStatus::found) return Observation::not_yet();
  ++found_;
  return Observation::found(steps_to_complete(refinement->execution_seconds(), step_seconds));
}

void PlannerWorld::discard_from(int culprit) {
  // Parents come before their children (in the instance's order and in the order nodes stream
  // in), so one pass marks every action at or below the culprit.
  std::vector<bool> below(actions_.size(), false);
  for (auto a = static_cast<std::size_t>(culprit); a < actions_.size(); ++a) {
    const int parent = actions_[a].parent;
    below[a] = static_cast<int>(a) == culprit || (parent >= 0 && below[static_cast<std::size_t>(parent)]);
    if (below[a] && refinements_[a]) {
      refinements_[a].reset();
      ++attempts_[a];
    }
  }
}

const Clock* PlannerWorld::clock() const noexcept {
  return options_.effort.unit == EffortUnit::collision_checks ? &nominal_clock_ : nullptr;
}

void PlannerWorld::collect_statistics(Statistics& statistics) const {
  statistics.add("refinements_started", static_cast<double>(started_));
  statistics.add("refinements_found", static_cast<double>(found_));
  statistics.add("backtracks", static_cast<double>(backtracks_));
}

WorldFactory streaming_planner_worlds(const Domain& domain, const StreamingWorldOptions& streaming,
                                      const PlannerWorldOptions& options) {
  return [&domain, streaming, options] { return std::make_unique<PlannerWorld>(domain, streaming, options); };
}

WorldFactory planner_worlds(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options) {
  return [&domain, &problem, options] { return std::make_unique<PlannerWorld>(domain, problem, options); };
}

}  // namespace ontime::domains
