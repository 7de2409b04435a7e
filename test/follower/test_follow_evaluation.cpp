// The follower demo's figures (components/follower/follower_monitor/follower_monitor.hpp) on
// scripted truth: pointing error, distance kept once the object has stood for settle_s, stop
// latency.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "follower/follower_monitor/follower_monitor.hpp"

namespace mocap::evaluation {
namespace {

constexpr int64_t kFrame = 33'333'333;  // 30 Hz, ns

TEST(FollowEvaluator, PointingErrorIsTheAngleOffTheOpticalAxis) {
  FollowEvaluator evaluator;
  const Eigen::Isometry3d camera = Eigen::Isometry3d::Identity();
  evaluator.add_truth(0, {std::tan(3 * M_PI / 180) * 2.0, 0, 2.0}, camera, true);
  evaluator.add_truth(kFrame, {0, 0, 2.0}, camera, false);  // not trackable: not counted
  ASSERT_EQ(evaluator.figures().pointing_error_deg.size(), 1u);
  EXPECT_NEAR(evaluator.figures().pointing_error_deg[0], 3.0, 1e-9);
}

TEST(FollowEvaluator, DistancesCountOnceTheObjectHasStoodForSettleTime) {
  FollowEvaluator evaluator({.walking_speed_mps = 0.1, .speed_window_s = 0.5, .settle_s = 1.0});
  evaluator.add_base({0, 0});
  const Eigen::Isometry3d camera = Eigen::Isometry3d::Identity();
  // The camera at the world's origin, axes aligned: walking along x at 1 m/s for a second,
  // then standing 2.5 m from the base for two seconds.
  int64_t t = 0;
  for (int k = 0; k <= 30; ++k, t += kFrame) {
    evaluator.add_truth(t, {1.5 + k / 30.0, 0, 2.0}, camera, true);
  }
  EXPECT_NEAR(evaluator.object_speed_mps(), 1.0, 0.01);
  EXPECT_EQ(evaluator.figures().pointing_error_walking_deg.size(), 30u);  // the first has no speed
  for (int k = 0; k < 60; ++k, t += kFrame) evaluator.add_truth(t, {2.5, 0, 2.0}, camera, true);
  // Standing from when the 0.5 s window holds no motion, then settling for a second.
  const size_t steady = evaluator.figures().steady_distance_m.size();
  EXPECT_GE(steady, 10u);
  EXPECT_LE(steady, 20u);
  EXPECT_DOUBLE_EQ(evaluator.figures().steady_distance_m.back(), 2.5);
}

TEST(FollowEvaluator, StopLatencyRunsFromTheLastPoseToTheFirstZeroCommand) {
  FollowEvaluator evaluator;
  evaluator.add_velocity_command(0, 0, 0);  // stopped before anything moved: not a stop
  evaluator.add_pose(1'000'000'000);
  evaluator.add_velocity_command(1'050'000'000, 0.3, 0.1);
  evaluator.add_velocity_command(1'100'000'000, 0.3, 0.0);
  evaluator.add_velocity_command(1'300'000'000, 0, 0);
  evaluator.add_velocity_command(1'350'000'000, 0, 0);  // still stopped: counted once
  ASSERT_EQ(evaluator.figures().stop_latency_s.size(), 1u);
  EXPECT_NEAR(evaluator.figures().stop_latency_s[0], 0.3, 1e-9);
}

TEST(Spread, MedianPercentileAndMaximum) {
  std::vector<double> values;
  for (int i = 1; i <= 100; ++i) values.push_back(i);
  const Spread s = spread(values);
  EXPECT_EQ(s.median, 51);
  EXPECT_EQ(s.p95, 96);
  EXPECT_EQ(s.max, 100);
  EXPECT_TRUE(std::isnan(spread({}).median));
}

// A negative speed would count the object as walking forever, and no distance as steady.
TEST(FollowEvaluationOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(FollowEvaluationOptions{}.problem(), std::nullopt);
  EXPECT_EQ(FollowEvaluationOptions{.walking_speed_mps = -0.1}.problem(),
            "walking_speed_mps: -0.1 is below 0");
  EXPECT_EQ(FollowEvaluationOptions{.speed_window_s = -1}.problem(),
            "speed_window_s: -1 is below 0");
  EXPECT_EQ(FollowEvaluationOptions{.settle_s = 0}.problem(), std::nullopt);  // steady at once
  try {
    FollowEvaluator evaluator({.settle_s = -4});
    ADD_FAILURE() << "a negative settle time accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "FollowEvaluationOptions::settle_s: -4 is below 0");
  }
}

}  // namespace
}  // namespace mocap::evaluation
