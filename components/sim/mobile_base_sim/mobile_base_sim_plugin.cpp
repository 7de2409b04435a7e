// mobile_base_sim: a simulated two-wheeled base (mobile_base_sim.hpp) driven by /cmd_vel,
// carrying the pan/tilt turret; publishes where the base is and where the turret's camera is,
// for the drive follower's closed loop and for a synthetic camera that renders from the
// moving camera (synthetic_ir_camera's moving_camera).
//
// Integration runs on the steady clock, each step over the time since the previous one, and
// the poses are stamped on that same time line (anchored to the wall clock at the first step),
// so distances over stamp differences are the commanded speeds even when ticks are late.
// Like a real base, it stops when commands stop coming: a crashed or disconnected driver must
// not leave it running.
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include <geometry_msgs/msg/pose_stamped.hpp>
#include <geometry_msgs/msg/twist.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <sensor_msgs/msg/joint_state.hpp>

#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "follower/turret_kinematics/turret_model.hpp"
#include "sim/mobile_base_sim/mobile_base_sim.hpp"

namespace mocap::sim {
namespace {

using geometry_msgs::msg::PoseStamped;
using geometry_msgs::msg::Twist;
using sensor_msgs::msg::JointState;
using SteadyClock = std::chrono::steady_clock;

constexpr double kDegree = M_PI / 180;

PoseStamped stamped_pose(const Eigen::Isometry3d& pose,
                         const builtin_interfaces::msg::Time& stamp) {
  PoseStamped message;
  message.header().stamp(stamp);
  message.header().frame_id("world");
  message.pose(to_pose_message(pose));
  return message;
}

struct Settings {
  double rate_hz = 100.0;
  double cmd_vel_timeout_s = 0.5;
  double x = 0.0;
  double y = 0.0;
  double yaw_deg = 0.0;
  double max_linear_mps = 0.7;
  double max_angular_rps = 3.14;
  std::string turret = mocap::config_file("turret.yaml");
  std::string pan_joint = "pan";
  std::string tilt_joint = "tilt";
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("rate_hz", "integration and publication rate", &Settings::rate_hz)
        .range(1, 1000)
        .add("cmd_vel_timeout_s", "no /cmd_vel for this long: the base stops",
             &Settings::cmd_vel_timeout_s)
        .range(0.001, 60)
        .add("x", "initial position in the world, m", &Settings::x)
        .add("y", "initial position in the world, m", &Settings::y)
        .add("yaw_deg", "initial heading, degrees counter-clockwise from world x",
             &Settings::yaw_deg)
        .range(-360, 360)
        .add("max_linear_mps", "top speed (a TurtleBot 2's), m/s; 0: no limit",
             &Settings::max_linear_mps)
        .range(0, 100)
        .add("max_angular_rps", "top turn rate (a TurtleBot 2's), rad/s; 0: no limit",
             &Settings::max_angular_rps)
        .range(0, 100)
        .add("turret", "the turret's kinematic chain: where the camera is on the base",
             &Settings::turret)
        .path()
        .add("pan_joint", "the pan joint's name in the joint states", &Settings::pan_joint)
        .add("tilt_joint", "the tilt joint's name in the joint states", &Settings::tilt_joint);

class MobileBaseSim final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Simulates a two-wheeled base driven by /cmd_vel (exact arcs, stops when commands stop) "
        "carrying the pan/tilt turret; publishes the base's pose and the turret camera's pose "
        "in the world.");
    kParameters.declare(spec);
    spec.subscribes<Twist>(topics::kCmdVel, Qos::reliable(),
                           "linear.x (m/s) and angular.z (rad/s)");
    spec.subscribes<JointState>(topics::kTurretJointStates, Qos::sensor_data(),
                                "the turret's angles, radians (0, 0 until the first)");
    spec.publishes<PoseStamped>(topics::kBasePose, Qos::reliable(), "the base in frame 'world'");
    spec.publishes<PoseStamped>(topics::kSimCameraPose, Qos::reliable(),
                                "the turret's camera (optical frame) in frame 'world'");
  }

  explicit MobileBaseSim(Context& context)
      : Component(context),
        base_({settings_.x, settings_.y, settings_.yaw_deg * kDegree},
              {settings_.max_linear_mps, settings_.max_angular_rps}),
        turret_(turret::load_turret(settings_.turret)),
        timeout_(std::chrono::duration_cast<SteadyClock::duration>(
            std::chrono::duration<double>(settings_.cmd_vel_timeout_s))) {
    base_publisher_ = create_publisher<PoseStamped>(topics::kBasePose);
    camera_publisher_ = create_publisher<PoseStamped>(topics::kSimCameraPose);
    create_subscription<Twist>(topics::kCmdVel, [this](const Twist& twist) { on_command(twist); });
    create_subscription<JointState>(topics::kTurretJointStates,
                                    [this](const JointState& state) { on_joint_state(state); });
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(1.0 / settings_.rate_hz)),
                 [this] { tick(); });
    log().info("base at x {} m, y {} m, yaw {} deg; {} Hz; turret {}", base_.pose().x,
               base_.pose().y, base_.pose().yaw / kDegree, settings_.rate_hz, turret_.source());
  }

  ~MobileBaseSim() override {
    log().info(
        "{} steps, {} commands ({} not finite), {} joint states, {} stops for want of "
        "commands; drove {:.3f} m, ended at x {:.3f} m, y {:.3f} m, yaw {:.1f} deg",
        steps_, commands_, invalid_commands_, joint_states_, timeouts_, base_.odometer_m(),
        base_.pose().x, base_.pose().y, base_.pose().yaw / kDegree);
  }

 private:
  void on_command(const Twist& twist) {
    if (!std::isfinite(twist.linear().x()) || !std::isfinite(twist.angular().z())) {
      if (invalid_commands_++ == 0) log().warn("non-finite /cmd_vel ignored");
      return;
    }
    ++commands_;
    command_ = {twist.linear().x(), twist.angular().z()};
    command_at_ = SteadyClock::now();
  }

  void on_joint_state(const JointState& state) {
    std::optional<double> pan, tilt;
    for (size_t i = 0; i < state.name().size() && i < state.position().size(); ++i) {
      if (state.name()[i] == settings_.pan_joint) pan = state.position()[i];
      if (state.name()[i] == settings_.tilt_joint) tilt = state.position()[i];
    }
    if (pan && std::isfinite(*pan)) joints_.pan = *pan;
    if (tilt && std::isfinite(*tilt)) joints_.tilt = *tilt;
    ++joint_states_;
  }

  void tick() {
    const SteadyClock::time_point steady = SteadyClock::now();
    if (!anchor_) {
      anchor_ = steady;
      anchor_wall_ = now();
      previous_ = steady;
    }
    const double dt = std::chrono::duration<double>(steady - previous_).count();
    previous_ = steady;

    const bool commanded = command_ && steady - command_at_ <= timeout_;
    if (!commanded && driving_) {
      ++timeouts_;
      log().warn("no {} for {} s: stopped", topics::kCmdVel, settings_.cmd_vel_timeout_s);
    }
    driving_ = commanded;
    if (commanded) {
      base_.step(command_->first, command_->second, dt);
    }
    ++steps_;

    const auto stamp =
        to_time_msg(anchor_wall_ + std::chrono::duration_cast<Clock::duration>(steady - *anchor_));
    const Eigen::Isometry3d world_from_base = base_.world_from_base();
    base_publisher_.publish(stamped_pose(world_from_base, stamp));
    camera_publisher_.publish(
        stamped_pose(world_from_base * turret_.base_from_camera(joints_), stamp));
  }

  UnicycleBase base_;
  turret::TurretModel turret_;
  SteadyClock::duration timeout_;
  Publisher<PoseStamped> base_publisher_;
  Publisher<PoseStamped> camera_publisher_;
  std::optional<std::pair<double, double>> command_;  // linear, angular
  SteadyClock::time_point command_at_;
  turret::JointAngles joints_;
  std::optional<SteadyClock::time_point> anchor_;
  Clock::time_point anchor_wall_;
  SteadyClock::time_point previous_;
  bool driving_ = false;
  uint64_t steps_ = 0, commands_ = 0, invalid_commands_ = 0, joint_states_ = 0, timeouts_ = 0;
};

}  // namespace
}  // namespace mocap::sim

MOCAP_REGISTER_COMPONENT(mocap::sim::MobileBaseSim, "mobile_base_sim")
