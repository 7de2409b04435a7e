// dynamixel_follower: the pan/tilt turret of seed 000 §5.11 on two AX-12A servos. It keeps the
// tracked constellation on the camera's optical axis (dynamixel_follower.hpp) and drives the
// servos over a Dynamixel Protocol 1.0 bus (dynamixel_bus.hpp) on a worker the host runs, each
// cycle:
//
//   1. READ present position, speed and load of both servos -> /turret/joint_states;
//   2. the command for now -> one SYNC_WRITE of goal position and moving speed to both
//      (also on /turret/command, for inspection).
//
// Poses on /mocap/poses are placed in the base frame with the joint angles of their image's
// time. A servo reporting overheating or overload gets its torque switched off, for both, and
// an alert on /alerts; the follower then only reports, until restarted. A bus that goes away
// (adaptor unplugged) is reopened with back-off.
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/alert.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/joint_state.hpp>

#include "common/topics/graph_topics.hpp"
#include "follower/dynamixel/ax12_control_table.hpp"
#include "follower/dynamixel/dynamixel_bus.hpp"
#include "follower/dynamixel_follower/dynamixel_follower.hpp"
#include "follower/dynamixel_follower/servo_mapping.hpp"
#include "follower/turret_kinematics/joint_history.hpp"
#include "follower/turret_kinematics/turret_model.hpp"

namespace mocap::turret {
namespace {

namespace ax12 = dynamixel::ax12;
using dynamixel::BusError;
using dynamixel::BusErrorKind;
using JointState = sensor_msgs::msg::JointState;

constexpr uint8_t kShutdownErrors =
    dynamixel::error_bit::kOverheating | dynamixel::error_bit::kOverload;

int64_t clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

// The follower's and the bus's options with what only the plugin reads.
struct Settings : TurretFollowerOptions {
  std::string port = "/dev/ttyUSB0";
  dynamixel::DynamixelBusOptions bus;
  int reply_timeout_ms = 10;  // bus.reply_timeout
  int pan_id = 1;
  int tilt_id = 2;
  std::string turret = mocap::config_file("turret.yaml");
  std::string constellation;  // empty: the first of each pose array
  double rate_hz = 50;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("port", "serial device of the Dynamixel adaptor (or the ax12_sim's device_link)",
             &Settings::port)
        .path()
        .add("baud", "bus baud rate (the servos' setting)", &Settings::bus,
             &dynamixel::DynamixelBusOptions::baud_rate)
        .range(9600, 3000000)
        .add("pan_id", "servo ID of the pan joint", &Settings::pan_id)
        .range(0, 253)
        .add("tilt_id", "servo ID of the tilt joint", &Settings::tilt_id)
        .range(0, 253)
        .add("turret", "the turret's kinematic chain and servo mapping (config/turret.yaml)",
             &Settings::turret)
        .path()
        .add("constellation", "the constellation to follow; empty = the first of each pose array",
             &Settings::constellation)
        .add("rate_hz", "control cycles per second", &Settings::rate_hz)
        .range(1, 500)
        .add("pan_speed_rps", "pan speed limit, rad/s (the seed's heavy turret: 0.1)",
             &Settings::pan_speed_rps)
        .range(0.01, 11.9)
        .add("tilt_speed_rps", "tilt speed limit, rad/s (the seed's heavy turret: 0.05)",
             &Settings::tilt_speed_rps)
        .range(0.01, 11.9)
        .add("lost_after_s", "no pose for this long: the track is lost", &Settings::lost_after_s)
        .range(0.01, 60)
        .add("max_lead_s",
             "aim at where the object's velocity (in the base frame, from its recent positions) "
             "has taken it since its image, at most this far ahead; 0 = where it was seen",
             &Settings::max_lead_s)
        .range(0, 2)
        .add("hold_s", "after losing the track, hold still this long", &Settings::hold_s)
        .range(0, 3600)
        .add("search", "after holding, sweep the pan joint to find the object", &Settings::search)
        .add("search_speed_rps", "pan speed while searching, rad/s", &Settings::search_speed_rps)
        .range(0.01, 11.9)
        .add("reply_timeout_ms", "wait for a servo's answer, per attempt",
             &Settings::reply_timeout_ms)
        .range(1, 1000)
        .add("retries", "further attempts after a timeout or a corrupt answer", &Settings::bus,
             &dynamixel::DynamixelBusOptions::retries)
        .range(0, 10);

class DynamixelFollower final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Keeps the tracked constellation centred with a pan/tilt turret of two AX-12A servos "
        "(Dynamixel Protocol 1.0 on a serial port); publishes the joints' present state. "
        "Overheating or overload: torque off and an alert.");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                                             "tracked poses, camera frame");
    spec.publishes<JointState>(topics::kTurretJointStates, Qos::reliable(),
                               "joints pan and tilt: present position (rad), speed (rad/s), "
                               "load (fraction of the maximum torque) as effort");
    spec.publishes<JointState>(topics::kTurretCommand, Qos::reliable(),
                               "joints pan and tilt: goal position (rad) and speed limit "
                               "(rad/s) sent each cycle");
    spec.publishes<mocap_msgs::msg::Alert>(topics::kAlerts, Qos::reliable(),
                                           "servo faults: torque switched off");
  }

  explicit DynamixelFollower(Context& context)
      : Component(context), follower_(load_turret(settings_.turret), settings_) {
    if (settings_.pan_id == settings_.tilt_id) {
      throw std::invalid_argument("pan_id and tilt_id are both " +
                                  std::to_string(settings_.pan_id) +
                                  "; each servo needs its own ID");
    }
    period_ = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(1 / settings_.rate_hz));
    states_ = create_publisher<JointState>(topics::kTurretJointStates);
    commands_ = create_publisher<JointState>(topics::kTurretCommand);
    alerts_ = create_publisher<mocap_msgs::msg::Alert>(topics::kAlerts);
    create_subscription<mocap_msgs::msg::ConstellationPoseArray>(
        topics::kPoses,
        [this](const mocap_msgs::msg::ConstellationPoseArray& poses) { on_poses(poses); });
    // The bus is driven from a worker of its own, started with the graph, so that blocking
    // serial I/O never holds up the executor.
    create_worker("bus", [this](std::stop_token stop) { run(stop); });
    log().info("servos {} (pan) and {} (tilt) on {} at {} bit/s, {} Hz; turret {}",
               settings_.pan_id, settings_.tilt_id, settings_.port, settings_.bus.baud_rate,
               settings_.rate_hz, follower_.turret().source());
  }

  ~DynamixelFollower() override {
    log().info(
        "{} cycles, {} poses used, {} without a joint reading; bus: {} packets, {} replies, {} "
        "timeouts, {} corrupt, {} retries; {} reconnects",
        cycles_, poses_used_, poses_early_, bus_stats_.packets_sent, bus_stats_.replies,
        bus_stats_.timeouts, bus_stats_.corrupt_replies, bus_stats_.retries, reconnects_);
  }

 private:
  // The servos' IDs on the bus (range-checked to 0..253 by the parameter list).
  uint8_t pan_id() const { return static_cast<uint8_t>(settings_.pan_id); }
  uint8_t tilt_id() const { return static_cast<uint8_t>(settings_.tilt_id); }

  // --- executor side ----------------------------------------------------------------------

  void on_poses(const mocap_msgs::msg::ConstellationPoseArray& poses) {
    for (const auto& pose : poses.poses()) {
      if (!settings_.constellation.empty() && pose.name() != settings_.constellation) continue;
      const auto& p = pose.pose().pose().position();
      const int64_t stamp_ns = to_nanoseconds(pose.pose().header().stamp());
      std::lock_guard lock(mutex_);
      std::optional<JointAngles> angles = history_.at(stamp_ns);
      if (!angles) {
        ++poses_early_;  // the joints have not been read yet
        return;
      }
      const Eigen::Vector3d in_camera(p.x(), p.y(), p.z());
      follower_.observe(stamp_ns, in_camera, *angles);
      ++poses_used_;
      return;
    }
  }

  // --- bus thread --------------------------------------------------------------------------

  void run(const std::stop_token& stop) {
    std::chrono::milliseconds backoff(100);
    auto next = std::chrono::steady_clock::now();
    while (!stop.stop_requested()) {
      try {
        if (!bus_) {
          connect();
          backoff = std::chrono::milliseconds(100);
        }
        if (!faulted_)
          cycle();
        else
          report_only();
      } catch (const BusError& e) {
        if (e.kind() == BusErrorKind::kPortGone) {
          bus_stats_ = add(bus_stats_, bus_->stats());
          bus_.reset();
          log().warn("{}; reopening in {} ms", e.what(), backoff.count());
          wait_for_stop(stop, backoff);
          backoff = std::min(backoff * 2, std::chrono::milliseconds(2000));
          continue;
        }
        if (e.kind() == BusErrorKind::kServoError && (e.servo_errors() & kShutdownErrors)) {
          shut_down(e);
        } else if (++bus_errors_ <= 10 || bus_errors_ % 100 == 0) {
          log().warn("{} ({} bus errors so far)", e.what(), bus_errors_);
        }
      } catch (const std::exception& e) {  // cannot open the device
        log().warn("{}; retrying in {} ms", e.what(), backoff.count());
        wait_for_stop(stop, backoff);
        backoff = std::min(backoff * 2, std::chrono::milliseconds(2000));
        continue;
      }
      next += period_;
      const auto now = std::chrono::steady_clock::now();
      if (next < now) next = now;  // fell behind: no burst of cycles to catch up
      wait_for_stop(stop, next - now);
    }
    if (bus_) bus_stats_ = add(bus_stats_, bus_->stats());
  }

  void connect() {
    dynamixel::DynamixelBusOptions options = settings_.bus;
    options.reply_timeout = std::chrono::milliseconds(settings_.reply_timeout_ms);
    bus_ = std::make_unique<dynamixel::DynamixelBus>(settings_.port, options);
    if (connections_++ > 0) ++reconnects_;
    for (uint8_t id : {pan_id(), tilt_id()}) {
      if (uint8_t errors = bus_->ping(id); errors != 0) {
        log().warn("servo {} reports {}", id, dynamixel::describe_errors(errors));
      }
    }
    // A servo that reports overheating or overload refuses nothing but says so: the caller
    // switches both off again (shut_down).
    for (uint8_t id : {pan_id(), tilt_id()}) bus_->write_u8(id, ax12::kTorqueEnable, 1);
    log().info("servos {} and {} answer on {}; torque on", pan_id(), tilt_id(), bus_->device());
  }

  struct ServoReading {
    uint16_t position = 0;
    double speed_rps = 0;
    double load = 0;
  };

  ServoReading read_servo(uint8_t id) {
    std::vector<uint8_t> data;
    try {
      data = bus_->read(id, ax12::kPresentPosition, 6);
    } catch (const BusError& e) {
      // A servo reporting a condition still answers with its data.
      if (e.kind() != BusErrorKind::kServoError || e.reply_data().size() != 6) throw;
      if (!faulted_ && (e.servo_errors() & kShutdownErrors)) throw;
      data = e.reply_data();
    }
    return {ax12::get_u16(data, 0), ax12::present_speed_to_rad_s(ax12::get_u16(data, 2)),
            ax12::present_load_to_fraction(ax12::get_u16(data, 4))};
  }

  // Reads both joints, publishes them and keeps them for the poses. Returns the angles.
  JointAngles read_joints() {
    const ServoReading pan = read_servo(pan_id()), tilt = read_servo(tilt_id());
    const int64_t stamp_ns = clock_ns();
    const TurretModel& turret = follower_.turret();
    const JointAngles angles{joint_angle(turret.pan(), pan.position),
                             joint_angle(turret.tilt(), tilt.position)};
    {
      std::lock_guard lock(mutex_);
      history_.add(stamp_ns, angles);
    }
    auto state = std::make_shared<JointState>();
    state->header().stamp(to_time_msg(Clock::time_point(std::chrono::nanoseconds(stamp_ns))));
    state->name({"pan", "tilt"});
    state->position({angles.pan, angles.tilt});
    state->velocity({turret.pan().servo.direction * pan.speed_rps,
                     turret.tilt().servo.direction * tilt.speed_rps});
    state->effort(
        {turret.pan().servo.direction * pan.load, turret.tilt().servo.direction * tilt.load});
    states_.publish(std::move(state));
    return angles;
  }

  void cycle() {
    const JointAngles present = read_joints();
    TurretCommand command;
    {
      std::lock_guard lock(mutex_);
      command = follower_.update(clock_ns(), present);
    }
    if (command.mode != last_mode_) {
      log().info("{}", to_string(command.mode));
      last_mode_ = command.mode;
    }
    const TurretModel& turret = follower_.turret();
    auto item = [](uint8_t id, uint16_t position, uint16_t speed) {
      return dynamixel::SyncWriteItem{id,
                                      {uint8_t(position & 0xFF), uint8_t(position >> 8),
                                       uint8_t(speed & 0xFF), uint8_t(speed >> 8)}};
    };
    const dynamixel::SyncWriteItem items[] = {
        item(pan_id(), servo_position(turret.pan(), command.goal.pan),
             ax12::rad_s_to_moving_speed(command.speed.pan)),
        item(tilt_id(), servo_position(turret.tilt(), command.goal.tilt),
             ax12::rad_s_to_moving_speed(command.speed.tilt))};
    bus_->sync_write(ax12::kGoalPosition, 4, items);
    ++cycles_;

    auto sent = std::make_shared<JointState>();
    sent->header().stamp(to_time_msg(now()));
    sent->name({"pan", "tilt"});
    sent->position({command.goal.pan, command.goal.tilt});
    sent->velocity({command.speed.pan, command.speed.tilt});
    commands_.publish(std::move(sent));
  }

  // After a shutdown: keep reporting where the joints are.
  void report_only() { read_joints(); }

  void shut_down(const BusError& error) {
    faulted_ = true;
    for (uint8_t id : {pan_id(), tilt_id()}) {
      try {
        bus_->write_u8(id, ax12::kTorqueEnable, 0);
      } catch (const BusError& e) {
        // The servo executes a write while reporting its condition; only a lost answer is news.
        if (e.kind() != BusErrorKind::kServoError) log().warn("torque off: {}", e.what());
      }
    }
    const std::string text = std::string(error.what()) + ": torque off on both servos";
    log().error("{}", text);
    auto alert = std::make_shared<mocap_msgs::msg::Alert>();
    alert->header().stamp(to_time_msg(now()));
    alert->source(name());
    alert->level(2);
    alert->text(text);
    alerts_.publish(std::move(alert));
  }

  static dynamixel::DynamixelBusStats add(dynamixel::DynamixelBusStats a,
                                          const dynamixel::DynamixelBusStats& b) {
    a.packets_sent += b.packets_sent;
    a.replies += b.replies;
    a.timeouts += b.timeouts;
    a.corrupt_replies += b.corrupt_replies;
    a.retries += b.retries;
    return a;
  }

  // Shared between the pose callback and the bus thread.
  std::mutex mutex_;
  TurretFollower follower_;
  JointHistory history_;
  uint64_t poses_used_ = 0, poses_early_ = 0;

  // Bus thread only (read by the destructor after it has ended).
  std::unique_ptr<dynamixel::DynamixelBus> bus_;
  dynamixel::DynamixelBusStats bus_stats_;
  TurretMode last_mode_ = TurretMode::Idle;
  bool faulted_ = false;
  uint64_t cycles_ = 0, bus_errors_ = 0, connections_ = 0, reconnects_ = 0;

  std::chrono::nanoseconds period_{20'000'000};
  Publisher<JointState> states_;
  Publisher<JointState> commands_;
  Publisher<mocap_msgs::msg::Alert> alerts_;
};

}  // namespace
}  // namespace mocap::turret

MOCAP_REGISTER_COMPONENT(mocap::turret::DynamixelFollower, "dynamixel_follower")
