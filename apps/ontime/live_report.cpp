#include "live_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <span>
#include <vector>

#include "ontime/report/report.hpp"
#include "python_runner.hpp"

namespace ontime::cli {

const char* status_name(Status status) {
  return status == Status::success ? "success" : status == Status::failure ? "failure" : "undecided";
}

// The charges of a live episode (prefix "") or their means over a run ("mean_").
void add_charges(Json& out, const LiveTotals& totals, const std::string& prefix) {
  out[prefix + "elapsed_seconds"] = totals.elapsed;
  out[prefix + "decision_seconds"] = totals.decision;
  out[prefix + "planning_seconds"] = totals.planning;
  out[prefix + "overrun_seconds"] = totals.overrun;
  out[prefix + "outside_seconds"] = totals.outside;
}

Json live_json(const EpisodeResult& result) {
  Json episode;
  episode["status"] = status_name(result.status);
  episode["step_clock_status"] = status_name(result.model_status);
  episode["solution"] = result.solution;
  episode["decisions"] = result.decisions;
  episode["steps"] = result.steps_used;
  add_charges(episode, result.live, "");
  Json timeline = Json::array();
  for (const LiveStep& step : result.timeline) {
    timeline.push_back({{"skeleton", step.skeleton},
                        {"action", step.action},
                        {"start", step.start},
                        {"outside_seconds", step.outside_seconds},
                        {"decision_seconds", step.decision_seconds},
                        {"planning_seconds", step.planning_seconds},
                        {"overrun_seconds", step.overrun_seconds},
                        {"observe_seconds", step.observe_seconds},
                        {"steps_charged", step.steps_charged},
                        {"refined", step.refined},
                        {"execution_seconds", step.refined ? Json(step.execution_seconds) : Json(nullptr)}});
  }
  episode["timeline"] = std::move(timeline);
  return episode;
}

// One row per step of the episode: what the timeline picture draws.
std::string timeline_csv(const Problem& problem, const EpisodeResult& result) {
  std::string csv =
      "skeleton,action,start,outside_seconds,decision_seconds,planning_seconds,overrun_seconds,observe_seconds,"
      "refined,execution_seconds\n";
  for (const LiveStep& step : result.timeline) {
    const std::string action = step.action >= 0 ? problem.action(step.action).id : "";
    csv += fmt::format("{},{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{},{:.9f}\n", step.skeleton,
                       report::csv_field(action), step.start, step.outside_seconds, step.decision_seconds,
                       step.planning_seconds, step.overrun_seconds, step.observe_seconds, step.refined ? 1 : 0,
                       step.refined ? step.execution_seconds : 0.0);
  }
  return csv;
}

void plot_timeline(const Problem& problem, const EpisodeResult& shown, const std::filesystem::path& data,
                   const std::filesystem::path& png, const std::string& title) {
  // The plan executed: every action of the skeleton that succeeded.
  double execution = 0;
  if (shown.status == Status::success) {
    const std::span<const int> plan = problem.skeleton(shown.solution);
    for (const LiveStep& step : shown.timeline) {
      if (step.refined && std::find(plan.begin(), plan.end(), step.action) != plan.end()) {
        execution += step.execution_seconds;
      }
    }
  }
  run_python_script("plot_timeline.py", png, [&](const std::string& drawing) {
    return std::vector<std::string>{
        "--data",      data.string(),
        "--output",    drawing,
        "--title",     title,
        "--deadline",  fmt::format("{}", problem.deadline() * problem.step_seconds()),
        "--step",      fmt::format("{}", problem.step_seconds()),
        "--skeletons", std::to_string(problem.skeleton_count()),
        "--solution",  std::to_string(shown.status == Status::success ? shown.solution : -1),
        "--execution", fmt::format("{}", execution)};
  });
}

}  // namespace ontime::cli
