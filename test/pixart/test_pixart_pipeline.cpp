// The whole PixArt path through the runtime, compared with the simulator's ground truth:
//   - live, as launch_yaml/pixart_localization.yaml runs it: simulated box -> SLCAN bytes on a
//     pseudo-terminal -> pixart_bridge -> pixart_localizer -> /pixart/robots;
//   - replayed: the simulated box's candump log and ground-truth CSV -> pixart_bridge
//     (source candump) -> pixart_localizer, paired with the truth by stamp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/robot_pose_array.hpp>

#include "host/plugin_loader.hpp"
#include "sim/pixart_box_sim/candump_recording.hpp"
#include "sim/pixart_box_sim/pixart_box_simulator.hpp"
#include "sim/pixart_box_sim/pixart_scene.hpp"
#include "test/test_support.hpp"

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

// Rows of the simulator's ground-truth CSV (candump_recording.hpp), per robot, in stamp order.
struct TruthRow {
  int64_t stamp_ns = 0;
  double x = 0, y = 0;
};
std::map<std::string, std::vector<TruthRow>> read_truth_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, kTruthCsvHeader);
  std::map<std::string, std::vector<TruthRow>> rows;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string stamp, robot, x, y;
    std::getline(fields, stamp, ',');
    std::getline(fields, robot, ',');
    std::getline(fields, x, ',');
    std::getline(fields, y, ',');
    rows[robot].push_back({std::stoll(stamp), std::stod(x), std::stod(y)});
  }
  return rows;
}

// The truth at `stamp_ns`, linear between the rows around it; nothing outside them.
std::optional<Eigen::Vector2d> truth_at(const std::vector<TruthRow>& rows, int64_t stamp_ns) {
  auto after = std::lower_bound(rows.begin(), rows.end(), stamp_ns,
                                [](const TruthRow& row, int64_t t) { return row.stamp_ns < t; });
  if (after == rows.end() || after == rows.begin()) return std::nullopt;
  auto before = after - 1;
  double f = double(stamp_ns - before->stamp_ns) / double(after->stamp_ns - before->stamp_ns);
  return Eigen::Vector2d(before->x + f * (after->x - before->x),
                         before->y + f * (after->y - before->y));
}

// Collects /pixart/robots.
class PoseCollector final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<Poses>("/pixart/robots", Qos::reliable(), "");
  }
  explicit PoseCollector(Context& context) : Component(context) {
    create_subscription<Poses>("/pixart/robots", [this](const Poses& poses) {
      std::lock_guard lock(mutex);
      arrays.push_back(poses);
    });
  }
  std::mutex mutex;
  std::vector<Poses> arrays;
};

TEST(PixartPipeline, ReplayedLogMatchesItsGroundTruthByStamp) {
  test::TempDir dir;
  PluginLoader loader;
  const std::string config = (test::source_dir() / "config" / "pixart").string();
  Rig rig = load_rig(config + "/rig.yaml");
  PixartBoxSimulator simulator(rig, load_pixart_scene(config + "/scenes/two_robots.yaml", rig));
  const int64_t start_ns = 1'700'000'000'000'000'000;
  {
    std::ofstream log(dir / "box.log"), truth(dir / "box.log.truth.csv");
    write_candump_recording(simulator, log,
                            {.duration_s = 1.5,
                             .rate_hz = 270,
                             .start_ns = start_ns,
                             .truth = &truth,
                             .truth_rate_hz = 50});
  }
  const auto truth = read_truth_csv(dir / "box.log.truth.csv");
  ASSERT_EQ(truth.size(), 2u);
  for (const auto& [robot, rows] : truth) {
    ASSERT_EQ(rows.size(), 75u) << robot;  // 1.5 s at 50 Hz
    EXPECT_EQ(rows.front().stamp_ns, start_ns) << robot;
  }

  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  host.add(*loader.load("pixart_bridge").factory,
           {.name = "bridge",
            .parameters = {{"source", std::string("candump")},
                           {"file", (dir / "box.log").string()},
                           {"camera_names", std::vector<std::string>{"camera0", "camera1",
                                                                     "camera2", "camera3"}}}});
  host.add(*loader.load("pixart_localizer").factory,
           {.name = "localizer", .parameters = {{"rig", config + "/rig.yaml"}}});
  auto& collector = static_cast<PoseCollector&>(
      host.add(make_component_factory<PoseCollector>("collector"), {.name = "collector"}));
  host.start();
  // Until a pose of the log's last 50 ms arrives (the log plays for 1.5 s).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  auto reached_the_end = [&] {
    std::lock_guard lock(collector.mutex);
    return !collector.arrays.empty() &&
           to_nanoseconds(collector.arrays.back().header().stamp()) >= start_ns + 1'450'000'000;
  };
  while (!reached_the_end() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  host.stop();

  // The replay keeps the log's stamps, so each pose pairs with the truth of its time. robot_a
  // circles at 0.09 m/s: the few milliseconds between a robot's reading and the array's stamp
  // (the newest reading of any robot) move it by well under a millimetre.
  std::lock_guard lock(collector.mutex);
  std::map<std::string, std::vector<double>> errors;
  for (const Poses& poses : collector.arrays) {
    const int64_t stamp_ns = to_nanoseconds(poses.header().stamp());
    ASSERT_GE(stamp_ns, start_ns);
    ASSERT_LT(stamp_ns, start_ns + 1'500'000'000);
    for (const auto& pose : poses.robots()) {
      auto expected = truth_at(truth.at(pose.name()), stamp_ns);
      if (!expected) continue;
      errors[pose.name()].push_back((Eigen::Vector2d(pose.x(), pose.y()) - *expected).norm());
    }
  }
  ASSERT_EQ(errors.size(), 2u);
  for (const auto& [robot, robot_errors] : errors) {
    EXPECT_GE(robot_errors.size(), 30u) << robot;  // 50 Hz for about 1.5 s
    EXPECT_LT(median(robot_errors), 0.003) << robot;
  }
}

}  // namespace
}  // namespace mocap::pixart
