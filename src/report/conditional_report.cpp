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

}  // namespace ontime::report
