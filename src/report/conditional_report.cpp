#include "ontime/report/conditional_report.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <set>

namespace ontime::report {
namespace {

using Json = nlohmann::ordered_json;

double found_share(const ConditionalData& data) {
  double found = 0;
  for (const std::uint8_t f : data.found) found += f;
  return data.rows() == 0 ? 0.0 : found / static_cast<double>(data.rows());
}

}  // namespace

std::string conditional_fit_json(const ConditionalTimeModel& model, const ConditionalData& data,
                                 const std::string& output) {
  const Json file = Json::parse(model.to_json());
  Json out = Json::object();
  out["kind"] = model.kind();
  out["feature_names"] = model.feature_names();
  out["step_seconds"] = model.step_seconds();
  out["horizon"] = model.horizon();
  out["rows"] = data.rows();
  out["worlds"] = std::set<std::string>(data.worlds.begin(), data.worlds.end()).size();
  out["found"] = found_share(data);
  if (!output.empty()) out["model"] = output;
  // (The boosted kind's trees, XGBoost's model texts, stay in the model file.)
  out["parameters"] = Json::object();
  for (const auto& [key, value] : file["parameters"].items()) {
    if (!key.ends_with("_booster")) out["parameters"][key] = value;
  }
  return out.dump();
}

std::string conditional_fit_text(const ConditionalTimeModel& model, const ConditionalData& data,
                                 const std::string& output) {
  std::string text = fmt::format(
      "Fitted a {} conditional time model{} from {} records of {} worlds ({:.1f}% found), "
      "{} features, horizon {} steps of {} s.\n",
      model.kind(), output.empty() ? "" : " (" + output + ")", data.rows(),
      std::set<std::string>(data.worlds.begin(), data.worlds.end()).size(), 100 * found_share(data),
      model.feature_count(), model.horizon(), model.step_seconds());
  const Json parameters = Json::parse(model.to_json())["parameters"];
  if (parameters.contains("log_likelihood") && parameters.contains("evaluations")) {
    text += fmt::format("Planning log-likelihood per record at the optimum: {:.6f} ({} evaluations).\n",
                        parameters["log_likelihood"].get<double>(), parameters["evaluations"].get<int>());
  } else if (parameters.contains("log_likelihood") && parameters.contains("trees")) {
    text += fmt::format("Planning log-likelihood per record after {} rounds of trees: {:.6f}.\n",
                        parameters["trees"].get<int>(), parameters["log_likelihood"].get<double>());
  }
  return text;
}

namespace {

Steps horizon_of(const ScoreReport& report) {
  return report.options.horizon > 0 ? report.options.horizon : report.problem->deadline();
}

}  // namespace

std::string attempt_scores_json(const ScoreReport& report) {
  const AttemptScores& scores = report.scores;
  Json out = Json::object();
  out["instance"] = report.instance;
  out["logs"] = std::vector<std::string>(report.logs.begin(), report.logs.end());
  out["horizon"] = horizon_of(report);
  out["attempts"] = scores.attempts;
  out["found"] = scores.found;
  out["censored"] = scores.censored;
  out["skipped"] = scores.skipped;
  out["planning_nll"] = scores.planning_nll;
  out["integrated_brier"] = scores.integrated_brier;
  out["executions"] = scores.executions;
  out["execution_nll"] = scores.execution_nll;
  out["floored"] = scores.floored;
  out["floor"] = report.options.floor;
  return out.dump();
}

std::string attempt_scores_text(const ScoreReport& report) {
  const AttemptScores& scores = report.scores;
  std::string out = fmt::format("instance          {} ({}), deadline {}, horizon {} steps\n", report.instance,
                                report.problem->name(), report.problem->deadline(), horizon_of(report));
  out += fmt::format("attempts          {} ({} found within the horizon, {} censored; {} skipped)\n", scores.attempts,
                     scores.found, scores.censored, scores.skipped);
  out += fmt::format("planning NLL      {:.4f} nats per attempt\n", scores.planning_nll);
  out += fmt::format("integrated Brier  {:.4f}\n", scores.integrated_brier);
  out += fmt::format("execution NLL     {:.4f} nats per found attempt ({})\n", scores.execution_nll, scores.executions);
  if (scores.floored > 0) {
    out += fmt::format("floored           {} outcomes the instance gives less than {:g}, scored at it\n",
                       scores.floored, report.options.floor);
  }
  return out;
}

}  // namespace ontime::report
