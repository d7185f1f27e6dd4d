#pragma once
// The online update of one action's attempt distributions in a world being refined: a prediction
// (a conditional time model's, or any instance's) as the prior, every attempt the robot makes
// (found after t steps, backtracked after t, or cut off after c without either) as data, the
// posterior mean as the distributions the allocators plan with (docs/learning.md, "Online
// update").
//
// Computes the discrete-time beta-Stacy posterior (Walker and Muliere 1997) generalised to the two
// competing ends of an attempt of SPEC §7 (a motion, or a backtrack). At each step t = 1..H an
// attempt still at risk is found, backtracks or continues, with probabilities (h(t), g(t),
// 1 - h(t) - g(t)): the cause-specific hazards. A priori the steps are independent,
// (h(t), g(t), 1 - h(t) - g(t)) ~ Dirichlet(a_t, b_t, c_t) with a_t = s p(t), b_t = s q(t) and
// c_t = s S(t), S(t) = 1 - sum_{u<=t} (p(u) + q(u)), under the prior's planning PMF p and
// backtrack PMF q (so their means are the prior's cause-specific hazards) and strength s, the
// prior's worth in attempts. A found attempt at t adds 1 to a_t, a backtrack at t adds 1 to b_t,
// and either adds 1 to c_u for u < t; an attempt cut off after c steps adds 1 to c_u for u <= c.
// The posterior means are p(t) = E h(t) W(t - 1) and q(t) = E g(t) W(t - 1), with
// W(t) = prod_{u<=t} (1 - E h(u) - E g(u)); the mass of neither beyond H is "never". Without
// backtracking (q all "never": every b_t = 0) it is the beta-Stacy posterior of the planning time
// alone, Beta(a_t, c_t) hazards, computed with the same operations in the same order.
//
// Guarantees: conjugate for right-censored data (every step's Dirichlet stays one, so the order of
// the attempts does not matter); with no data it is the prior (up to rounding); p and q sum to at
// most 1 by construction (their sum is 1 - W(H)), so an instance takes them; as attempts grow it
// tends to the Aalen-Johansen estimate of the action's own attempts (estimate_attempts of
// fitting.hpp; without backtracks the Kaplan-Meier estimate): with n_t attempts at risk at t, each
// hazard is within s / n_t of the estimate's. A step whose a_t + b_t + c_t = 0 (no prior mass
// left and no attempt at risk) has hazards 0. Cost: O(t) per observation (no allocation), O(H)
// for the posterior means or a predictive probability.

#include <span>
#include <vector>

#include "ontime/model/distribution.hpp"

namespace ontime {

class PlanningPosterior {
 public:
  // `prior` over 1..horizon (mass at later steps counts as "never"), no backtracking; strength
  // s > 0. Throws UsageError for a horizon out of 1..Distribution::kMaxStep or a strength that is
  // not positive and finite.
  PlanningPosterior(const Distribution& prior, Steps horizon, double strength);
  // With backtracking (SPEC §7): the prior's planning PMF and backtrack PMF (their masses summing
  // to at most 1), both over 1..horizon. Throws UsageError as above, or for backtrack mass at
  // step 0 or masses summing above 1 (beyond Distribution::kSumTolerance).
  PlanningPosterior(const Distribution& planning, const Distribution& backtrack, Steps horizon, double strength);

  // Found after t >= 1 steps (t beyond the horizon: cut off at the horizon).
  void observe_found(Steps t);
  // Backtracked after t >= 1 steps (t beyond the horizon: cut off at the horizon).
  void observe_backtrack(Steps t);
  // Cut off after c >= 0 steps without a motion or a backtrack (c beyond the horizon: the horizon).
  void observe_cut_off(Steps c);

  // The posterior mean of the planning PMF: over 1..horizon, the rest "never".
  Distribution mean() const;
  // The posterior mean of the backtrack PMF: over 1..horizon, the rest "never" (all "never" while
  // neither the prior nor an attempt backtracked).
  Distribution backtrack_mean() const;
  // The posterior predictive probability of one attempt's outcome, before it is observed: found
  // at t (P(T = t, found)), backtracked at t, or cut off after c (neither within c steps).
  double predictive_found(Steps t) const;
  double predictive_backtrack(Steps t) const;
  double predictive_cut_off(Steps c) const;

  // H: the last step of the posterior; later steps are "never".
  Steps horizon() const noexcept { return static_cast<Steps>(alpha_.size()) - 1; }
  // s: the prior's worth in attempts.
  double strength() const noexcept { return strength_; }
  // Attempts observed so far, found, backtracked or cut off.
  std::size_t observations() const noexcept { return observations_; }

 private:
  // The posterior mean hazard of a motion at step t, and of a backtrack.
  double hazard(std::size_t t) const noexcept;
  double backtrack_hazard(std::size_t t) const noexcept;
  // One attempt that ended at step t >= 1 (found: `ends` is alpha_; backtracked: back_).
  void observe_end(std::vector<double>& ends, Steps t);
  // W(t - 1): the posterior mean chance that an attempt is still at risk at step t.
  double at_risk(std::size_t t) const noexcept;
  // The posterior mean of the planning PMF, or of the backtrack PMF.
  Distribution mean_of(bool backtrack) const;

  // Index t = 1..H (0 unused): a_t (found), b_t (backtrack), c_t (continue).
  std::vector<double> alpha_, back_, beta_;
  double strength_;
  std::size_t observations_ = 0;
};

}  // namespace ontime
