// The turret follower (components/follower/dynamixel_follower): servo units, the joint history, the
// follower's modes, and the plugin driving the simulated AX-12A chain (ax12_sim) over a real
// pseudo-terminal, with a camera stand-in that sees a fixed target through the turret's present
// angles: the loop closes through real Dynamixel bytes.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/alert.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/joint_state.hpp>

#include "follower/dynamixel_follower/dynamixel_follower.hpp"
#include "follower/dynamixel_follower/servo_mapping.hpp"
#include "follower/turret_kinematics/joint_history.hpp"
#include "follower/turret_kinematics/turret_model.hpp"
#include "host/plugin_loader.hpp"
#include "test/test_support.hpp"

namespace mocap::turret {
namespace {

using JointState = sensor_msgs::msg::JointState;
using Poses = mocap_msgs::msg::ConstellationPoseArray;
using Alert = mocap_msgs::msg::Alert;

constexpr double kDegree = M_PI / 180;
constexpr int64_t kSecond = 1'000'000'000;
// One AX-12A position unit: 300 / 1024 degrees.
constexpr double kPositionUnit = 300.0 / 1024 * kDegree;

const TurretModel& shipped_turret() {
  static const TurretModel turret =
      load_turret((test::source_dir() / "config" / "turret.yaml").string());
  return turret;
}

TEST(ServoMapping, AnglesAndPositionsRoundTripForEitherMounting) {
  Joint joint;
  joint.servo = {512, 1};
  EXPECT_EQ(servo_position(joint, 0), 512);
  EXPECT_EQ(servo_position(joint, 150 * kDegree), 1024 - 1);  // clamped to the register
  EXPECT_EQ(servo_position(joint, 30 * kDegree), 512 + 102);  // 30 / (300 / 1024) = 102.4
  EXPECT_NEAR(joint_angle(joint, 614), 102 * kPositionUnit, 1e-12);
  joint.servo = {400, -1};  // mounted the other way round, zero off centre
  EXPECT_EQ(servo_position(joint, 30 * kDegree), 400 - 102);
  for (int position : {0, 100, 400, 777, 1023}) {
    EXPECT_EQ(servo_position(joint, joint_angle(joint, static_cast<uint16_t>(position))), position);
  }
}

TEST(JointHistory, InterpolatesBetweenReadingsAndHoldsOutsideThem) {
  JointHistory history(kSecond);
  EXPECT_FALSE(history.at(0));
  history.add(1 * kSecond, {0.0, 0.0});
  history.add(2 * kSecond, {1.0, -0.5});
  history.add(1 * kSecond, {9.0, 9.0});  // older than the newest: ignored
  EXPECT_DOUBLE_EQ(history.at(1 * kSecond + kSecond / 4)->pan, 0.25);
  EXPECT_DOUBLE_EQ(history.at(1 * kSecond + kSecond / 4)->tilt, -0.125);
  EXPECT_DOUBLE_EQ(history.at(0)->pan, 0.0);
  EXPECT_DOUBLE_EQ(history.at(5 * kSecond)->pan, 1.0);
  history.add(4 * kSecond, {2.0, 0.0});  // the others are now more than a second older
  EXPECT_DOUBLE_EQ(history.at(3 * kSecond)->pan, 2.0);
  EXPECT_DOUBLE_EQ(history.latest()->pan, 2.0);
}

TEST(TurretFollower, AimsAtWhatItSawThenHoldsThenSearches) {
  TurretFollowerOptions options;
  options.lost_after_s = 0.3;
  options.hold_s = 1.0;
  options.search = true;
  TurretFollower follower(shipped_turret(), options);
  const JointAngles present{0.1, 0.0};
  EXPECT_EQ(follower.update(0, present).mode, TurretMode::Idle);

  // A target 2 m ahead and 1 m to the left of the base, seen through the present angles.
  const Eigen::Vector3d target(2.0, 1.0, 1.0);
  const Eigen::Vector3d in_camera = shipped_turret().base_from_camera(present).inverse() * target;
  follower.observe(kSecond, in_camera, present);
  TurretCommand command = follower.update(kSecond + kSecond / 10, present);
  EXPECT_EQ(command.mode, TurretMode::Tracking);
  EXPECT_LT(shipped_turret().pointing_error(command.goal, target), 1e-6);
  EXPECT_NEAR(command.pointing_error_rad, shipped_turret().pointing_error(present, target), 1e-12);
  EXPECT_NEAR(command.goal.pan, std::atan2(1.0, 2.0), 2 * kDegree);
  EXPECT_DOUBLE_EQ(command.speed.pan, options.pan_speed_rps);

  // Lost after 0.3 s: hold where the joints were then, for a second; then sweep.
  const JointAngles moved{0.3, 0.1};
  command = follower.update(kSecond + kSecond / 2, moved);
  EXPECT_EQ(command.mode, TurretMode::Holding);
  EXPECT_DOUBLE_EQ(command.goal.pan, 0.3);
  command = follower.update(2 * kSecond, {0.35, 0.1});
  EXPECT_EQ(command.mode, TurretMode::Holding);
  EXPECT_DOUBLE_EQ(command.goal.pan, 0.3);
  command = follower.update(3 * kSecond, {0.35, 0.1});
  EXPECT_EQ(command.mode, TurretMode::Searching);
  EXPECT_DOUBLE_EQ(command.goal.pan, shipped_turret().pan().max_rad);
  EXPECT_DOUBLE_EQ(command.speed.pan, options.search_speed_rps);
  command = follower.update(4 * kSecond, {shipped_turret().pan().max_rad, 0});
  EXPECT_DOUBLE_EQ(command.goal.pan, shipped_turret().pan().min_rad);  // turns round

  // Seen again: tracking at once.
  follower.observe(5 * kSecond, in_camera, present);
  EXPECT_EQ(follower.update(5 * kSecond, present).mode, TurretMode::Tracking);
}

TEST(TurretFollower, LeadsAMovingObjectByItsVelocity) {
  TurretFollowerOptions options;
  options.max_lead_s = 0.2;
  TurretFollower follower(shipped_turret(), options);
  const Eigen::Vector3d velocity(0.0, 1.0, 0.0);  // walking to the base's left at 1 m/s
  auto at = [&](int64_t stamp_ns) -> Eigen::Vector3d {
    return Eigen::Vector3d(3.0, 0.0, 1.0) + velocity * (stamp_ns * 1e-9 - 1.0);
  };
  // Seen every 30 ms for 0.3 s while the turret turns to follow it.
  int64_t stamp = kSecond;
  for (int k = 0; k <= 10; ++k, stamp += 30'000'000) {
    const JointAngles angles{0.01 * k, 0.0};
    follower.observe(stamp, shipped_turret().base_from_camera(angles).inverse() * at(stamp),
                     angles);
  }
  const int64_t last = stamp - 30'000'000;
  const std::optional<Eigen::Vector3d> measured = follower.velocity_in_base();
  ASSERT_TRUE(measured.has_value());
  EXPECT_LT((measured.value() - velocity).norm(), 1e-6);
  // 0.1 s after its last image it is 10 cm further left: the turret aims there.
  const JointAngles present{0.1, 0.0};
  TurretCommand command = follower.update(last + kSecond / 10, present);
  EXPECT_LT(shipped_turret().pointing_error(command.goal, at(last + kSecond / 10)), 1e-6);
  EXPECT_GT(shipped_turret().pointing_error(command.goal, at(last)), kDegree);
  // No further ahead than max_lead_s, however late the next image.
  command = follower.update(last + kSecond / 4, present);
  EXPECT_LT(shipped_turret().pointing_error(command.goal, at(last + kSecond / 5)), 1e-6);
  // Found again after a loss, it has no velocity until it is measured again.
  follower.observe(last + kSecond, shipped_turret().base_from_camera(present).inverse() * at(0),
                   present);
  EXPECT_FALSE(follower.velocity_in_base().has_value());
}

TEST(TurretFollower, RejectsSpeedsThatAreNotPositive) {
  TurretFollowerOptions options;
  options.pan_speed_rps = 0;
  EXPECT_THROW(TurretFollower(shipped_turret(), options), std::invalid_argument);
}

// --- the plugin on the simulated servos --------------------------------------------------------

// Sees a fixed target (base frame) as a camera on the turret would: each joint state becomes
// a pose of the target in the camera frame, stamped like the joint state. Records the joint
// states and alerts.
class CameraStandIn final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<JointState>("/turret/joint_states", Qos::reliable(), "");
    spec.subscribes<Alert>("/alerts", Qos::reliable(), "");
    spec.publishes<Poses>("/mocap/poses", Qos::reliable(), "");
  }
  explicit CameraStandIn(Context& context) : Component(context) {
    poses_ = create_publisher<Poses>("/mocap/poses");
    create_subscription<JointState>("/turret/joint_states", [this](const JointState& state) {
      const JointAngles angles{state.position()[0], state.position()[1]};
      const Eigen::Vector3d seen = shipped_turret().base_from_camera(angles).inverse() * target;
      Poses poses;
      poses.header(state.header());
      mocap_msgs::msg::ConstellationPose pose;
      pose.name("board_a");
      pose.pose().header(state.header());
      pose.pose().pose().position().x(seen.x());
      pose.pose().pose().position().y(seen.y());
      pose.pose().pose().position().z(seen.z());
      poses.poses().push_back(pose);
      if (seen.z() > 0) poses_.publish(poses);
      std::lock_guard lock(mutex);
      states.push_back(angles);
      changed.notify_all();
    });
    create_subscription<Alert>("/alerts", [this](const Alert& alert) {
      std::lock_guard lock(mutex);
      alerts.push_back(alert);
      changed.notify_all();
    });
  }

  // Waits until `done()` holds (under the lock), at most 20 s.
  template <class Predicate>
  bool wait(Predicate done) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(20), done);
  }

  const Eigen::Vector3d target{1.5, 1.2, 1.1};
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<JointAngles> states;
  std::vector<Alert> alerts;

 private:
  Publisher<Poses> poses_;
};

struct Turret {
  test::TempDir dir;
  PluginLoader loader;
  ComponentHost host{{.name = "test", .threads = 2, .dds = {.enabled = false}}};
  std::string port = (dir / "servos").string();

  void add_servos(std::vector<std::string> faults = {}) {
    host.add(
        *loader.load("ax12_sim").factory,
        {.name = "servos", .parameters = {{"device_link", port}, {"faults", std::move(faults)}}});
  }
  void add_follower() {
    host.add(*loader.load("dynamixel_follower").factory,
             {.name = "follower", .parameters = {{"port", port}}});
  }
  CameraStandIn& add_camera() {
    return static_cast<CameraStandIn&>(
        host.add(make_component_factory<CameraStandIn>("camera"), {.name = "camera"}));
  }
};

TEST(DynamixelFollowerPlugin, TurnsTheSimulatedServosUntilTheTargetIsCentred) {
  Turret turret;
  turret.add_servos();
  turret.add_follower();
  CameraStandIn& camera = turret.add_camera();
  turret.host.start();
  // Centred to within the servos' resolution (one position unit on each joint).
  const bool centred = camera.wait([&] {
    return !camera.states.empty() &&
           shipped_turret().pointing_error(camera.states.back(), camera.target) < 2 * kPositionUnit;
  });
  turret.host.stop();
  std::lock_guard lock(camera.mutex);
  ASSERT_TRUE(centred) << "last angles " << camera.states.back().pan / kDegree << ", "
                       << camera.states.back().tilt / kDegree;
  const Aim aim = shipped_turret().aim_at(camera.target);
  EXPECT_NEAR(camera.states.back().pan, aim.angles.pan, 2 * kPositionUnit);
  EXPECT_NEAR(camera.states.back().tilt, aim.angles.tilt, 2 * kPositionUnit);
  EXPECT_TRUE(camera.alerts.empty());
}

TEST(DynamixelFollowerPlugin, AnOverheatingServoIsSwitchedOffWithAnAlert) {
  Turret turret;
  turret.add_servos({"2:overheat"});
  turret.add_follower();
  CameraStandIn& camera = turret.add_camera();
  turret.host.start();
  const bool alerted = camera.wait([&] { return !camera.alerts.empty(); });
  // Joint states keep coming after the shutdown.
  size_t states_then = 0;
  {
    std::lock_guard lock(camera.mutex);
    states_then = camera.states.size();
  }
  const bool still_reporting = camera.wait([&] { return camera.states.size() > states_then + 5; });
  turret.host.stop();
  ASSERT_TRUE(alerted);
  EXPECT_TRUE(still_reporting);
  std::lock_guard lock(camera.mutex);
  ASSERT_EQ(camera.alerts.size(), 1u);
  EXPECT_EQ(camera.alerts[0].level(), 2);
  EXPECT_EQ(camera.alerts[0].source(), "follower");
  EXPECT_NE(camera.alerts[0].text().find("servo 2"), std::string::npos) << camera.alerts[0].text();
  EXPECT_NE(camera.alerts[0].text().find("overheating"), std::string::npos)
      << camera.alerts[0].text();
  EXPECT_NE(camera.alerts[0].text().find("torque off"), std::string::npos);
}

TEST(DynamixelFollowerPlugin, WaitsForTheAdaptorAndConnectsWhenItAppears) {
  Turret turret;
  turret.add_follower();  // nothing at the port yet: it retries with back-off
  CameraStandIn& camera = turret.add_camera();
  turret.host.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  {
    std::lock_guard lock(camera.mutex);
    EXPECT_TRUE(camera.states.empty());
  }
  turret.add_servos();  // plugged in
  const bool reading = camera.wait([&] { return camera.states.size() >= 10; });
  turret.host.stop();
  EXPECT_TRUE(reading);
}

TEST(DynamixelFollowerPlugin, AnUnpluggedAdaptorIsReopenedWhenItComesBack) {
  test::TempDir dir;
  PluginLoader loader;
  const std::string port = (dir / "servos").string();
  // The servos in a host of their own, so they can go away while the follower runs.
  auto servos = std::make_unique<ComponentHost>(
      HostOptions{.name = "servos", .threads = 1, .dds = {.enabled = false}});
  servos->add(*loader.load("ax12_sim").factory,
              {.name = "servos", .parameters = {{"device_link", port}}});
  servos->start();
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  host.add(*loader.load("dynamixel_follower").factory,
           {.name = "follower", .parameters = {{"port", port}}});
  auto& camera = static_cast<CameraStandIn&>(
      host.add(make_component_factory<CameraStandIn>("camera"), {.name = "camera"}));
  host.start();
  ASSERT_TRUE(camera.wait([&] { return camera.states.size() >= 10; }));

  servos.reset();  // unplugged: the pseudo-terminal closes, the link goes
  size_t states_then = 0;
  {
    std::lock_guard lock(camera.mutex);
    states_then = camera.states.size();
  }
  servos = std::make_unique<ComponentHost>(
      HostOptions{.name = "servos", .threads = 1, .dds = {.enabled = false}});
  servos->add(*loader.load("ax12_sim").factory,
              {.name = "servos", .parameters = {{"device_link", port}}});
  servos->start();  // plugged in again, a new device under the same name
  const bool reading_again = camera.wait([&] { return camera.states.size() >= states_then + 10; });
  host.stop();
  servos.reset();
  EXPECT_TRUE(reading_again);
}

TEST(DynamixelFollowerPlugin, BadParametersAreClearErrors) {
  PluginLoader loader;
  ComponentHost host({.name = "test", .dds = {.enabled = false}});
  try {
    host.add(*loader.load("dynamixel_follower").factory,
             {.name = "follower", .parameters = {{"pan_id", 3}, {"tilt_id", 3}}});
    ADD_FAILURE() << "no error";
  } catch (const ComponentError& e) {
    EXPECT_NE(std::string(e.what()).find("pan_id and tilt_id are both 3"), std::string::npos)
        << e.what();
  }
  try {
    host.add(*loader.load("dynamixel_follower").factory,
             {.name = "follower2", .parameters = {{"turret", std::string("/nonexistent.yaml")}}});
    ADD_FAILURE() << "no error";
  } catch (const ComponentError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent.yaml: cannot read the turret"),
              std::string::npos)
        << e.what();
  }
}

// The plugin's parameter ranges keep a launch file's options usable; options built in code get
// the same checks from the follower, which names the field.
TEST(TurretFollowerOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(TurretFollowerOptions{}.problem(), std::nullopt);
  EXPECT_EQ(TurretFollowerOptions{.pan_speed_rps = 0}.problem(), "pan_speed_rps: 0 is not above 0");
  EXPECT_EQ(TurretFollowerOptions{.max_lead_s = -0.1}.problem(), "max_lead_s: -0.1 is below 0");
  EXPECT_EQ(TurretFollowerOptions{.max_lead_s = 0}.problem(), std::nullopt);  // aim where seen
  EXPECT_EQ(
      TurretFollowerOptions{.velocity_window_s = std::numeric_limits<double>::infinity()}.problem(),
      "velocity_window_s: inf is not finite");
  try {
    TurretFollower follower(shipped_turret(), {.hold_s = -1});
    ADD_FAILURE() << "a negative hold accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "TurretFollowerOptions::hold_s: -1 is below 0");
  }
}

}  // namespace
}  // namespace mocap::turret
