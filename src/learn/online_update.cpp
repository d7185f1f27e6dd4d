#include "ontime/learn/online_update.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {

PlanningPosterior::PlanningPosterior(const Distribution& prior, Steps horizon, double strength) : strength_(strength) {
  if (horizon < 1 || horizon > Distribution::kMaxStep) {
    throw UsageError("the horizon must be between 1 and " + std::to_string(Distribution::kMaxStep) + " steps");
  }
  if (!(std::isfinite(strength) && strength > 0)) throw UsageError("the prior's strength must be a positive number");
  const auto H = static_cast<std::size_t>(horizon);
  alpha_.assign(H + 1, 0.0);
  beta_.assign(H + 1, 0.0);
  for (std::size_t t = 1; t <= H; ++t) {
    alpha_[t] = strength * prior.pmf(static_cast<Steps>(t));
    beta_[t] = strength * prior.survival(static_cast<Steps>(t));
  }
}

double PlanningPosterior::hazard(std::size_t t) const noexcept {
  const double total = alpha_[t] + beta_[t];
  return total > 0 ? alpha_[t] / total : 0.0;
}

void PlanningPosterior::observe_found(Steps t) {
  if (t < 1) throw UsageError("a motion is found after at least 1 step");
  const auto H = static_cast<std::size_t>(horizon());
  if (static_cast<std::size_t>(t) > H) {
    observe_cut_off(horizon());
    return;
  }
  const auto at = static_cast<std::size_t>(t);
  alpha_[at] += 1;
  for (std::size_t u = 1; u < at; ++u) beta_[u] += 1;
  ++observations_;
}

void PlanningPosterior::observe_cut_off(Steps c) {
  if (c < 0) throw UsageError("an attempt is cut off after 0 or more steps");
  const std::size_t last = std::min(static_cast<std::size_t>(c), static_cast<std::size_t>(horizon()));
  for (std::size_t u = 1; u <= last; ++u) beta_[u] += 1;
  ++observations_;
}

Distribution PlanningPosterior::mean() const {
  const auto H = static_cast<std::size_t>(horizon());
  std::vector<double> masses(H + 1, 0.0);
  double alive = 1;
  for (std::size_t t = 1; t <= H; ++t) {
    masses[t] = alive * hazard(t);
    alive -= masses[t];
  }
  return Distribution::from_pmf(std::move(masses));
}

double PlanningPosterior::predictive_found(Steps t) const {
  if (t < 1 || t > horizon()) return 0.0;
  double alive = 1;
  for (std::size_t u = 1; u < static_cast<std::size_t>(t); ++u) alive *= 1 - hazard(u);
  return alive * hazard(static_cast<std::size_t>(t));
}

double PlanningPosterior::predictive_cut_off(Steps c) const {
  double alive = 1;
  const std::size_t last =
      std::min(static_cast<std::size_t>(std::max<Steps>(c, 0)), static_cast<std::size_t>(horizon()));
  for (std::size_t u = 1; u <= last; ++u) alive *= 1 - hazard(u);
  return alive;
}

}  // namespace ontime
