#include "ontime/learn/pooled_time_model.hpp"

#include <set>

#include "learn/conditional_kinds.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/util/error.hpp"

namespace ontime {
namespace {

std::string masses_json(const Distribution& distribution) {
  return detail::ModelJson(std::vector<double>(distribution.masses().begin(), distribution.masses().end())).dump();
}

}  // namespace

const std::string& PooledTimeModel::kind_name() {
  static const std::string name = "pooled";
  return name;
}

PooledTimeModel::PooledTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon,
                                 std::size_t rows, std::size_t worlds, Distribution planning, Distribution execution)
    : ConditionalTimeModel(std::move(feature_names), step_seconds, horizon, rows, worlds),
      planning_(std::move(planning)),
      execution_(std::move(execution)) {}

std::unique_ptr<PooledTimeModel> PooledTimeModel::fit(const ConditionalData& data,
                                                      std::vector<std::string> feature_names, Steps horizon) {
  PlanningSample sample;
  std::vector<Steps> execution;
  for (std::size_t i = 0; i < data.rows(); ++i) {
    if (data.found[i] != 0) {
      sample.found.push_back(data.planning[i]);
      execution.push_back(steps_to_complete(data.execution_seconds[i], data.step_seconds));
    } else {
      sample.censored.push_back(data.planning[i]);
    }
  }
  const std::set<std::string> worlds(data.worlds.begin(), data.worlds.end());
  return std::make_unique<PooledTimeModel>(std::move(feature_names), data.step_seconds, horizon, data.rows(),
                                           worlds.size(), estimate_planning(sample, horizon),
                                           estimate_execution(execution, horizon));
}

PredictedTimes PooledTimeModel::predict_checked(std::span<const double> /*features*/) const {
  return {planning_, execution_};
}

std::string PooledTimeModel::parameters_json() const {
  return "{\"planning\": " + masses_json(planning_) + ", \"execution\": " + masses_json(execution_) + "}";
}

namespace detail {

std::unique_ptr<ConditionalTimeModel> read_pooled_model(const ParameterReader& reader, ModelHeader header) {
  const auto distribution = [&](const std::string& key) {
    std::vector<double> masses = reader.reals(key, 0);
    if (masses.size() > static_cast<std::size_t>(header.horizon) + 1)
      reader.fail(key, "lists steps beyond the horizon");
    try {
      return Distribution::from_pmf(std::move(masses));
    } catch (const UsageError& error) {
      reader.fail(key, error.what());
    }
  };
  Distribution planning = distribution("planning");
  Distribution execution = distribution("execution");
  return std::make_unique<PooledTimeModel>(std::move(header.feature_names), header.step_seconds, header.horizon,
                                           header.rows, header.worlds, std::move(planning), std::move(execution));
}

}  // namespace detail
}  // namespace ontime
