// The results of `ontime solve --act concurrent` (report::ConcurrentSolve), as JSON and as text.

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "ontime/report/report.hpp"

namespace ontime::report {
namespace {

using Json = nlohmann::ordered_json;

// The skeleton refined first acting while planning, -1 when none can finish by the deadline.
int first_refined(const ConcurrentSolve& solve) {
  return solve.solution.first.is_start() ? -1 : solve.solution.first.refine;
}

}  // namespace

std::string to_json(const ConcurrentSolve& solve) {
  const Problem& problem = *solve.problem;
  const ConcurrentSolution& solution = solve.solution;
  Json out;
  out["instance"] = solve.instance;
  out["name"] = problem.name();
  out["method"] = solve.method;
  out["acting"] = std::string(acting_name(Acting::concurrent));
  out[problem.has_rewards() ? "optimal_expected_reward" : "optimal_success_probability"] =
      solution.exact ? Json(solution.lower) : Json(nullptr);
  out["lower_bound"] = solution.lower;
  out["upper_bound"] = solution.upper;
  out["exact"] = solution.exact;
  if (!solution.exact) out["stopped_by"] = solution.stopped_by;
  out["states"] = solution.solved;
  if (solve.method == "search") out["records"] = solution.records;
  if (solve.timing) out["seconds"] = solve.seconds;
  const int first = first_refined(solve);
  out["first_choice"] = first;
  out["first_action"] = first >= 0 ? problem.action(problem.action_at(first, 0)).id : "";
  if (solve.method == "layered") {
    if (solution.frontier_layer >= 0) out["frontier_level"] = solution.frontier_layer;
    out["levels"] = solution.layers.size();
    if (solve.timing) {
      out["peak_memory_bytes"] = solution.peak_memory_bytes;
      out["peak_disk_bytes"] = solution.peak_disk_bytes;
    }
    if (solve.stats) {
      Json levels = Json::array();
      for (const LayerFigures& level : solution.layers) {
        Json figures{{"level", level.layer}, {"states", level.states}};
        if (solve.timing) {
          figures["forward_seconds"] = level.forward_seconds;
          figures["backward_seconds"] = level.backward_seconds;
        }
        levels.push_back(figures);
      }
      out["level_figures"] = levels;
    }
  }
  return out.dump(2);
}

std::string to_text(const ConcurrentSolve& solve) {
  const Problem& problem = *solve.problem;
  const ConcurrentSolution& solution = solve.solution;
  std::string out = fmt::format("instance                     {} ({}), deadline {}, {} skeletons\n", solve.instance,
                                problem.name(), problem.deadline(), problem.skeleton_count());
  out += "acting                       concurrent: the robot executes refined actions while the rest is planned\n";
  const char* objective = problem.has_rewards() ? "optimal expected reward    " : "optimal success probability";
  if (solution.exact) {
    out += fmt::format("{}  {:.6f}\n", objective, solution.lower);
  } else {
    out += fmt::format("{}  in [{:.6f}, {:.6f}] (width {:.6f}; ended by {})\n", objective, solution.lower,
                       solution.upper, solution.upper - solution.lower, solution.stopped_by);
  }
  if (const int first = first_refined(solve); first >= 0) {
    out += fmt::format("first choice                 skeleton {} (refine {})\n", first,
                       problem.action(problem.action_at(first, 0)).id);
  } else {
    out += "first choice                 none (no skeleton can meet the deadline)\n";
  }
  out += fmt::format("states                       {}\n", solution.solved);
  if (solve.method == "search") out += fmt::format("states bounded               {}\n", solution.records);
  if (solve.method == "layered") {
    out += fmt::format("levels                       {} (CT plus the actions started)", solution.layers.size());
    out += solution.frontier_layer >= 0 ? fmt::format("; level {} bounded\n", solution.frontier_layer) : "\n";
    if (solve.timing) {
      out += fmt::format("peak memory, disk            {:.1f} MiB, {:.1f} MiB\n",
                         static_cast<double>(solution.peak_memory_bytes) / 1048576.0,
                         static_cast<double>(solution.peak_disk_bytes) / 1048576.0);
    }
    if (solve.stats) {
      out += solve.timing ? "level     states   forward s  backward s\n" : "level     states\n";
      for (const LayerFigures& level : solution.layers) {
        out += fmt::format("{:>5} {:>10}", level.layer, level.states);
        out +=
            solve.timing ? fmt::format(" {:>11.4f} {:>11.4f}\n", level.forward_seconds, level.backward_seconds) : "\n";
      }
    }
  }
  if (solve.timing) out += fmt::format("time                         {:.4f} s\n", solve.seconds);
  return out;
}

}  // namespace ontime::report
