// The whole follower loop as launch_yaml/follower_demo.yaml ships it, run by mocap_launch for
// 26 s of config/scenes/follow_walk.yaml: the person stands, walks away and to the side,
// stands, and turns away (track lost at about 17.5 s). The follower monitor's figures must show
// the turret centring the board, the base holding 1.5 m in front of it, and the base stopping
// when the track is lost. The bounds are loose: the loop runs in real time on a shared machine.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <string>

#include "test/test_support.hpp"

namespace mocap {
namespace {

TEST(FollowerDemo, TurretCentresBaseKeepsItsDistanceAndStopsWhenTheTrackIsLost) {
  test::TempDir dir;
  const std::string servos = (dir / "servos").string();
  const std::string summary = (dir / "summary.yaml").string();
  auto [code, output] = test::run_command(
      {(test::bin_dir() / "mocap_launch").string(),
       (test::source_dir() / "launch_yaml" / "follower_demo.yaml").string(), "--duration", "26",
       "--set", "servos.device_link=" + servos, "--set", "turret.port=" + servos, "--set",
       "monitor.summary_file=" + summary, "--set", "viewer.port=0"},
      {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(30))}}, std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  YAML::Node figures = YAML::LoadFile(summary);
  SCOPED_TRACE(test::read_file(summary));
  EXPECT_LT(figures["pointing_error_deg"]["median"].as<double>(), 2.0);
  EXPECT_LT(figures["pointing_error_walking_deg"]["median"].as<double>(), 3.0);
  EXPECT_NEAR(figures["steady_distance_m"]["median"].as<double>(), 1.5, 0.1);
  EXPECT_GT(figures["steady_distance_m"]["within_percent"].as<double>(), 90.0);
  // One loss; lost after lost_after_s (0.25 s) without a pose, zero in the same period.
  EXPECT_EQ(figures["stop_latency_s"]["count"].as<int>(), 1);
  EXPECT_LT(figures["stop_latency_s"]["max"].as<double>(), 0.5);
  EXPECT_EQ(figures["alerts"].as<int>(), 1);
  // The loops ran (nominal: turret 50 Hz, drive 20 Hz, camera 30 Hz).
  EXPECT_GT(figures["rates_hz"]["turret"].as<double>(), 25.0);
  EXPECT_GT(figures["rates_hz"]["drive"].as<double>(), 10.0);
  EXPECT_GT(figures["rates_hz"]["poses"].as<double>(), 10.0);
}

TEST(FollowerDemo, ShippedLaunchFileIsValid) {
  auto [code, output] = test::run_command(
      {(test::bin_dir() / "mocap_launch").string(),
       (test::source_dir() / "launch_yaml" / "follower_demo.yaml").string(), "--check"});
  EXPECT_EQ(code, 0) << output;
}

}  // namespace
}  // namespace mocap
