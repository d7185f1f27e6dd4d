#pragma once
// The pooled conditional time model: one planning and one execution distribution for every
// action of every world, features ignored. What a user has without conditional models (one fit
// over the pooled log), and the yardstick the others must beat (docs/learning.md).
//
// Computes: planning by the Kaplan-Meier estimator over all rows (estimate_planning of
// fitting.hpp at the horizon, censoring included), execution by the empirical PMF over all
// found rows (estimate_execution). Guarantees: exactly fit_problem's distributions for a log
// of one action at deadline = horizon. Cost: O(rows + horizon) to fit, O(horizon) to predict.

#include <vector>

#include "ontime/learn/conditional_model.hpp"

namespace ontime {

class PooledTimeModel final : public ConditionalTimeModel {
 public:
  // The kind's name in model files and options: "pooled".
  static const std::string& kind_name();
  // A model from its parts: what fit computes, or the model file's reader reads back. `rows` and `worlds`
  // count the training data's rows and worlds.
  PooledTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon, std::size_t rows,
                  std::size_t worlds, Distribution planning, Distribution execution);
  // Fits `data` as above, over steps 1..horizon.
  static std::unique_ptr<PooledTimeModel> fit(const ConditionalData& data, std::vector<std::string> feature_names,
                                              Steps horizon);

  // The kind, kind_name(): "pooled".
  const std::string& kind() const noexcept override { return kind_name(); }
  // The planning distribution every prediction returns.
  const Distribution& planning() const noexcept { return planning_; }
  // The execution distribution every prediction returns.
  const Distribution& execution() const noexcept { return execution_; }

 private:
  PredictedTimes predict_checked(std::span<const double> features) const override;
  std::string parameters_json() const override;

  Distribution planning_, execution_;
};

}  // namespace ontime
