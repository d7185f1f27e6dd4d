#include "ontime/learn/online_update.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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

TEST(PlanningPosterior, RefusesBadArguments) {
  EXPECT_THROW(PlanningPosterior(prior(), 0, 1.0), UsageError);
  EXPECT_THROW(PlanningPosterior(prior(), 2, 0.0), UsageError);
  EXPECT_THROW(PlanningPosterior(prior(), 2, std::nan("")), UsageError);
  PlanningPosterior posterior(prior(), 2, 1.0);
  EXPECT_THROW(posterior.observe_found(0), UsageError);
  EXPECT_THROW(posterior.observe_cut_off(-1), UsageError);
}

}  // namespace
}  // namespace ontime
