#include "ontime/learn/online_update.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "ontime/learn/fitting.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {
namespace {

// Prior p(1) = 1/2, p(2) = 1/4, never 1/4, horizon 2, strength 2: a = (1, 1/2), b = (1, 1/2).
Distribution prior() { return Distribution::from_pmf({0.0, 0.5, 0.25}); }

TEST(PlanningPosterior, WithoutDataIsThePrior) {
  const PlanningPosterior posterior(prior(), 2, 2.0);
  const Distribution mean = posterior.mean();
  EXPECT_DOUBLE_EQ(mean.pmf(1), 0.5);
  EXPECT_DOUBLE_EQ(mean.pmf(2), 0.25);
  EXPECT_DOUBLE_EQ(mean.never(), 0.25);
  EXPECT_DOUBLE_EQ(posterior.predictive_cut_off(1), 0.5);
}

// Hand-computed: found at 2 makes a = (1, 3/2), b = (2, 1/2): hazards 1/3 and 3/4, so p(1) = 1/3,
// p(2) = 2/3 x 3/4 = 1/2, never 1/6. Then cut off after 1 step: b1 = 3, hazard 1/4, p(1) = 1/4,
// p(2) = 3/4 x 3/4 = 9/16, never 3/16.
TEST(PlanningPosterior, FoundAndCutOffAttemptsMoveTheHazardsAsTheAlgebraSays) {
  PlanningPosterior posterior(prior(), 2, 2.0);
  EXPECT_DOUBLE_EQ(posterior.predictive_found(2), 0.25);
  posterior.observe_found(2);
  Distribution mean = posterior.mean();
  EXPECT_DOUBLE_EQ(mean.pmf(1), 1.0 / 3);
  EXPECT_DOUBLE_EQ(mean.pmf(2), 0.5);
  EXPECT_NEAR(mean.never(), 1.0 / 6, 1e-15);
  EXPECT_DOUBLE_EQ(posterior.predictive_cut_off(1), 2.0 / 3);
  posterior.observe_cut_off(1);
  mean = posterior.mean();
  EXPECT_DOUBLE_EQ(mean.pmf(1), 0.25);
  EXPECT_DOUBLE_EQ(mean.pmf(2), 9.0 / 16);
  EXPECT_NEAR(mean.never(), 3.0 / 16, 1e-15);
  EXPECT_EQ(posterior.observations(), 2u);
  // Beyond the horizon: a found attempt counts as cut off at the horizon.
  PlanningPosterior late(prior(), 2, 2.0), cut(prior(), 2, 2.0);
  late.observe_found(7);
  cut.observe_cut_off(2);
  EXPECT_EQ(late.mean(), cut.mean());
}

// Conjugate: the order of the attempts does not matter.
TEST(PlanningPosterior, TheOrderOfTheAttemptsDoesNotMatter) {
  PlanningPosterior one(prior(), 2, 3.0), other(prior(), 2, 3.0);
  one.observe_found(1);
  one.observe_cut_off(2);
  one.observe_found(2);
  other.observe_found(2);
  other.observe_found(1);
  other.observe_cut_off(2);
  EXPECT_EQ(one.mean(), other.mean());
}

// Many attempts of the action itself outweigh a wrong prior: the posterior tends to their
// Kaplan-Meier estimate. The prior weighs one attempt; at least about 2,000 attempts are at risk at
// every step, so no hazard moves by more than about 1/2,000 from the estimate's.
TEST(PlanningPosterior, ManyAttemptsGiveTheirKaplanMeierEstimate) {
  PlanningPosterior posterior(Distribution::from_pmf({0.0, 0.0, 0.0, 0.0, 0.9}), 4, 1.0);
  PlanningSample sample;
  SplitMix64 random(3);
  for (int i = 0; i < 20000; ++i) {
    const Steps found = 1 + static_cast<Steps>(uniform01(random) * 6);  // 5, 6: not within the horizon
    const Steps cut = static_cast<Steps>(uniform01(random) * 5);
    if (found <= cut && found <= 4) {
      posterior.observe_found(found);
      sample.found.push_back(found);
    } else {
      posterior.observe_cut_off(std::min<Steps>(cut, 4));
      sample.censored.push_back(std::min<Steps>(cut, 4));
    }
  }
  const Distribution km = estimate_planning(sample, 4);
  const Distribution mean = posterior.mean();
  for (Steps t = 1; t <= 4; ++t) EXPECT_NEAR(mean.pmf(t), km.pmf(t), 1e-3) << t;
}

// Backtracking (SPEC §7): planning p(1) = 1/4, p(2) = 1/4 and backtrack q(1) = 1/4, q(2) = 1/8,
// never 1/8; horizon 2, strength 4: a = (1, 1), b = (1, 1/2), c = (4 S(1), 4 S(2)) = (2, 1/2).
Distribution planning_prior() { return Distribution::from_pmf({0.0, 0.25, 0.25}); }
Distribution backtrack_prior() { return Distribution::from_pmf({0.0, 0.25, 0.125}); }

TEST(PlanningPosterior, WithBacktrackingAndWithoutDataBothDistributionsAreThePrior) {
  const PlanningPosterior posterior(planning_prior(), backtrack_prior(), 2, 4.0);
  const Distribution planning = posterior.mean(), backtrack = posterior.backtrack_mean();
  for (Steps t = 1; t <= 2; ++t) {
    EXPECT_NEAR(planning.pmf(t), planning_prior().pmf(t), 1e-12) << t;
    EXPECT_NEAR(backtrack.pmf(t), backtrack_prior().pmf(t), 1e-12) << t;
  }
  EXPECT_NEAR(posterior.predictive_backtrack(2), 0.125, 1e-12);
  EXPECT_NEAR(posterior.predictive_cut_off(2), 0.125, 1e-12);
  // A shipped example's backtracking action (data/instances/kitchen-grasps.json, move+place(B1,S):
  // found at 5 with 0.001, backtracking at 1 and 2 with the rest) over its deadline of 40 steps.
  const Distribution found = Distribution::from_pmf({0, 0, 0, 0, 0, 0.001});
  const Distribution back = Distribution::from_pmf({0, 0.978, 0.021});
  const PlanningPosterior kitchen(found, back, 40, 10.0);
  for (Steps t = 1; t <= 40; ++t) {
    EXPECT_NEAR(kitchen.mean().pmf(t), found.pmf(t), 1e-12) << t;
    EXPECT_NEAR(kitchen.backtrack_mean().pmf(t), back.pmf(t), 1e-12) << t;
  }
}

// Hand-computed. A backtrack at 2 makes b_2 = 3/2 and c_1 = 3: step 1 has hazards 1/5 (found) and
// 1/5 (backtrack) of a total of 5, step 2 hazards 1/3 and 1/2 of 3, so p = (1/5, 3/5 x 1/3 = 1/5),
// q = (1/5, 3/5 x 1/2 = 3/10), never 3/5 x 1/6 = 1/10. Found at 1 then makes a_1 = 2 (total 6):
// p = (1/3, 1/2 x 1/3 = 1/6), q = (1/6, 1/4), never 1/12. Cut off after 1 then makes c_1 = 4
// (total 7): p = (2/7, 4/7 x 1/3 = 4/21), q = (1/7, 2/7), never 2/21.
TEST(PlanningPosterior, BacktrackedFoundAndCutOffAttemptsMoveBothHazardsAsTheAlgebraSays) {
  PlanningPosterior posterior(planning_prior(), backtrack_prior(), 2, 4.0);
  posterior.observe_backtrack(2);
  Distribution p = posterior.mean(), q = posterior.backtrack_mean();
  EXPECT_DOUBLE_EQ(p.pmf(1), 1.0 / 5);
  EXPECT_DOUBLE_EQ(p.pmf(2), 1.0 / 5);
  EXPECT_DOUBLE_EQ(q.pmf(1), 1.0 / 5);
  EXPECT_DOUBLE_EQ(q.pmf(2), 3.0 / 10);
  EXPECT_NEAR(posterior.predictive_cut_off(2), 1.0 / 10, 1e-15);
  EXPECT_DOUBLE_EQ(posterior.predictive_found(1), 1.0 / 5);
  posterior.observe_found(1);
  p = posterior.mean();
  q = posterior.backtrack_mean();
  EXPECT_DOUBLE_EQ(p.pmf(1), 1.0 / 3);
  EXPECT_DOUBLE_EQ(p.pmf(2), 1.0 / 6);
  EXPECT_DOUBLE_EQ(q.pmf(1), 1.0 / 6);
  EXPECT_DOUBLE_EQ(q.pmf(2), 1.0 / 4);
  EXPECT_NEAR(posterior.predictive_cut_off(2), 1.0 / 12, 1e-15);
  posterior.observe_cut_off(1);
  p = posterior.mean();
  q = posterior.backtrack_mean();
  EXPECT_DOUBLE_EQ(p.pmf(1), 2.0 / 7);
  EXPECT_DOUBLE_EQ(p.pmf(2), 4.0 / 21);
  EXPECT_DOUBLE_EQ(q.pmf(1), 1.0 / 7);
  EXPECT_DOUBLE_EQ(q.pmf(2), 2.0 / 7);
  EXPECT_DOUBLE_EQ(posterior.predictive_backtrack(2), 2.0 / 7);
  EXPECT_NEAR(posterior.predictive_cut_off(2), 2.0 / 21, 1e-15);
  EXPECT_EQ(posterior.observations(), 3u);
  // Beyond the horizon a backtrack is an attempt cut off at the horizon.
  PlanningPosterior late(planning_prior(), backtrack_prior(), 2, 4.0), cut(planning_prior(), backtrack_prior(), 2, 4.0);
  late.observe_backtrack(3);
  cut.observe_cut_off(2);
  EXPECT_EQ(late.mean(), cut.mean());
  EXPECT_EQ(late.backtrack_mean(), cut.backtrack_mean());
}

// Without backtracking the competing-risk posterior is the beta-Stacy posterior of the planning
// time alone, to the bit.
TEST(PlanningPosterior, ABacktrackPriorThatNeverBacktracksChangesNothing) {
  PlanningPosterior alone(prior(), 2, 2.0), competing(prior(), Distribution{}, 2, 2.0);
  for (PlanningPosterior* posterior : {&alone, &competing}) {
    posterior->observe_found(2);
    posterior->observe_cut_off(1);
    posterior->observe_found(1);
  }
  EXPECT_EQ(alone.mean(), competing.mean());
  EXPECT_EQ(competing.backtrack_mean(), Distribution{});
  EXPECT_EQ(alone.predictive_found(2), competing.predictive_found(2));
  EXPECT_EQ(alone.predictive_cut_off(1), competing.predictive_cut_off(1));
}

// Conjugate: every order of found, backtracked and cut-off attempts gives the same posterior, to the
// bit (each count of the posterior is its prior value plus the same ones, whatever their order).
TEST(PlanningPosterior, WithBacktrackingTheOrderOfTheAttemptsDoesNotMatter) {
  enum Kind { found, backtracked, cut_off };
  struct Observation {
    Kind kind;
    Steps steps;
    bool operator<(const Observation& other) const {
      return kind != other.kind ? kind < other.kind : steps < other.steps;
    }
  };
  std::array<Observation, 6> attempts{
      {{found, 1}, {found, 2}, {backtracked, 1}, {backtracked, 2}, {cut_off, 1}, {cut_off, 0}}};
  std::sort(attempts.begin(), attempts.end());
  const auto posterior_of = [](const std::array<Observation, 6>& order) {
    PlanningPosterior posterior(planning_prior(), backtrack_prior(), 2, 3.0);
    for (const Observation& o : order) {
      if (o.kind == found) posterior.observe_found(o.steps);
      if (o.kind == backtracked) posterior.observe_backtrack(o.steps);
      if (o.kind == cut_off) posterior.observe_cut_off(o.steps);
    }
    return posterior;
  };
  const PlanningPosterior first = posterior_of(attempts);
  int orders = 0;
  do {
    const PlanningPosterior other = posterior_of(attempts);
    ASSERT_EQ(other.mean(), first.mean());
    ASSERT_EQ(other.backtrack_mean(), first.backtrack_mean());
    ++orders;
  } while (std::next_permutation(attempts.begin(), attempts.end()));
  EXPECT_EQ(orders, 720);
  EXPECT_EQ(first.observations(), 6u);
}

// As the attempts grow the posterior tends to their Aalen-Johansen estimate (estimate_attempts):
// with k copies of a sample whose steps 1..H each have n_t attempts at risk, every hazard of the
// posterior is within s / (k n_t) of the estimate's (|(k d + s p) / (k n + s S) - d / n| <= s / (k n)
// for p <= S, d <= n), and a PMF, a hazard times a product of 1 - h - g, is then within
// sum_t 2 s / (k n_t) of the estimate's (products of numbers in [0, 1] differ by at most the sum of
// their differences). The bound is met, and the error falls as k grows.
TEST(PlanningPosterior, ManyAttemptsWithBacktracksGiveTheirAalenJohansenEstimate) {
  constexpr Steps kHorizon = 4;
  constexpr double kStrength = 3.0;
  // A prior far from the sample: found at 4 only, backtracking at 1.
  const Distribution found_prior = Distribution::from_pmf({0, 0, 0, 0, 0.5});
  const Distribution back_prior = Distribution::from_pmf({0, 0.4});
  // The sample: found at 1, 1, 2, 3; backtracked at 1, 2, 2; cut off after 0, 2, 4 (at risk at
  // every step: n = (9, 6, 2, 1)).
  PlanningSample sample;
  sample.found = {1, 1, 2, 3};
  sample.backtracked = {1, 2, 2};
  sample.blamed = {"c", "c", "c"};
  sample.censored = {0, 2, 4};
  const std::array<double, kHorizon> at_risk{9, 6, 2, 1};
  const AttemptEstimate estimate = estimate_attempts(sample, kHorizon);
  double previous = 1;
  for (const int copies : {1, 10, 100, 1000}) {
    PlanningPosterior posterior(found_prior, back_prior, kHorizon, kStrength);
    for (int copy = 0; copy < copies; ++copy) {
      for (const Steps t : sample.found) posterior.observe_found(t);
      for (const Steps t : sample.backtracked) posterior.observe_backtrack(t);
      for (const Steps c : sample.censored) posterior.observe_cut_off(c);
    }
    double bound = 0;
    for (const double n : at_risk) bound += 2 * kStrength / (copies * n);
    const Distribution p = posterior.mean(), q = posterior.backtrack_mean();
    double error = 0;
    for (Steps t = 1; t <= kHorizon; ++t) {
      error = std::max(
          {error, std::abs(p.pmf(t) - estimate.planning.pmf(t)), std::abs(q.pmf(t) - estimate.backtrack.pmf(t))});
    }
    EXPECT_LE(error, bound) << copies;
    EXPECT_LT(error, previous) << copies;
    previous = error;
  }
}

TEST(PlanningPosterior, RefusesBadArguments) {
  EXPECT_THROW(PlanningPosterior(prior(), 0, 1.0), UsageError);
  EXPECT_THROW(PlanningPosterior(prior(), 2, 0.0), UsageError);
  EXPECT_THROW(PlanningPosterior(prior(), 2, std::nan("")), UsageError);
  PlanningPosterior posterior(prior(), 2, 1.0);
  EXPECT_THROW(posterior.observe_found(0), UsageError);
  EXPECT_THROW(posterior.observe_cut_off(-1), UsageError);
  EXPECT_THROW(posterior.observe_backtrack(0), UsageError);
  EXPECT_THROW(PlanningPosterior(prior(), Distribution::from_pmf({0.5}), 2, 1.0), UsageError);
  EXPECT_THROW(PlanningPosterior(prior(), Distribution::from_pmf({0.0, 0.0, 0.5}), 2, 1.0), UsageError);
}

}  // namespace
}  // namespace ontime
