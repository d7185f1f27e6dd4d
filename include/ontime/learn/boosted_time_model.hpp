#pragma once
// The boosted conditional time model: planning and execution times conditioned on an action's
// features by gradient-boosted trees, XGBoost's (docs/learning.md, "The boosted model").
//
// Computes, for the feature vector x (three boosters, each a sum of trees giving one number):
//   planning  a mixture cure model. P(never | x) = pi(x) = s(k(x)): the attempts that would not find
//             a motion however long they ran (s is the logistic function, k the never booster).
//             The others find at the time T (in steps, continuous) of an accelerated failure time
//             law: log T = log u + m(x) + aft_scale * e, with m the planning booster, u the unit the
//             times were given to XGBoost in (the median step of the found attempts), and e
//             standard normal, logistic or extreme (the Gumbel minimum: T is Weibull; at scale 1
//             exponential, its whole steps geometric). An attempt is found at step t when T is in
//             (t - 1, t] (as steps_to_complete counts), so with S(v) = P(T > v | x)
//               P(found at t | x) = (1 - pi) (S(t - 1) - S(t)),  t = 1..horizon,
//             and the rest, pi + (1 - pi) S(horizon), is "never": never found, or found after the
//             horizon (the law's tail beyond it is not renormalised onto 1..horizon).
//   execution log(seconds) ~ Normal(c(x), sigma^2), c the execution booster, discretised as the
//             hazard kind's: P(X = k) = P((k - 1) step < seconds <= k step), k = 1..horizon.
// Fitting, planning: maximum likelihood of the right-censored data, as the hazard kind. A row found
// at t <= horizon contributes (1 - pi)(S(t - 1) - S(t)); a row cut off after c steps (or found after
// the horizon: c = horizon) pi + (1 - pi) S(c): it is censored, not "never" - it may be an attempt
// that would have found later. Both boosters grow together, one tree each per round, and before
// every round the E step of EM gives each cut-off row the posterior probability that it is never,
// w = pi / (pi + (1 - pi) S(c)), from the current trees. Then the never booster (binary:logistic)
// grows a tree on the logistic loss's gradient pi - w and hessian pi (1 - pi) (found rows: w = 0),
// computed here and given to XGBoost, and the planning booster's tree is XGBoost's survival:aft with the found rows
// interval-censored on (t - 1, t] (left-censored for t = 1) and the cut-off rows right-censored at c, weighted 1 - w.
// By Fisher's identity these gradients are exactly those of the observed censored log-likelihood (the hessians are the
// complete data's, positive), so each round is a boosting step on the likelihood itself; no row is labelled "never"
// because it was cut off. Rows cut off within their first step (c = 0) carry no information and weigh 0. The cure
// fraction and the tail beyond the horizon are told apart only by the law's shape (aft_distribution, aft_scale); their
// sum, the "never" of the prediction, is what the censored data determine. Execution: XGBoost's reg:squarederror on
// log(seconds) of the found rows (the log-normal's maximum-likelihood location); sigma the root mean square of the
// residuals out of fold (five folds by row order, each predicted by the trees of the other four: the training residuals
// would understate it by what the trees fit of the noise). Guarantees: the same data and settings give the same model
// file on every machine: one thread, the exact tree method, no sampling, no randomness; the never booster's gradients,
// the E step and the predicted distributions by SLEEF (portable_math.hpp) rather than libm, whose builds for CPUs with
// and without FMA may differ in a last bit; base scores whose margins XGBoost computes exactly (its
// logf of 1 for 0.5 and 1; the execution's mean itself); XGBoost's own survival:aft gradients call
// libm in double and are rounded to float, which hides such a bit (tested under glibc's builds).
// The boosters are stored as XGBoost's JSON and read back to the same predictions, bit for bit
// (XGBoost prints the shortest decimal of each float); every fit checks it on its training rows. Cost:
// fitting O(trees x rows x features x depth) (the exact greedy tree method; the execution booster
// six times, with its folds) plus O(trees x rows) for the E steps; predicting a batch of rows is one
// XGBoost call per booster (a fixed cost of tens of microseconds) plus O(trees x depth + horizon) a
// row: predict_rows rather than predict for many actions.

#include <memory>
#include <string>
#include <vector>

#include "ontime/learn/conditional_model.hpp"

namespace ontime {

// The settings of a fit (ConditionalFitOptions' fields of the same names).
struct BoostedSettings {
  int trees = 100;
  int depth = 3;
  double learning_rate = 0.3;
  double min_child_weight = 1;
  std::string aft_distribution = "normal";  // normal, logistic or extreme
  double aft_scale = 1;
};

struct BoostedParameters {
  BoostedSettings settings;
  int planning_unit = 1;       // u: steps, the median step of the found rows (1 without any)
  double execution_sigma = 1;  // sigma > 0
  double log_likelihood = 0;   // planning, per row, after the last round
};

class BoostedTimeModel final : public ConditionalTimeModel {
 public:
  // XGBoost's boosters (never, planning, execution), opaque outside the library.
  struct Boosters;

  // The kind's name in model files and options: "boosted".
  static const std::string& kind_name();
  // A model from its parts: what fit computes, or the model file's reader reads back. `rows` and `worlds`
  // count the training data's rows and worlds.
  BoostedTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon, std::size_t rows,
                   std::size_t worlds, BoostedParameters parameters, std::unique_ptr<Boosters> boosters);
  // Frees the boosters (defined where XGBoost's handles are known).
  ~BoostedTimeModel() override;
  BoostedTimeModel(const BoostedTimeModel&) = delete;
  BoostedTimeModel& operator=(const BoostedTimeModel&) = delete;

  // Throws UsageError for settings out of range, data without features, or a failure of XGBoost
  // (its message).
  static std::unique_ptr<BoostedTimeModel> fit(const ConditionalData& data, std::vector<std::string> feature_names,
                                               Steps horizon, const BoostedSettings& settings);

  // The kind, kind_name(): "boosted".
  const std::string& kind() const noexcept override { return kind_name(); }
  // The fit's settings, the planning unit u, the execution's sigma and the fit's log-likelihood.
  const BoostedParameters& parameters() const noexcept { return parameters_; }

 private:
  PredictedTimes predict_checked(std::span<const double> features) const override;
  std::vector<PredictedTimes> predict_rows_checked(std::span<const double> rows, std::size_t count) const override;
  std::string parameters_json() const override;

  BoostedParameters parameters_;
  std::unique_ptr<Boosters> boosters_;
};

}  // namespace ontime
