// drive_follower: the tracked object's poses (camera frame) and the turret's joint angles ->
// /cmd_vel for a two-wheeled base that keeps goal_distance_m in front of the object, facing
// it (seed 000 §5.11.4; drive_follower.hpp). Every control period publishes a command, zero
// while nothing is tracked, so that a base's command watchdog fires only when the follower
// itself is gone.
//
// Poses are used only once the turret's angles are known: with the wrong angles the object
// would be placed in the wrong direction and the base driven there. Each pose is placed with
// the angles the turret had at its image's time (joint_history.hpp), not the latest ones,
// which run ahead while the turret turns.
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <geometry_msgs/msg/twist.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/alert.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/joint_state.hpp>

#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "follower/drive_follower/drive_follower.hpp"
#include "follower/drive_follower/object_in_base.hpp"
#include "follower/turret_kinematics/joint_history.hpp"
#include "follower/turret_kinematics/turret_model.hpp"

namespace mocap::drive {
namespace {

using geometry_msgs::msg::Twist;
using mocap_msgs::msg::Alert;
using mocap_msgs::msg::ConstellationPose;
using mocap_msgs::msg::ConstellationPoseArray;
using sensor_msgs::msg::JointState;

constexpr uint8_t kWarning = 1;

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The follower's options with what only the plugin reads.
struct Settings : FollowerOptions {
  std::string turret = mocap::config_file("turret.yaml");
  std::string constellation;  // empty: the first of each pose array
  std::string pan_joint = "pan";
  std::string tilt_joint = "tilt";
  double rate_hz = 20;  // control_period_s is its inverse
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("turret", "the turret's kinematic chain: where the camera is on the base",
             &Settings::turret)
        .path()
        .add("constellation", "the constellation to follow; empty: the first of each pose array",
             &Settings::constellation)
        .add("pan_joint", "the pan joint's name in the joint states", &Settings::pan_joint)
        .add("tilt_joint", "the tilt joint's name in the joint states", &Settings::tilt_joint)
        .add("rate_hz", "control rate: one /cmd_vel per period", &Settings::rate_hz)
        .range(1, 1000)
        .add("lost_after_s", "no pose of the constellation for this long: track lost, base stopped",
             &Settings::lost_after_s)
        .range(0.01, 60)
        .add("goal_distance_m", "the goal is this far in front of the object", &Settings::drive,
             &DriveOptions::goal_distance_m)
        .range(0.1, 20)
        .add("goal_tolerance_m",
             "once arrived, the base only turns while the goal stays this close", &Settings::drive,
             &DriveOptions::goal_tolerance_m)
        .range(0.005, 5)
        .add("arrival_tolerance_m",
             "the base drives until the goal is this close (at most goal_tolerance_m)",
             &Settings::drive, &DriveOptions::arrival_tolerance_m)
        .range(0.005, 5)
        .add("linear_gain", "forward speed per metre to the goal, 1/s", &Settings::drive,
             &DriveOptions::linear_gain)
        .range(0.01, 20)
        .add("angular_gain", "turn rate per radian of heading error, 1/s", &Settings::drive,
             &DriveOptions::angular_gain)
        .range(0.01, 20)
        .add("max_linear_mps", "top speed, m/s", &Settings::drive, &DriveOptions::max_linear_mps)
        .range(0.01, 5)
        .add("max_angular_rps", "top turn rate, rad/s", &Settings::drive,
             &DriveOptions::max_angular_rps)
        .range(0.01, 20)
        .add("max_linear_accel_mps2", "largest change of speed, m/s^2", &Settings::acceleration,
             &AccelerationLimits::max_linear_accel_mps2)
        .range(0.01, 100)
        .add("max_angular_accel_rps2", "largest change of turn rate, rad/s^2",
             &Settings::acceleration, &AccelerationLimits::max_angular_accel_rps2)
        .range(0.01, 100);

class DriveFollowerComponent final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Drives a two-wheeled base to stay goal_distance_m in front of a tracked constellation, "
        "pointed at it (the seed's two rules, with acceleration limits); stops at once and "
        "raises an alert when the track is lost.");
    kParameters.declare(spec);
    spec.subscribes<ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                            "constellation poses in the tracking camera's frame");
    spec.subscribes<JointState>(topics::kTurretJointStates, Qos::sensor_data(),
                                "the turret's pan and tilt angles, radians");
    spec.publishes<Twist>(topics::kCmdVel, Qos::reliable(),
                          "linear.x (m/s) and angular.z (rad/s) every control period");
    spec.publishes<Alert>(topics::kAlerts, Qos::reliable(),
                          "one alert each time the track is lost");
  }

  explicit DriveFollowerComponent(Context& context)
      : Component(context),
        turret_(turret::load_turret(settings_.turret)),
        follower_(follower_options()) {
    if (settings_.pan_joint == settings_.tilt_joint) {
      throw std::invalid_argument("pan_joint and tilt_joint are both '" + settings_.pan_joint +
                                  "'");
    }
    command_publisher_ = create_publisher<Twist>(topics::kCmdVel);
    alert_publisher_ = create_publisher<Alert>(topics::kAlerts);
    create_subscription<JointState>(topics::kTurretJointStates,
                                    [this](const JointState& state) { on_joint_state(state); });
    create_subscription<ConstellationPoseArray>(
        topics::kPoses, [this](const ConstellationPoseArray& poses) { on_poses(poses); });
    const double rate = settings_.rate_hz;
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(1.0 / rate)),
                 [this] { control(); });
    const DriveOptions& drive = follower_.options().drive;
    log().info("following {} at {} m, {} Hz, stopping after {} s without it (turret {})",
               settings_.constellation.empty() ? std::string("the first constellation")
                                               : settings_.constellation,
               drive.goal_distance_m, rate, follower_.options().lost_after_s, turret_.source());
  }

  ~DriveFollowerComponent() override {
    log().info(
        "{} control periods: {} forward, {} backward, {} facing, {} stopped; {} poses used, {} "
        "arrays without the constellation, {} poses before the turret's angles, {} invalid "
        "poses; {} joint states, {} without the joints; {} tracks found, {} lost",
        periods_, periods_forward_, periods_backward_, periods_facing_, periods_stopped_,
        poses_used_, arrays_without_, poses_before_joints_, invalid_poses_, joint_states_,
        joint_states_without_, tracks_found_, tracks_lost_);
  }

 private:
  FollowerOptions follower_options() const {
    FollowerOptions options = settings_;
    options.control_period_s = 1.0 / settings_.rate_hz;
    return options;
  }

  void on_joint_state(const JointState& state) {
    std::optional<double> pan, tilt;
    for (size_t i = 0; i < state.name().size() && i < state.position().size(); ++i) {
      if (state.name()[i] == settings_.pan_joint) pan = state.position()[i];
      if (state.name()[i] == settings_.tilt_joint) tilt = state.position()[i];
    }
    if (!pan || !tilt || !std::isfinite(*pan) || !std::isfinite(*tilt)) {
      if (joint_states_without_++ == 0) {
        log().warn("joint states without finite positions of '{}' and '{}' are ignored",
                   settings_.pan_joint, settings_.tilt_joint);
      }
      return;
    }
    ++joint_states_;
    joints_.add(to_nanoseconds(state.header().stamp()), turret::JointAngles{*pan, *tilt});
  }

  void on_poses(const ConstellationPoseArray& poses) {
    const ConstellationPose* followed = nullptr;
    for (const ConstellationPose& pose : poses.poses()) {
      if (settings_.constellation.empty() || pose.name() == settings_.constellation) {
        followed = &pose;
        break;
      }
    }
    if (!followed) {
      ++arrays_without_;
      return;
    }
    const std::optional<turret::JointAngles> joints =
        joints_.at(to_nanoseconds(followed->pose().header().stamp()));
    if (!joints) {
      if (poses_before_joints_++ == 0) {
        log().warn("poses are not used until {} carries the angles of '{}' and '{}'",
                   topics::kTurretJointStates, settings_.pan_joint, settings_.tilt_joint);
      }
      return;
    }
    const std::optional<Eigen::Isometry3d> camera_from_object =
        to_isometry(followed->pose().pose());
    if (!camera_from_object) {
      ++invalid_poses_;
      return;
    }
    followed_name_ = followed->name();
    const ObjectObservation observation =
        object_in_base(turret_.base_from_camera(*joints), *camera_from_object);
    follower_.observe(observation.object, steady_seconds());
    ++poses_used_;
  }

  void control() {
    const FollowerStep step = follower_.step(steady_seconds());
    ++periods_;
    if (!step.command) {
      ++periods_stopped_;
    } else if (step.command->rule == DriveRule::Forward) {
      ++periods_forward_;
    } else if (step.command->rule == DriveRule::Backward) {
      ++periods_backward_;
    } else {
      ++periods_facing_;
    }
    // The stop goes out before anything else can delay it.
    Twist twist;
    twist.linear().x(step.velocity.linear_mps);
    twist.angular().z(step.velocity.angular_rps);
    command_publisher_.publish(std::move(twist));

    if (step.event == TrackEvent::Lost) {
      ++tracks_lost_;
      const std::string text = "track of " + followed_name_ + " lost: stopped";
      log().warn("{} (no pose for {} s)", text, follower_.options().lost_after_s);
      Alert alert;
      alert.header().stamp(to_time_msg(now()));
      alert.source("drive_follower");
      alert.level(kWarning);
      alert.text(text);
      alert_publisher_.publish(std::move(alert));
    } else if (step.event == TrackEvent::Found) {
      log().info("track of {} {}: following", followed_name_,
                 tracks_found_++ == 0 ? "found" : "regained");
    }
  }

  turret::TurretModel turret_;
  DriveFollower follower_;
  Publisher<Twist> command_publisher_;
  Publisher<Alert> alert_publisher_;
  turret::JointHistory joints_;
  std::string followed_name_;
  uint64_t periods_ = 0, periods_forward_ = 0, periods_backward_ = 0, periods_facing_ = 0,
           periods_stopped_ = 0;
  uint64_t poses_used_ = 0, arrays_without_ = 0, poses_before_joints_ = 0, invalid_poses_ = 0;
  uint64_t joint_states_ = 0, joint_states_without_ = 0;
  uint64_t tracks_found_ = 0, tracks_lost_ = 0;
};

}  // namespace
}  // namespace mocap::drive

MOCAP_REGISTER_COMPONENT(mocap::drive::DriveFollowerComponent, "drive_follower")
