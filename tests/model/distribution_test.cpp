#include "ontime/model/distribution.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {
namespace {

// Planning time of instance 4's a1_1: 1..5 with 0.3, 0.15, 0.1, 0.15, 0.3.
Distribution asymmetric() { return Distribution::from_pmf({0.0, 0.3, 0.15, 0.1, 0.15, 0.3}); }

TEST(Distribution, CdfAndSurvivalAreComplementary) {
  const Distribution d = asymmetric();
  EXPECT_DOUBLE_EQ(d.cdf(0), 0.0);
  EXPECT_DOUBLE_EQ(d.cdf(2), 0.45);
  EXPECT_DOUBLE_EQ(d.cdf(5), 1.0);
  EXPECT_DOUBLE_EQ(d.cdf(99), 1.0);
  EXPECT_DOUBLE_EQ(d.survival(2), 0.55);
  EXPECT_DOUBLE_EQ(d.survival(-1), 1.0);
  EXPECT_NEAR(d.survival(5), 0.0, 1e-15);
  EXPECT_EQ(d.min_step(), 1);
  EXPECT_EQ(d.max_step(), 5);
}

TEST(Distribution, HazardIsConditionalProbabilityOfFinishingNext) {
  const Distribution d = asymmetric();
  EXPECT_DOUBLE_EQ(d.hazard(0), 0.3);
  EXPECT_DOUBLE_EQ(d.hazard(1), 0.15 / 0.7);
  EXPECT_DOUBLE_EQ(d.hazard(2), 0.1 / 0.55);
  EXPECT_DOUBLE_EQ(d.hazard(3), 0.15 / 0.45);
  EXPECT_DOUBLE_EQ(d.hazard(4), 1.0);
  EXPECT_DOUBLE_EQ(d.hazard(5), 0.0);  // nothing left
}

TEST(Distribution, HazardWithNeverMassNeverReachesOne) {
  // 0.5 at step 2, the rest never.
  const Distribution d = Distribution::from_pmf({0.0, 0.0, 0.5});
  EXPECT_DOUBLE_EQ(d.never(), 0.5);
  EXPECT_DOUBLE_EQ(d.hazard(0), 0.0);
  EXPECT_DOUBLE_EQ(d.hazard(1), 0.5);
  EXPECT_DOUBLE_EQ(d.hazard(2), 0.0);
  EXPECT_DOUBLE_EQ(d.survival(2), 0.5);
}

TEST(Distribution, ConditioningShiftsAndRenormalises) {
  const Distribution d = asymmetric();
  const Distribution after_two = d.conditioned(2);
  // Remaining mass 0.55 over steps 3, 4, 5 -> 1, 2, 3.
  EXPECT_DOUBLE_EQ(after_two.pmf(0), 0.0);
  EXPECT_DOUBLE_EQ(after_two.pmf(1), 0.1 / 0.55);
  EXPECT_DOUBLE_EQ(after_two.pmf(2), 0.15 / 0.55);
  EXPECT_DOUBLE_EQ(after_two.pmf(3), 0.3 / 0.55);
  EXPECT_NEAR(after_two.never(), 0.0, 1e-12);
  // Conditioning agrees with hazards: P(T' = 1) = h(spent).
  for (Steps spent = 0; spent < 5; ++spent) {
    EXPECT_NEAR(d.conditioned(spent).pmf(1), d.hazard(spent), 1e-15) << spent;
  }
  // Nothing left: all mass on never.
  EXPECT_DOUBLE_EQ(d.conditioned(5).never(), 1.0);
}

TEST(Distribution, ConditioningKeepsNeverMassProportion) {
  const Distribution d = Distribution::from_pmf({0.0, 0.2, 0.0, 0.4});  // never 0.4
  const Distribution after_one = d.conditioned(1);
  EXPECT_DOUBLE_EQ(after_one.pmf(2), 0.4 / 0.8);
  EXPECT_DOUBLE_EQ(after_one.never(), 0.5);
}

TEST(Distribution, FromCdfDifferencesTheSteps) {
  // Instance file form {"2": 0.1, "3": 0.9, "4": 1.0}.
  const Distribution d = Distribution::from_cdf({0.0, 0.0, 0.1, 0.9, 1.0});
  EXPECT_DOUBLE_EQ(d.pmf(2), 0.1);
  EXPECT_DOUBLE_EQ(d.pmf(3), 0.8);
  EXPECT_NEAR(d.pmf(4), 0.1, 1e-15);
  EXPECT_THROW(Distribution::from_cdf({0.0, 0.5, 0.4}), UsageError);
}

TEST(Distribution, RejectsInvalidMasses) {
  EXPECT_THROW(Distribution::from_pmf({-0.1, 0.5}), UsageError);
  EXPECT_THROW(Distribution::from_pmf({0.0, 1.5}), UsageError);
  EXPECT_THROW(Distribution::from_pmf({0.6, 0.6}), UsageError);
  EXPECT_THROW(Distribution::from_pmf({std::nan("")}), UsageError);
  try {
    Distribution::from_pmf({0.5, -std::nan("")});
    ADD_FAILURE() << "accepted";
  } catch (const UsageError& error) {
    EXPECT_STREQ(error.what(), "a probability is not a number (NaN)");
  }
  EXPECT_NO_THROW(Distribution::from_pmf({0.5, 0.5 + 1e-10}));
}

TEST(Distribution, MeanIsOverTheFiniteSupport) {
  EXPECT_DOUBLE_EQ(asymmetric().mean_finite(), 0.3 * 1 + 0.15 * 2 + 0.1 * 3 + 0.15 * 4 + 0.3 * 5);
  // Mass 0.5 at 2 and 0.25 at 4, never 0.25: E[T | finite] = (1 + 1) / 0.75.
  EXPECT_DOUBLE_EQ(Distribution::from_pmf({0.0, 0.0, 0.5, 0.0, 0.25}).mean_finite(), 2.0 / 0.75);
  EXPECT_TRUE(std::isinf(Distribution().mean_finite()));
}

TEST(Distribution, QuantileInvertsTheCdf) {
  const Distribution d = Distribution::from_pmf({0.0, 0.25, 0.0, 0.5});  // never 0.25
  EXPECT_EQ(d.quantile(0.0), 1);
  EXPECT_EQ(d.quantile(0.2499), 1);
  EXPECT_EQ(d.quantile(0.25), 3);
  EXPECT_EQ(d.quantile(0.7499), 3);
  EXPECT_EQ(d.quantile(0.75), kNever);
}

TEST(Distribution, SamplingFollowsThePmfAndTheSeed) {
  const Distribution d = asymmetric();
  SplitMix64 generator(42);
  constexpr int kDraws = 200'000;
  std::array<int, 6> counts{};
  for (int i = 0; i < kDraws; ++i) ++counts.at(static_cast<std::size_t>(d.sample(generator)));
  for (Steps t = 1; t <= 5; ++t) {
    const double p = d.pmf(t);
    const double sigma = std::sqrt(p * (1 - p) / kDraws);
    EXPECT_NEAR(counts[static_cast<std::size_t>(t)] / double(kDraws), p, 4.5 * sigma) << t;
  }
  SplitMix64 first(7), second(7);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(d.sample(first), d.sample(second));
}

}  // namespace
}  // namespace ontime
