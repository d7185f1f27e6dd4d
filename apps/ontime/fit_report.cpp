#include "fit_report.hpp"

#include <fmt/format.h>

#include "markdown_table.hpp"

namespace ontime::cli {
namespace {

struct ActionSummary {
  double found_in_time;    // P(planning time <= D)
  double mean_planning;    // E[T | T <= D], steps
  double mean_execution;   // E[X | X <= D], steps
  double execution_never;  // P(X > D)
};

ActionSummary summarise(const Action& action) {
  return ActionSummary{1.0 - action.planning.never(), action.planning.mean_finite(), action.execution.mean_finite(),
                       action.execution.never()};
}

std::string format_mean(double mean) { return std::isfinite(mean) ? fmt::format("{:.2f}", mean) : "-"; }

}  // namespace

std::string fit_report_markdown(const FitResult& fit) {
  const std::vector<std::string> header{"action",   "attempts",     "found",        "cut off",
                                        "P(T ≤ D)", "E[T | T ≤ D]", "E[X | X ≤ D]", "P(X > D)"};
  std::vector<std::vector<std::string>> body;
  for (std::size_t a = 0; a < fit.actions.size(); ++a) {
    const ActionFit& counts = fit.actions[a];
    const ActionSummary summary = summarise(fit.problem.action(static_cast<int>(a)));
    body.push_back({counts.id, std::to_string(counts.attempts), std::to_string(counts.found),
                    std::to_string(counts.censored), fmt::format("{:.3f}", summary.found_in_time),
                    format_mean(summary.mean_planning), format_mean(summary.mean_execution),
                    fmt::format("{:.3f}", summary.execution_never)});
  }
  return render_markdown(header, body);
}

Json fit_report_json(const FitResult& fit) {
  Json actions = Json::array();
  for (std::size_t a = 0; a < fit.actions.size(); ++a) {
    const ActionFit& counts = fit.actions[a];
    const ActionSummary summary = summarise(fit.problem.action(static_cast<int>(a)));
    Json entry;
    entry["action"] = counts.id;
    entry["attempts"] = counts.attempts;
    entry["found"] = counts.found;
    entry["cut_off"] = counts.censored;
    entry["planning_within_deadline"] = summary.found_in_time;
    entry["mean_planning_steps"] = std::isfinite(summary.mean_planning) ? Json(summary.mean_planning) : Json(nullptr);
    entry["mean_execution_steps"] =
        std::isfinite(summary.mean_execution) ? Json(summary.mean_execution) : Json(nullptr);
    entry["execution_never"] = summary.execution_never;
    actions.push_back(entry);
  }
  return actions;
}

}  // namespace ontime::cli
