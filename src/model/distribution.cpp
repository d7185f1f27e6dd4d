#include "ontime/model/distribution.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {

Distribution::Distribution() { finish(); }

Distribution Distribution::from_pmf(std::vector<double> masses) {
  if (masses.size() > static_cast<std::size_t>(kMaxStep) + 1) {
    throw UsageError("distribution lists steps beyond " + std::to_string(kMaxStep));
  }
  double total = 0;
  for (const double mass : masses) {
    // NaN named as such (std::to_string writes "-nan" or "nan" by its sign bit).
    if (std::isnan(mass)) throw UsageError("a probability is not a number (NaN)");
    if (!(mass >= 0.0 && mass <= 1.0)) {
      throw UsageError("probability outside [0, 1]: " + std::to_string(mass));
    }
    total += mass;
  }
  if (total > 1.0 + kSumTolerance) {
    throw UsageError("probabilities sum to " + std::to_string(total) + " > 1");
  }
  Distribution distribution;
  distribution.masses_ = std::move(masses);
  distribution.finish();
  return distribution;
}

Distribution Distribution::from_cdf(const std::vector<double>& cumulative) {
  std::vector<double> masses(cumulative.size(), 0.0);
  double previous = 0;
  for (std::size_t t = 0; t < cumulative.size(); ++t) {
    const double value = cumulative[t];
    if (!(value >= 0.0 && value <= 1.0 + kSumTolerance) || value < previous) {
      throw UsageError("a CDF must be non-decreasing within [0, 1]");
    }
    masses[t] = value - previous;
    previous = value;
  }
  return from_pmf(std::move(masses));
}

void Distribution::finish() {
  while (!masses_.empty() && masses_.back() == 0.0) masses_.pop_back();
  const std::size_t size = masses_.size();
  cumulative_.assign(size, 0.0);
  tail_.assign(size + 1, 0.0);
  double running = 0;
  for (std::size_t t = 0; t < size; ++t) {
    running += masses_[t];
    cumulative_[t] = running;
  }
  // Summed from the end so that small survivals (deep in a tail) keep their precision.
  for (std::size_t t = size; t-- > 0;) tail_[t] = tail_[t + 1] + masses_[t];
  never_ = std::max(0.0, 1.0 - (size > 0 ? tail_[0] : 0.0));
  min_step_ = kNever;
  max_step_ = kNever;
  for (std::size_t t = 0; t < size; ++t) {
    if (masses_[t] > 0.0) {
      if (min_step_ == kNever) min_step_ = static_cast<Steps>(t);
      max_step_ = static_cast<Steps>(t);
    }
  }
}

double Distribution::pmf(Steps t) const noexcept {
  return t >= 0 && static_cast<std::size_t>(t) < masses_.size() ? masses_[static_cast<std::size_t>(t)] : 0.0;
}

double Distribution::cdf(Steps t) const noexcept {
  if (t < 0 || masses_.empty()) return 0.0;
  return cumulative_[std::min(static_cast<std::size_t>(t), masses_.size() - 1)];
}

double Distribution::survival(Steps t) const noexcept {
  if (t < 0) return 1.0;
  const std::size_t next = static_cast<std::size_t>(t) + 1;
  return never_ + (next < tail_.size() ? tail_[next] : 0.0);
}

double Distribution::hazard(Steps spent) const noexcept {
  const double remaining = survival(spent);
  if (remaining <= 0.0) return 0.0;
  return std::min(1.0, pmf(spent + 1) / remaining);
}

Distribution Distribution::conditioned(Steps spent) const {
  const double remaining = survival(spent);
  if (spent < 0 || remaining <= 0.0) return Distribution{};
  std::vector<double> masses;
  const auto first = static_cast<std::size_t>(spent);
  if (masses_.size() > first) {
    masses.assign(masses_.begin() + static_cast<std::ptrdiff_t>(first), masses_.end());
    masses[0] = 0.0;  // T - spent >= 1 given T > spent
    for (double& mass : masses) mass /= remaining;
  }
  Distribution result;
  result.masses_ = std::move(masses);
  result.finish();
  return result;
}

double Distribution::mean_finite() const noexcept {
  double weighted = 0, total = 0;
  for (std::size_t t = 0; t < masses_.size(); ++t) {
    weighted += static_cast<double>(t) * masses_[t];
    total += masses_[t];
  }
  return total > 0 ? weighted / total : std::numeric_limits<double>::infinity();
}

Steps Distribution::quantile(double u) const noexcept {
  const auto found = std::upper_bound(cumulative_.begin(), cumulative_.end(), u);
  if (found == cumulative_.end()) return kNever;
  return static_cast<Steps>(found - cumulative_.begin());
}

}  // namespace ontime
