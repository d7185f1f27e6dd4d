#pragma once
// A distribution over whole time steps with a "never" remainder.
//
// The planning time of an action (steps of refinement effort until a motion is found,
// t >= 1) and its execution time (steps the robot needs, x >= 0) are both Distributions.
// Probability mass that the listed steps do not cover is "never": the action cannot be
// refined, or its motion cannot be executed, before any deadline (SPEC §1).

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "ontime/util/random.hpp"

namespace ontime {

// A number of time steps. `kNever` stands for the "never" outcome.
using Steps = std::int32_t;
inline constexpr Steps kNever = std::numeric_limits<Steps>::max();

class Distribution {
 public:
  // The largest step a distribution may list. Keeps dense tables bounded.
  static constexpr Steps kMaxStep = 100'000;
  // Slack allowed when checking that probabilities sum to at most 1.
  static constexpr double kSumTolerance = 1e-9;

  // All mass on "never".
  Distribution();

  // masses[t] is the probability of exactly t steps. Throws UsageError when a
  // mass is negative, NaN or above 1, when they sum above 1 + kSumTolerance, or when the
  // table is longer than kMaxStep + 1. Input files are validated before this with the
  // place of each error; this check guards programmatic use.
  static Distribution from_pmf(std::vector<double> masses);

  // cumulative[t] is P(T <= t). Throws UsageError when it decreases or leaves [0, 1].
  static Distribution from_cdf(const std::vector<double>& cumulative);

  // P(T = t); 0 outside the listed steps (the "never" mass is never()).
  double pmf(Steps t) const noexcept;
  double cdf(Steps t) const noexcept;       // P(T <= t)
  double survival(Steps t) const noexcept;  // P(T > t), "never" included
  // The "never" mass, 1 minus the listed steps' mass.
  double never() const noexcept { return never_; }

  // P(T = spent + 1 | T > spent): the chance that one more step finishes, after `spent`
  // steps that did not. Zero when nothing is left (survival 0).
  double hazard(Steps spent) const noexcept;

  // The law of T - spent given T > spent (the planning time still to go after `spent`
  // unsuccessful steps). Requires survival(spent) > 0; otherwise all mass is "never".
  Distribution conditioned(Steps spent) const;

  // Smallest and largest step with positive mass; kNever when there is none.
  Steps min_step() const noexcept { return min_step_; }
  Steps max_step() const noexcept { return max_step_; }

  // E[T | T finite]: the mean over the listed, finite support; +infinity if there is none.
  double mean_finite() const noexcept;

  // The step for a uniform u in [0, 1): the smallest t with cdf(t) > u, or kNever.
  Steps quantile(double u) const noexcept;

  template <class Generator>
  // A step drawn from the distribution with `generator`: quantile of a uniform draw, or kNever.
  Steps sample(Generator& generator) const {
    return quantile(uniform01(generator));
  }

  // masses()[t] = pmf(t) for t < masses().size(); zero beyond.
  std::span<const double> masses() const noexcept { return masses_; }

  friend bool operator==(const Distribution&, const Distribution&) = default;

 private:
  void finish();

  std::vector<double> masses_;
  std::vector<double> cumulative_;  // cumulative_[t] = P(T <= t)
  std::vector<double> tail_;        // tail_[t] = P(t <= T < infinity), summed from the end
  double never_ = 1.0;
  Steps min_step_ = kNever;
  Steps max_step_ = kNever;
};

}  // namespace ontime
