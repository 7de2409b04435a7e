// The drive_follower and mobile_base_sim plugins in-process through ComponentHost: test
// components play poses, joint states and velocity commands and record what comes out. The
// assertions are on the messages' values (and the simulator's own stamps), not on wall-clock
// timing; waits only bound how long a test may take.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <geometry_msgs/msg/pose_stamped.hpp>
#include <geometry_msgs/msg/twist.hpp>
#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/alert.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/joint_state.hpp>

#include "follower/turret_kinematics/turret_model.hpp"
#include "host/plugin_loader.hpp"
#include "test/test_support.hpp"

namespace mocap::drive {
namespace {

using geometry_msgs::msg::PoseStamped;
using geometry_msgs::msg::Twist;
using mocap_msgs::msg::Alert;
using mocap_msgs::msg::ConstellationPose;
using mocap_msgs::msg::ConstellationPoseArray;
using sensor_msgs::msg::JointState;

constexpr std::chrono::seconds kPatience(10);

const turret::TurretModel& shipped_turret() {
  static const turret::TurretModel turret =
      turret::load_turret((test::source_dir() / "config" / "turret.yaml").string());
  return turret;
}

const ComponentFactory& plugin(const char* name) {
  static PluginLoader loader;
  return *loader.load(name).factory;
}

JointState joint_state(double pan, double tilt) {
  JointState state;
  state.name({"pan", "tilt"});
  state.position({pan, tilt});
  return state;
}

// A board `distance` m along the camera's optical axis, turned to face the camera.
ConstellationPose board_on_axis(const std::string& name, double distance) {
  ConstellationPose pose;
  pose.name(name);
  pose.pose().header().frame_id("camera");
  pose.pose().pose().position().z(distance);
  // Half a turn about the camera's x axis: the board's z axis points back at the camera.
  pose.pose().pose().orientation().x(1);
  pose.pose().pose().orientation().w(0);
  pose.points_used(12);
  return pose;
}

// Waits, under `mutex`, until `done()` holds; false if it does not within kPatience.
bool wait_until(std::mutex& mutex, std::condition_variable& changed,
                const std::function<bool()>& done) {
  std::unique_lock lock(mutex);
  return changed.wait_for(lock, kPatience, done);
}

// ---------------------------------------------------------------------------------------------
// drive_follower.

// Plays the tracking pipeline and the turret: every 10 ms an array with board_b 0.6 m ahead
// (to be ignored: following it would mean backing up) and board_a 4 m ahead, while `poses_on`;
// the turret's angles always.
class TrackingPlayer final : public Component {
 public:
  static constexpr double kPan = 0.3;  // rad: the boards are ahead and to the left

  static void declare(ComponentSpec& spec) {
    spec.publishes<ConstellationPoseArray>("/mocap/poses", Qos::reliable(), "");
    spec.publishes<JointState>("/turret/joint_states", Qos::reliable(), "");
  }
  explicit TrackingPlayer(Context& context) : Component(context) {
    poses_ = create_publisher<ConstellationPoseArray>("/mocap/poses");
    joints_ = create_publisher<JointState>("/turret/joint_states");
    create_timer(std::chrono::milliseconds(10), [this] { play(); });
  }

  std::atomic<bool> poses_on{true};

 private:
  void play() {
    JointState state = joint_state(kPan, 0);
    state.header().stamp(to_time_msg(now()));
    joints_.publish(std::move(state));
    if (!poses_on) return;
    ConstellationPoseArray array;
    array.header().stamp(to_time_msg(now()));
    array.header().frame_id("camera");
    array.poses().push_back(board_on_axis("board_b", 0.6));
    array.poses().push_back(board_on_axis("board_a", 4.0));
    poses_.publish(std::move(array));
  }

  Publisher<ConstellationPoseArray> poses_;
  Publisher<JointState> joints_;
};

// Records /cmd_vel and /alerts in the order they arrive.
class CommandRecorder final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<Twist>("/cmd_vel", Qos::reliable(), "");
    spec.subscribes<Alert>("/alerts", Qos::reliable(), "");
  }
  explicit CommandRecorder(Context& context) : Component(context) {
    create_subscription<Twist>("/cmd_vel", [this](const Twist& twist) {
      std::lock_guard lock(mutex);
      twists.push_back(twist);
      changed.notify_all();
    });
    create_subscription<Alert>("/alerts", [this](const Alert& alert) {
      std::lock_guard lock(mutex);
      alerts.push_back(alert);
      twists_before_alert.push_back(twists.size());
      changed.notify_all();
    });
  }

  std::mutex mutex;
  std::condition_variable changed;
  std::vector<Twist> twists;
  std::vector<Alert> alerts;
  std::vector<size_t> twists_before_alert;  // how many twists had arrived before each alert
};

TEST(DriveFollowerPlugin, DrivesTowardTheGoalStopsWhenTheTrackIsLostAndAlertsOnce) {
  testing::internal::CaptureStderr();
  auto host = std::make_unique<ComponentHost>(
      HostOptions{.name = "test", .threads = 2, .dds = {.enabled = false}});
  host->add(plugin("drive_follower"),
            {.name = "follower",
             .parameters = {{"constellation", std::string("board_a")}, {"rate_hz", 50.0}}});
  auto& player = static_cast<TrackingPlayer&>(
      host->add(make_component_factory<TrackingPlayer>("player"), {.name = "player"}));
  auto& recorder = static_cast<CommandRecorder&>(
      host->add(make_component_factory<CommandRecorder>("recorder"), {.name = "recorder"}));
  host->start();

  // board_a 4 m along the camera's axis, panned 0.3 rad left, facing the camera: the goal is
  // 2.53 m out on that line, ahead and to the left. The speed ramps up to the top, 0.6 m/s.
  ASSERT_TRUE(wait_until(recorder.mutex, recorder.changed, [&] {
    return !recorder.twists.empty() && recorder.twists.back().linear().x() >= 0.6;
  })) << "never at top speed";
  {
    std::lock_guard lock(recorder.mutex);
    const Twist& last = recorder.twists.back();
    EXPECT_NEAR(last.linear().x(), 0.6, 1e-12);
    // Turning left toward the goal, which lies on the camera's axis (the pan joint stands on
    // the base's origin): 0.3 rad off the heading, times the angular gain 2.
    EXPECT_NEAR(last.angular().z(), 2.0 * TrackingPlayer::kPan, 1e-9);
    for (const Twist& twist : recorder.twists) {
      EXPECT_GE(twist.linear().x(), 0) << "backing up: board_b followed";
    }
    EXPECT_TRUE(recorder.alerts.empty());
  }

  // The poses stop: one alert, and from the period it was raised in on, exact zeros.
  player.poses_on = false;
  ASSERT_TRUE(wait_until(recorder.mutex, recorder.changed, [&] {
    return !recorder.alerts.empty() &&
           recorder.twists.size() >= recorder.twists_before_alert[0] + 20;
  })) << "no alert, or no commands after it";
  {
    std::lock_guard lock(recorder.mutex);
    ASSERT_EQ(recorder.alerts.size(), 1u);
    const Alert& alert = recorder.alerts[0];
    EXPECT_EQ(alert.source(), "drive_follower");
    EXPECT_EQ(alert.level(), 1);
    EXPECT_EQ(alert.text(), "track of board_a lost: stopped");
    EXPECT_GT(to_nanoseconds(alert.header().stamp()), 0);
    // The stop bypasses the acceleration limits: from top speed to exact zeros at once.
    // (That it comes in the period the loss is detected is the library's DriveFollower test;
    // the order of two topics' messages is not kept across subscriptions.)
    size_t stop = 0;
    while (stop < recorder.twists.size() && recorder.twists[stop].linear().x() == 0) ++stop;
    while (stop < recorder.twists.size() && recorder.twists[stop].linear().x() != 0) ++stop;
    ASSERT_GT(stop, 0u);
    ASSERT_LT(stop, recorder.twists.size()) << "never stopped";
    EXPECT_GT(recorder.twists[stop - 1].linear().x(), 0.5) << "slowed down before the stop";
    for (size_t i = stop; i < recorder.twists.size(); ++i) {
      EXPECT_EQ(recorder.twists[i].linear().x(), 0.0) << i;
      EXPECT_EQ(recorder.twists[i].angular().z(), 0.0) << i;
    }
  }

  // Back: the base drives again, from rest.
  size_t stopped_twists = 0;
  {
    std::lock_guard lock(recorder.mutex);
    stopped_twists = recorder.twists.size();
  }
  player.poses_on = true;
  ASSERT_TRUE(wait_until(recorder.mutex, recorder.changed, [&] {
    return recorder.twists.size() > stopped_twists && recorder.twists.back().linear().x() > 0.3;
  }));
  host->stop();
  {
    std::lock_guard lock(recorder.mutex);
    bool ramped = false;
    for (size_t i = stopped_twists; i < recorder.twists.size() && !ramped; ++i) {
      const double v = recorder.twists[i].linear().x();
      if (v > 0) {
        // 1 m/s² over at most two 20 ms periods.
        EXPECT_LE(v, 1.0 * 2 / 50 + 1e-9) << "the first command after the stop jumps";
        ramped = true;
      }
    }
    EXPECT_TRUE(ramped);
    EXPECT_EQ(recorder.alerts.size(), 1u);
  }
  host.reset();
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("track of board_a found: following"), std::string::npos) << log;
  EXPECT_NE(log.find("track of board_a lost: stopped (no pose for 0.25 s)"), std::string::npos)
      << log;
  EXPECT_NE(log.find("track of board_a regained: following"), std::string::npos) << log;
  EXPECT_NE(log.find("; 2 tracks found, 1 lost"), std::string::npos) << log;
  EXPECT_NE(log.find(" 0 backward,"), std::string::npos) << log;
}

TEST(DriveFollowerPlugin, PosesWaitForTheTurretsAngles) {
  // Joint states that lack the tilt joint: the object's direction is unknown, nothing moves.
  class AnglelessPlayer final : public Component {
   public:
    static void declare(ComponentSpec& spec) {
      spec.publishes<ConstellationPoseArray>("/mocap/poses", Qos::reliable(), "");
      spec.publishes<JointState>("/turret/joint_states", Qos::reliable(), "");
    }
    explicit AnglelessPlayer(Context& context) : Component(context) {
      poses_ = create_publisher<ConstellationPoseArray>("/mocap/poses");
      joints_ = create_publisher<JointState>("/turret/joint_states");
      create_timer(std::chrono::milliseconds(10), [this] {
        JointState state;
        state.name({"pan"});
        state.position({0.0});
        joints_.publish(std::move(state));
        ConstellationPoseArray array;
        array.poses().push_back(board_on_axis("board_a", 4.0));
        poses_.publish(std::move(array));
      });
    }

   private:
    Publisher<ConstellationPoseArray> poses_;
    Publisher<JointState> joints_;
  };

  testing::internal::CaptureStderr();
  auto host = std::make_unique<ComponentHost>(
      HostOptions{.name = "test", .threads = 2, .dds = {.enabled = false}});
  host->add(plugin("drive_follower"), {.name = "follower", .parameters = {{"rate_hz", 50.0}}});
  host->add(make_component_factory<AnglelessPlayer>("player"), {.name = "player"});
  auto& recorder = static_cast<CommandRecorder&>(
      host->add(make_component_factory<CommandRecorder>("recorder"), {.name = "recorder"}));
  host->start();
  ASSERT_TRUE(
      wait_until(recorder.mutex, recorder.changed, [&] { return recorder.twists.size() >= 20; }));
  host->stop();
  {
    std::lock_guard lock(recorder.mutex);
    for (const Twist& twist : recorder.twists) {
      EXPECT_EQ(twist.linear().x(), 0.0);
      EXPECT_EQ(twist.angular().z(), 0.0);
    }
    EXPECT_TRUE(recorder.alerts.empty());
  }
  host.reset();
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("joint states without finite positions of 'pan' and 'tilt' are ignored"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("poses are not used until /turret/joint_states carries the angles"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find(" 0 poses used,"), std::string::npos) << log;
}

std::string configuration_error(const char* plugin_name, ComponentConfig config) {
  ComponentHost host(HostOptions{.name = "test", .threads = 1, .dds = {.enabled = false}});
  try {
    host.add(plugin(plugin_name), std::move(config));
  } catch (const ComponentError& e) {
    return e.what();
  }
  return "no error";
}

TEST(DriveFollowerPlugin, WrongParametersAreClearErrors) {
  const auto error = [](std::map<std::string, ParameterValue> parameters) {
    return configuration_error("drive_follower", {.name = "follower", .parameters = parameters});
  };
  std::string message = error({{"rate_hz", 0.0}});
  EXPECT_NE(message.find("rate_hz"), std::string::npos) << message;
  message = error({{"max_linear_mps", std::string("fast")}});
  EXPECT_NE(message.find("max_linear_mps"), std::string::npos) << message;
  message = error({{"arrival_tolerance_m", 0.5}});
  EXPECT_NE(message.find("FollowerOptions::drive.arrival_tolerance_m: 0.5 is above "
                         "goal_tolerance_m (0.25)"),
            std::string::npos)
      << message;
  message = error({{"tilt_joint", std::string("pan")}});
  EXPECT_NE(message.find("pan_joint and tilt_joint are both 'pan'"), std::string::npos) << message;
  message = error({{"turret", std::string("/nonexistent/turret.yaml")}});
  EXPECT_NE(message.find("/nonexistent/turret.yaml: cannot read the turret"), std::string::npos)
      << message;
  EXPECT_EQ(error({}), "no error");
}

// ---------------------------------------------------------------------------------------------
// mobile_base_sim.

// Sends v = 0.5 m/s, ω = 0 every 20 ms while `driving`, and the turret's angles.
class CommandPlayer final : public Component {
 public:
  static constexpr double kPan = 0.3, kTilt = 0.2;

  static void declare(ComponentSpec& spec) {
    spec.publishes<Twist>("/cmd_vel", Qos::reliable(), "");
    spec.publishes<JointState>("/turret/joint_states", Qos::reliable(), "");
  }
  explicit CommandPlayer(Context& context) : Component(context) {
    commands_ = create_publisher<Twist>("/cmd_vel");
    joints_ = create_publisher<JointState>("/turret/joint_states");
    create_timer(std::chrono::milliseconds(20), [this] {
      joints_.publish(joint_state(kPan, kTilt));
      if (!driving) return;
      Twist twist;
      twist.linear().x(0.5);
      commands_.publish(std::move(twist));
    });
  }

  std::atomic<bool> driving{true};

 private:
  Publisher<Twist> commands_;
  Publisher<JointState> joints_;
};

class PoseRecorder final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<PoseStamped>("/base/pose", Qos::reliable(), "");
    spec.subscribes<PoseStamped>("/sim/camera_pose", Qos::reliable(), "");
  }
  explicit PoseRecorder(Context& context) : Component(context) {
    create_subscription<PoseStamped>("/base/pose", [this](const PoseStamped& pose) {
      std::lock_guard lock(mutex);
      base.push_back(pose);
      changed.notify_all();
    });
    create_subscription<PoseStamped>("/sim/camera_pose", [this](const PoseStamped& pose) {
      std::lock_guard lock(mutex);
      camera.push_back(pose);
      changed.notify_all();
    });
  }

  std::mutex mutex;
  std::condition_variable changed;
  std::vector<PoseStamped> base;
  std::vector<PoseStamped> camera;
};

Eigen::Isometry3d to_isometry(const PoseStamped& message) {
  const auto& p = message.pose().position();
  const auto& q = message.pose().orientation();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(p.x(), p.y(), p.z());
  pose.linear() = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).toRotationMatrix();
  return pose;
}

double seconds(const PoseStamped& message) {
  return static_cast<double>(to_nanoseconds(message.header().stamp())) * 1e-9;
}

TEST(MobileBaseSimPlugin, DrivesAtTheCommandedSpeedAndCarriesTheCamera) {
  testing::internal::CaptureStderr();
  auto host = std::make_unique<ComponentHost>(
      HostOptions{.name = "test", .threads = 2, .dds = {.enabled = false}});
  host->add(
      plugin("mobile_base_sim"),
      {.name = "base",
       .parameters = {{"x", 1.0}, {"y", -0.5}, {"yaw_deg", 0.0}, {"cmd_vel_timeout_s", 0.2}}});
  auto& player = static_cast<CommandPlayer&>(
      host->add(make_component_factory<CommandPlayer>("player"), {.name = "player"}));
  auto& recorder = static_cast<PoseRecorder&>(
      host->add(make_component_factory<PoseRecorder>("recorder"), {.name = "recorder"}));
  host->start();

  ASSERT_TRUE(wait_until(recorder.mutex, recorder.changed, [&] {
    return !recorder.base.empty() && recorder.base.back().pose().position().x() > 1.4 &&
           recorder.camera.size() >= recorder.base.size();
  })) << "the base does not move";
  {
    std::lock_guard lock(recorder.mutex);
    EXPECT_EQ(recorder.base.front().header().frame_id(), "world");
    EXPECT_DOUBLE_EQ(recorder.base.front().pose().position().x(), 1.0);  // the start
    // Speed from the simulator's own stamps, once under way (the first moving step may have
    // begun before the first command).
    const PoseStamped* first = nullptr;
    for (const PoseStamped& pose : recorder.base) {
      if (!first && pose.pose().position().x() > 1.05) first = &pose;
    }
    ASSERT_NE(first, nullptr);
    const PoseStamped& last = recorder.base.back();
    ASSERT_GT(seconds(last) - seconds(*first), 0.5);
    const double speed = (last.pose().position().x() - first->pose().position().x()) /
                         (seconds(last) - seconds(*first));
    EXPECT_NEAR(speed, 0.5, 0.005);
    for (const PoseStamped& pose : recorder.base) {
      EXPECT_DOUBLE_EQ(pose.pose().position().y(), -0.5);
      EXPECT_EQ(pose.pose().position().z(), 0);
      EXPECT_DOUBLE_EQ(pose.pose().orientation().w(), 1);
    }
    // The camera: the base's pose times the turret's chain at the played angles, same stamp.
    const PoseStamped& camera = recorder.camera[recorder.base.size() - 1];
    EXPECT_EQ(camera.header().frame_id(), "world");
    EXPECT_EQ(to_nanoseconds(camera.header().stamp()), to_nanoseconds(last.header().stamp()));
    const Eigen::Isometry3d expected =
        to_isometry(last) *
        shipped_turret().base_from_camera({CommandPlayer::kPan, CommandPlayer::kTilt});
    const Eigen::Isometry3d actual = to_isometry(camera);
    EXPECT_TRUE(actual.translation().isApprox(expected.translation(), 1e-12))
        << actual.translation().transpose() << " vs " << expected.translation().transpose();
    EXPECT_TRUE(actual.linear().isApprox(expected.linear(), 1e-12));
  }

  // Commands stop: the base stops by itself, and stays.
  player.driving = false;
  size_t moving = 0;
  {
    std::lock_guard lock(recorder.mutex);
    moving = recorder.base.size();
  }
  ASSERT_TRUE(wait_until(recorder.mutex, recorder.changed, [&] {
    const size_t n = recorder.base.size();
    if (n < moving + 30) return false;
    for (size_t i = n - 20; i < n; ++i) {
      if (recorder.base[i].pose().position().x() != recorder.base[n - 1].pose().position().x()) {
        return false;
      }
    }
    return true;
  })) << "the base does not stop without commands";
  host->stop();
  host.reset();
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("no /cmd_vel for 0.2 s: stopped"), std::string::npos) << log;
  EXPECT_NE(log.find("1 stops for want of commands"), std::string::npos) << log;
}

TEST(MobileBaseSimPlugin, WrongParametersAreClearErrors) {
  std::string message =
      configuration_error("mobile_base_sim", {.name = "base", .parameters = {{"rate_hz", -1.0}}});
  EXPECT_NE(message.find("rate_hz"), std::string::npos) << message;
  message = configuration_error(
      "mobile_base_sim",
      {.name = "base", .parameters = {{"turret", std::string("/nonexistent/turret.yaml")}}});
  EXPECT_NE(message.find("/nonexistent/turret.yaml"), std::string::npos) << message;
}

}  // namespace
}  // namespace mocap::drive
