#include "ontime/learn/online_update.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {

PlanningPosterior::PlanningPosterior(const Distribution& prior, Steps horizon, double strength)
    : PlanningPosterior(prior, Distribution{}, horizon, strength) {}

PlanningPosterior::PlanningPosterior(const Distribution& planning, const Distribution& backtrack, Steps horizon,
                                     double strength)
    : strength_(strength) {
  if (horizon < 1 || horizon > Distribution::kMaxStep) {
    throw UsageError("the horizon must be between 1 and " + std::to_string(Distribution::kMaxStep) + " steps");
  }
  if (!(std::isfinite(strength) && strength > 0)) throw UsageError("the prior's strength must be a positive number");
  if (backtrack.pmf(0) > 0) throw UsageError("backtrack steps start at 1");
  if ((1.0 - planning.never()) + (1.0 - backtrack.never()) > 1.0 + Distribution::kSumTolerance) {
    throw UsageError("planning and backtrack probabilities sum above 1");
  }
  const auto H = static_cast<std::size_t>(horizon);
  alpha_.assign(H + 1, 0.0);
  back_.assign(H + 1, 0.0);
  beta_.assign(H + 1, 0.0);
  for (std::size_t t = 1; t <= H; ++t) {
    const auto step = static_cast<Steps>(t);
    alpha_[t] = strength * planning.pmf(step);
    back_[t] = strength * backtrack.pmf(step);
    // S(t) = P(T > t) - (backtrack mass up to t): the planning survival itself without backtracking.
    beta_[t] = strength * std::max(0.0, planning.survival(step) - backtrack.cdf(step));
  }
}

double PlanningPosterior::hazard(std::size_t t) const noexcept {
  const double total = alpha_[t] + back_[t] + beta_[t];
  return total > 0 ? alpha_[t] / total : 0.0;
}

double PlanningPosterior::backtrack_hazard(std::size_t t) const noexcept {
  const double total = alpha_[t] + back_[t] + beta_[t];
  return total > 0 ? back_[t] / total : 0.0;
}

void PlanningPosterior::observe_end(std::vector<double>& ends, Steps t) {
  const auto H = static_cast<std::size_t>(horizon());
  if (static_cast<std::size_t>(t) > H) {
    observe_cut_off(horizon());
    return;
  }
  const auto at = static_cast<std::size_t>(t);
  ends[at] += 1;
  for (std::size_t u = 1; u < at; ++u) beta_[u] += 1;
  ++observations_;
}

void PlanningPosterior::observe_found(Steps t) {
  if (t < 1) throw UsageError("a motion is found after at least 1 step");
  observe_end(alpha_, t);
}

void PlanningPosterior::observe_backtrack(Steps t) {
  if (t < 1) throw UsageError("an attempt backtracks after at least 1 step");
  observe_end(back_, t);
}

void PlanningPosterior::observe_cut_off(Steps c) {
  if (c < 0) throw UsageError("an attempt is cut off after 0 or more steps");
  const std::size_t last = std::min(static_cast<std::size_t>(c), static_cast<std::size_t>(horizon()));
  for (std::size_t u = 1; u <= last; ++u) beta_[u] += 1;
  ++observations_;
}

Distribution PlanningPosterior::mean_of(bool backtrack) const {
  const auto H = static_cast<std::size_t>(horizon());
  std::vector<double> masses(H + 1, 0.0);
  double alive = 1;
  for (std::size_t t = 1; t <= H; ++t) {
    const double found = alive * hazard(t);
    const double back = alive * backtrack_hazard(t);
    masses[t] = backtrack ? back : found;
    alive -= found + back;
  }
  return Distribution::from_pmf(std::move(masses));
}

Distribution PlanningPosterior::mean() const { return mean_of(false); }

Distribution PlanningPosterior::backtrack_mean() const { return mean_of(true); }

double PlanningPosterior::at_risk(std::size_t t) const noexcept {
  double alive = 1;
  for (std::size_t u = 1; u < t; ++u) alive *= 1 - hazard(u) - backtrack_hazard(u);
  return alive;
}

double PlanningPosterior::predictive_found(Steps t) const {
  if (t < 1 || t > horizon()) return 0.0;
  return at_risk(static_cast<std::size_t>(t)) * hazard(static_cast<std::size_t>(t));
}

double PlanningPosterior::predictive_backtrack(Steps t) const {
  if (t < 1 || t > horizon()) return 0.0;
  return at_risk(static_cast<std::size_t>(t)) * backtrack_hazard(static_cast<std::size_t>(t));
}

double PlanningPosterior::predictive_cut_off(Steps c) const {
  const std::size_t last =
      std::min(static_cast<std::size_t>(std::max<Steps>(c, 0)), static_cast<std::size_t>(horizon()));
  return at_risk(last + 1);
}

}  // namespace ontime
