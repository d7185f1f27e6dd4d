#include "timeline_plot.hpp"

#include <fmt/format.h>

#include <vector>

#include "ontime/domains/report.hpp"
#include "python_runner.hpp"

namespace ontime::cli {

void plot_timeline(const Problem& problem, const EpisodeResult& shown, const std::filesystem::path& data,
                   const std::filesystem::path& png, const std::string& title) {
  const double execution = domains::report::executed_plan_seconds(problem, shown);
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
