#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "ontime/run/episode_runner.hpp"

namespace ontime {
namespace {

// The sample of rank round(q (n - 1)) in microseconds, as the histogram defines its quantiles.
double sorted_quantile(std::vector<std::int64_t> samples, double quantile) {
  std::sort(samples.begin(), samples.end());
  const auto rank = static_cast<std::size_t>(quantile * static_cast<double>(samples.size() - 1) + 0.5);
  return static_cast<double>(samples[rank]) / 1000.0;
}

TEST(LatencyHistogram, SmallDurationsAreExact) {
  LatencyHistogram histogram;
  for (std::int64_t nanoseconds = 1; nanoseconds <= 51; ++nanoseconds) histogram.add(nanoseconds);
  const LatencySummary summary = histogram.summary();
  EXPECT_EQ(summary.decisions, 51U);
  EXPECT_DOUBLE_EQ(summary.median_us, 0.026);
  EXPECT_DOUBLE_EQ(summary.p99_us, 0.051);
  EXPECT_DOUBLE_EQ(summary.mean_us, 0.026);
  EXPECT_DOUBLE_EQ(summary.max_us, 0.051);
}

TEST(LatencyHistogram, QuantilesWithinOneHundredTwentyEighthOfTheSortedSamples) {
  std::mt19937_64 random(7);
  std::lognormal_distribution<double> duration(8.0, 2.5);  // about 3 µs, spread over decades
  std::vector<std::int64_t> samples;
  LatencyHistogram first_half;
  LatencyHistogram second_half;
  double total = 0;
  for (int i = 0; i < 100'000; ++i) {
    const auto nanoseconds = static_cast<std::int64_t>(std::min(duration(random), 1e15));
    samples.push_back(nanoseconds);
    total += static_cast<double>(nanoseconds);
    (i % 2 == 0 ? first_half : second_half).add(nanoseconds);
  }
  LatencyHistogram merged = first_half;
  merged.merge(second_half);
  const LatencySummary summary = merged.summary();
  EXPECT_EQ(summary.decisions, samples.size());
  EXPECT_DOUBLE_EQ(summary.max_us, static_cast<double>(*std::max_element(samples.begin(), samples.end())) / 1000.0);
  EXPECT_NEAR(summary.mean_us, total / static_cast<double>(samples.size()) / 1000.0, 1e-9 * summary.mean_us);
  const double median = sorted_quantile(samples, 0.5);
  const double p99 = sorted_quantile(samples, 0.99);
  EXPECT_NEAR(summary.median_us, median, median / 128);
  EXPECT_NEAR(summary.p99_us, p99, p99 / 128);
  EXPECT_NE(summary.median_us, 0.0);
}

TEST(LatencyHistogram, TheLargestDurationsFitTheirBuckets) {
  LatencyHistogram histogram;
  histogram.add(INT64_MAX);
  histogram.add(0);
  histogram.add(-5);  // a clock that went backwards counts as zero
  const LatencySummary summary = histogram.summary();
  EXPECT_EQ(summary.decisions, 3U);
  EXPECT_DOUBLE_EQ(summary.median_us, 0.0);
  EXPECT_DOUBLE_EQ(summary.max_us, static_cast<double>(INT64_MAX) / 1000.0);
  EXPECT_NEAR(summary.p99_us, summary.max_us, summary.max_us / 128);
}

}  // namespace
}  // namespace ontime
