#pragma once
// The discrete-time hazard model with a cure fraction: planning and execution times conditioned
// on an action's features (docs/learning.md, "The hazard model").
//
// Computes, for the standardised feature vector z (each feature's training mean and standard
// deviation; a constant feature is left at 0):
//   planning  P(never | z) = s(g0 + g.z), the cure fraction: attempts that would not find a
//             motion however long they ran; otherwise the hazard of finding at step t is
//             h(t | z) = s(a[bin(t)] + b.z), so P(T = t | z) = (1 - P(never)) h(t) prod_{u<t} (1 - h(u))
//             for t = 1..horizon, and the rest is "never" (s is the logistic function; a is a
//             baseline per bin of steps, b and g the features' weights).
//   execution log(seconds) ~ Normal(c0 + c.z, sigma^2), discretised as the steps of fitting.hpp:
//             P(X = k) = P((k - 1) step < seconds <= k step), k = 1..horizon.
// Fitting: planning maximises the right-censored likelihood (a found row at t contributes
// P(T = t), a row cut off after c steps P(T > c) = P(never) + (1 - P(never)) prod_{u<=c} (1 - h(u)))
// minus ridge/2 (|b|^2 + |g|^2), by NLopt's L-BFGS with the exact gradient; rows with the same
// features are grouped, so an evaluation costs O(groups x horizon). Execution by ridge least
// squares (Eigen's LDLT). Guarantees: with no features and one bin per step the planning PMF
// over 1..horizon is the Kaplan-Meier estimate (the likelihood's maximum), to the optimiser's
// tolerance; deterministic (single-threaded, SLEEF's exp and log): the same file on every
// machine. Prediction: O(features + horizon).

#include <vector>

#include "ontime/learn/conditional_model.hpp"

namespace ontime {

struct HazardParameters {
  std::vector<double> mean, scale;  // standardisation, per feature
  std::vector<int> bin_end;         // bin j covers steps bin_end[j-1] + 1 .. bin_end[j] (bin_end[-1] = 0)
  std::vector<double> baseline;     // a, per bin
  std::vector<double> hazard;       // b, per feature
  double cure_intercept = 0;        // g0
  std::vector<double> cure;         // g, per feature
  double execution_intercept = 0;   // c0
  std::vector<double> execution;    // c, per feature
  double execution_sigma = 1;       // sigma > 0
  double ridge = 0;
  int iterations = 0;         // the optimiser's evaluations
  double log_likelihood = 0;  // planning, per row, at the optimum (without the penalty)
};

class HazardTimeModel final : public ConditionalTimeModel {
 public:
  // The kind's name in model files and options: "hazard".
  static const std::string& kind_name();
  // A model from its parts: what fit computes, or the model file's reader reads back. `rows` and `worlds`
  // count the training data's rows and worlds.
  HazardTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon, std::size_t rows,
                  std::size_t worlds, HazardParameters parameters);
  // Fits `data` as above, with the ridge penalty `ridge` (>= 0) and `bins` baseline levels over 1..horizon,
  // log-spaced (0: one per step; at most the horizon); the caller (fit_conditional_model) checks both.
  static std::unique_ptr<HazardTimeModel> fit(const ConditionalData& data, std::vector<std::string> feature_names,
                                              Steps horizon, double ridge, int bins);

  // The kind, kind_name(): "hazard".
  const std::string& kind() const noexcept override { return kind_name(); }
  // The fitted weights, standardisation and bins, and the fit's summary.
  const HazardParameters& parameters() const noexcept { return parameters_; }

 private:
  PredictedTimes predict_checked(std::span<const double> features) const override;
  std::string parameters_json() const override;

  HazardParameters parameters_;
};

}  // namespace ontime
