#pragma once
// The online update of one action's planning-time distribution in a world being refined: a
// prediction (a conditional time model's, or any instance's) as the prior, every attempt the
// robot makes (found after t steps, or not found after c) as data, the posterior mean as the
// distribution the allocators plan with (docs/learning.md, "Online update").
//
// Computes the discrete-time beta-Stacy posterior (Walker and Muliere 1997): the hazards
// h(t) = P(T = t | T >= t), t = 1..H, are independent Beta(a_t, b_t) with a_t = s p(t) and
// b_t = s P(T > t) under the prior p (so their means are the prior's hazards) and strength s, the
// prior's worth in attempts. A found attempt at t adds 1 to a_t and to b_u for u < t; an attempt
// cut off after c steps adds 1 to b_u for u <= c. The posterior mean PMF is
// p(t) = E h(t) prod_{u<t} (1 - E h(u)); the mass beyond H is "never". Guarantees: conjugate for
// right-censored data (the order of the attempts does not matter); with no data it is the prior;
// as attempts grow it tends to the Kaplan-Meier estimate of the action's own attempts. A hazard
// with a_t + b_t = 0 (no prior mass left and no attempt at risk) is 0. Cost: O(t) per
// observation (no allocation), O(H) for the posterior or a predictive probability.

#include <span>
#include <vector>

#include "ontime/model/distribution.hpp"

namespace ontime {

class PlanningPosterior {
 public:
  // `prior` over 1..horizon (mass at later steps counts as "never"); strength s > 0. Throws
  // UsageError for a horizon out of 1..Distribution::kMaxStep or a strength that is not positive
  // and finite.
  PlanningPosterior(const Distribution& prior, Steps horizon, double strength);

  // Found after t >= 1 steps (t beyond the horizon: cut off at the horizon).
  void observe_found(Steps t);
  // Cut off after c >= 0 steps without a motion (c beyond the horizon: the horizon).
  void observe_cut_off(Steps c);

  // The posterior mean: over 1..horizon, the rest "never".
  Distribution mean() const;
  // The posterior predictive probability of one attempt's outcome, before it is observed: found
  // at t (P(T = t)) or cut off after c (P(T > c)).
  double predictive_found(Steps t) const;
  double predictive_cut_off(Steps c) const;

  // H: the last step of the posterior; later steps are "never".
  Steps horizon() const noexcept { return static_cast<Steps>(alpha_.size()) - 1; }
  // s: the prior's worth in attempts.
  double strength() const noexcept { return strength_; }
  // Attempts observed so far, found or cut off.
  std::size_t observations() const noexcept { return observations_; }

 private:
  double hazard(std::size_t t) const noexcept;
  std::vector<double> alpha_, beta_;  // index t = 1..H (0 unused)
  double strength_;
  std::size_t observations_ = 0;
};

}  // namespace ontime
