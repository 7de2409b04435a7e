// The fiducial monitor's statistics.
#include <gtest/gtest.h>

#include <cmath>

#include "tracking/fiducial_monitor/fiducial_monitor.hpp"

namespace mocap::demo {
namespace {

TEST(StreamStatistics, ReportsAndStartsOver) {
  StreamStatistics statistics;
  EXPECT_FALSE(statistics.report());
  for (int i = 1; i <= 100; ++i) statistics.add(i * 1e-3, 12);
  auto report = statistics.report();
  ASSERT_TRUE(report);
  EXPECT_EQ(report->messages, 100u);
  EXPECT_DOUBLE_EQ(report->mean_items, 12);
  EXPECT_DOUBLE_EQ(report->latency_median_s, 50e-3);
  EXPECT_DOUBLE_EQ(report->latency_p99_s, 99e-3);
  EXPECT_DOUBLE_EQ(report->latency_max_s, 100e-3);
  EXPECT_FALSE(statistics.report());
  EXPECT_EQ(statistics.total_messages(), 100u);
}

}  // namespace
}  // namespace mocap::demo
