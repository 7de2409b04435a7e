#include <gtest/gtest.h>

#include "core/rate_estimator.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;

TEST(RateEstimator, SteadyStreamFromSourceTimestamps) {
  RateEstimator estimator(1000);
  RateEstimator::TimePoint t{};
  EXPECT_FALSE(estimator.stats());
  // 10 kHz with +-20 us of jitter on every stamp.
  for (int i = 0; i < 5000; ++i) {
    estimator.add(t + i * 100us + (i % 2 ? 20us : -20us));
  }
  auto stats = estimator.stats();
  ASSERT_TRUE(stats);
  EXPECT_NEAR(stats->rate_hz, 10000.0, 10000.0 * 0.001);
  EXPECT_EQ(stats->samples, 1000u);
  EXPECT_NEAR(stats->min_period_s, 60e-6, 1e-9);
  EXPECT_NEAR(stats->max_period_s, 140e-6, 1e-9);
  EXPECT_NEAR(stats->stddev_period_s, 40e-6, 1e-7);
}

TEST(RateEstimator, NeedsTimeBetweenSamples) {
  RateEstimator estimator;
  RateEstimator::TimePoint t{};
  estimator.add(t);
  estimator.add(t);
  EXPECT_FALSE(estimator.stats());
}

}  // namespace
}  // namespace mocap
