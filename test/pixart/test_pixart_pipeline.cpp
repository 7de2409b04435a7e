// The whole PixArt path through the runtime, as launch_yaml/pixart_localization.yaml runs it:
// simulated box -> SLCAN bytes on a pseudo-terminal -> pixart_bridge -> pixart_localizer ->
// /pixart/robots, compared with the simulator's ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>

#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/robot_pose_array.hpp>

#include "plugin_loader.hpp"
#include "test_support.hpp"

namespace mocap::pixart {
namespace {

using Poses = mocap_msgs::msg::RobotPoseArray;

// Pairs each localized pose with the ground truth published nearest before it.
class Comparison final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<Poses>("/pixart/robots", Qos::reliable(), "");
    spec.subscribes<Poses>("/pixart/ground_truth", Qos::reliable(), "");
  }
  explicit Comparison(Context& context) : Component(context) {
    create_subscription<Poses>("/pixart/ground_truth", [this](const Poses& truth) {
      std::lock_guard lock(mutex);
      for (const auto& pose : truth.robots()) latest_truth[pose.name()] = pose;
    });
    create_subscription<Poses>("/pixart/robots", [this](const Poses& robots) {
      std::lock_guard lock(mutex);
      for (const auto& pose : robots.robots()) {
        auto truth = latest_truth.find(pose.name());
        if (truth == latest_truth.end()) continue;
        position_errors[pose.name()].push_back(
            std::hypot(pose.x() - truth->second.x(), pose.y() - truth->second.y()));
      }
      if (++arrays >= 100) done.notify_all();
    });
  }
  std::mutex mutex;
  std::condition_variable done;
  std::map<std::string, mocap_msgs::msg::RobotPose> latest_truth;
  std::map<std::string, std::vector<double>> position_errors;
  int arrays = 0;
};

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

TEST(PixartPipeline, SimulatedBoxOverAPtyToRobotPoses) {
  test::TempDir dir;
  PluginLoader loader;
  std::string config = (test::source_dir() / "config" / "pixart").string();
  std::string device = (dir / "adaptor").string();
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  host.add(*loader.load("pixart_box_sim").factory,
           {.name = "box",
            .parameters = {{"rig", config + "/rig.yaml"},
                           {"scene", config + "/scenes/two_robots.yaml"},
                           {"output", std::string("pty")},
                           {"device_link", device}}});
  host.add(*loader.load("pixart_bridge").factory,
           {.name = "bridge",
            .parameters = {{"device", device},
                           {"camera_names", std::vector<std::string>{"camera0", "camera1",
                                                                     "camera2", "camera3"}}}});
  host.add(*loader.load("pixart_localizer").factory,
           {.name = "localizer", .parameters = {{"rig", config + "/rig.yaml"}}});
  auto& comparison = static_cast<Comparison&>(
      host.add(make_component_factory<Comparison>("comparison"), {.name = "comparison"}));
  host.start();
  {
    std::unique_lock lock(comparison.mutex);
    ASSERT_TRUE(comparison.done.wait_for(lock, std::chrono::seconds(30),
                                         [&] { return comparison.arrays >= 100; }));
  }
  host.stop();
  std::lock_guard lock(comparison.mutex);
  // Both robots localized all along; robot_a circles at 0.09 m/s, so the truth published up to
  // 20 ms before a pose accounts for up to 2 mm.
  ASSERT_EQ(comparison.position_errors.size(), 2u);
  for (const auto& [robot, errors] : comparison.position_errors) {
    EXPECT_GE(errors.size(), 50u) << robot;
    EXPECT_LT(median(errors), 0.005) << robot;
  }
}

}  // namespace
}  // namespace mocap::pixart
