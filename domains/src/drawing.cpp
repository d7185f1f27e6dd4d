#include "ontime/domains/drawing.hpp"

#include <fmt/format.h>

#include <set>
#include <utility>

#include "ontime/domains/collection.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime::domains {

MapDrawing map_drawing(const Domain& domain, const DomainDefaults& defaults, std::uint64_t seed) {
  CollectionOptions settings;
  settings.step_seconds = defaults.collection.step_seconds;
  settings.budget_steps = defaults.collection.deadline;
  settings.effort.checks_per_second = defaults.collection.checks_per_second;
  const Scene scene = domain.scene();
  const auto& skeletons = domain.skeletons();
  MapDrawing drawing;
  drawing.title =
      skeletons.empty() ? scene.title : fmt::format("{}: one refined motion per skeleton (seed {})", scene.title, seed);
  drawing.polygons = scene.polygons;
  for (std::size_t k = 0; k < skeletons.size(); ++k) {
    std::vector<std::vector<Configuration>> motions;
    try {
      motions = refine_skeleton(domain, skeletons[k], stream_seed(seed, k), settings);
    } catch (const UsageError& error) {
      // An infeasible skeleton (kitchen-grasps' direct placement): captioned with the reason, not drawn.
      drawing.paths.push_back(
          {fmt::format("σ{}: {} (not refined: {})", k + 1, domain.describe(skeletons[k]), error.what()), {}, {}});
      continue;
    }
    Polyline points;
    for (const auto& motion : motions) {
      const auto trace = domain.trace(motion);
      points.insert(points.end(), trace.begin() + (points.empty() ? 0 : 1), trace.end());
    }
    drawing.paths.push_back({fmt::format("σ{}: {}", k + 1, domain.describe(skeletons[k])), std::move(points),
                             domain.outline(motions.back().back())});
  }
  return drawing;
}

EpisodeDrawing episode_drawing(const Domain& domain, const PlannerWorld& world, const EpisodeResult& shown,
                               std::string title) {
  const Problem& problem = *shown.problem;
  std::vector<double> action_seconds(static_cast<std::size_t>(problem.action_count()), 0.0);
  for (const LiveStep& step : shown.timeline) {
    if (step.action >= 0) action_seconds[static_cast<std::size_t>(step.action)] += step.planning_seconds;
  }
  EpisodeDrawing drawing;
  drawing.title = std::move(title);
  drawing.polygons = domain.scene().polygons;
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    std::vector<std::string> moves;
    double seconds = 0;
    for (const int action : problem.skeleton(k)) {
      moves.push_back(world.actions()[static_cast<std::size_t>(action)].action);
      seconds += action_seconds[static_cast<std::size_t>(action)];
    }
    drawing.skeletons.push_back({k, fmt::format("σ{}: {}", k + 1, domain.describe(moves)), seconds,
                                 shown.status == Status::success && shown.solution == k,
                                 domain.skeleton_points(moves)});
  }
  std::set<int> plan;
  if (shown.status == Status::success) {
    for (const int action : problem.skeleton(shown.solution)) plan.insert(action);
  }
  for (int a = 0; a < problem.action_count(); ++a) {
    const Refinement* refinement = world.refinement(a);
    if (refinement == nullptr || refinement->status() != RefinementStatus::found) continue;
    drawing.motions.push_back({problem.action(a).id, plan.contains(a), domain.trace(refinement->motion())});
  }
  return drawing;
}

}  // namespace ontime::domains
