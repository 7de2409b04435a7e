// px4_odometry: one tracked board (or a volume's robot), carried by a PX4 vehicle, as
// px4_msgs/VehicleOdometry on /fmu/in/vehicle_visual_odometry, the topic PX4's uXRCE-DDS agent
// forwards to the flight controller's external-vision input (remap it to
// /fmu/in/vehicle_mocap_odometry for PX4's motion-capture input; a swarm has one per vehicle,
// each remapped into its vehicle's namespace). Frames converted to PX4's (px4_odometry.hpp); rate
// kept by the poses' capture stamps.
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/component.hpp>
#include <mocap/component_spec.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <px4_msgs/msg/vehicle_odometry.hpp>

#include "common/topics/graph_topics.hpp"
#include "outputs/body_frames/body_state_message.hpp"
#include "outputs/body_frames/stamp_rate.hpp"
#include "outputs/px4_odometry/px4_odometry.hpp"

namespace mocap::outputs {
namespace {

using mocap_msgs::msg::ConstellationPose;
using mocap_msgs::msg::ConstellationPoseArray;
using px4_msgs::msg::VehicleOdometry;

// What PX4's ROS 2 examples publish with: reliable, the last 10 kept. A reliable writer meets
// the agent's reader whichever reliability it asks for; keep-last never holds the graph up.
Qos px4_qos() {
  Qos qos = Qos::reliable();
  qos.history = History::KeepLast;
  qos.depth = 10;
  return qos;
}

template <size_t N>
std::array<float, N> to_floats(const Eigen::Matrix<double, N, 1>& v) {
  std::array<float, N> values{};
  for (size_t i = 0; i < N; ++i) values[i] = static_cast<float>(v[static_cast<Eigen::Index>(i)]);
  return values;
}

uint64_t microseconds(int64_t nanoseconds) { return static_cast<uint64_t>(nanoseconds / 1000); }

struct Settings {
  std::string board;
  std::string pose_frame = "frd";
  std::vector<double> camera_in_world = {0, 0, 0, 0, 0, 0};
  std::vector<double> vehicle_in_board = {0, 0, 0, 0, 0, 0};
  std::string optical_frame = "camera_ir_optical";
  double rate_hz = 50.0;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("board", "the board the vehicle carries (required)", &Settings::board)
        .add("pose_frame",
             "frd: our world (z up) has any heading, PX4 gets FRD; ned: our world is ENU "
             "(x east, y north, z up), PX4 gets NED",
             &Settings::pose_frame)
        .add("camera_in_world",
             "the camera's REP 103 body frame in the world: x, y, z (m), roll, pitch, yaw "
             "(rad); [] for no camera (a volume's poses, in the world frame already)",
             &Settings::camera_in_world)
        .add("vehicle_in_board",
             "the vehicle's FLU body frame (x forward, y left, z up) in the board's frame: "
             "x, y, z (m), roll, pitch, yaw (rad)",
             &Settings::vehicle_in_board)
        .add("optical_frame", "the frame of /mocap/poses; poses in another are counted and skipped",
             &Settings::optical_frame)
        .add("rate_hz",
             "most messages a second, by the poses' capture stamps (PX4 wants 30-50; 0: "
             "every frame)",
             &Settings::rate_hz)
        .min(0);

class Px4OdometryComponent final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "One tracked board carried by a PX4 vehicle as px4_msgs/VehicleOdometry (PX4 v1.14 to "
        "v1.18) for PX4's uXRCE-DDS bridge: position, attitude, velocities and variances in "
        "PX4's frames (world NED or FRD, body FRD), at rate_hz by capture stamps.");
    kParameters.declare(spec);
    spec.subscribes<ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                            "the tracked boards in the camera's optical frame");
    spec.publishes<VehicleOdometry>(topics::kPx4VisualOdometry, px4_qos(),
                                    "the vehicle's odometry");
  }

  explicit Px4OdometryComponent(Context& context) : Component(context), rate_(settings_.rate_hz) {
    if (settings_.board.empty()) {
      throw std::invalid_argument("board: name the board the vehicle carries");
    }
    const std::string frame = settings_.pose_frame;
    if (frame != "frd" && frame != "ned") {
      throw std::invalid_argument("pose_frame: '" + frame + "'; expected frd or ned");
    }
    frame_ = frame == "ned" ? Px4Frame::Ned : Px4Frame::Frd;
    // No camera: a volume's poses, in the world frame already.
    if (!settings_.camera_in_world.empty()) {
      world_from_optical_ =
          world_from_optical(from_xyz_rpy(settings_.camera_in_world, "camera_in_world"));
    }
    board_from_vehicle_ = from_xyz_rpy(settings_.vehicle_in_board, "vehicle_in_board");
    const double rate = settings_.rate_hz;
    publisher_ = create_publisher<VehicleOdometry>(topics::kPx4VisualOdometry);
    create_subscription<ConstellationPoseArray>(
        topics::kPoses, [this](const ConstellationPoseArray& poses) { on_poses(poses); });
    log().info("{} as PX4 odometry ({} world, FRD body) at {} on {}", settings_.board,
               frame == "ned" ? "NED" : "FRD",
               rate > 0 ? fmt::format("{} Hz at most", rate) : std::string("every frame"),
               topics::kPx4VisualOdometry);
  }

  ~Px4OdometryComponent() override {
    log().info("{} messages sent; {} poses of {} skipped for the rate, {} in another frame", sent_,
               skipped_for_rate_, settings_.board, wrong_frame_);
  }

 private:
  void on_poses(const ConstellationPoseArray& poses) {
    for (const ConstellationPose& pose : poses.poses()) {
      if (pose.name() != settings_.board) continue;
      std::string frame_id = pose.pose().header().frame_id();
      if (frame_id.empty()) frame_id = poses.header().frame_id();
      if (!frame_id.empty() && frame_id != settings_.optical_frame) {
        if (wrong_frame_++ == 0) {
          log().warn("{} in frame '{}', not optical_frame '{}': skipped (and counted)",
                     settings_.board, frame_id, settings_.optical_frame);
        }
        continue;
      }
      const std::optional<BodyState> board = body_state(pose);
      if (!board) continue;
      const int64_t stamp_ns = to_nanoseconds(pose.pose().header().stamp());
      if (!rate_.due(settings_.board, stamp_ns)) {
        ++skipped_for_rate_;
        continue;
      }
      const Px4Odometry odometry =
          to_px4(attached(seen_from(world_from_optical_, *board), board_from_vehicle_), frame_);

      VehicleOdometry message;
      message.timestamp(microseconds(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                         std::chrono::system_clock::now().time_since_epoch())
                                         .count()));
      message.timestamp_sample(microseconds(stamp_ns));
      message.pose_frame(static_cast<uint8_t>(odometry.frame));
      message.position(to_floats<3>(odometry.position));
      message.q(to_floats<4>(
          Eigen::Vector4d(odometry.q[0], odometry.q[1], odometry.q[2], odometry.q[3])));
      message.velocity_frame(static_cast<uint8_t>(odometry.frame));
      message.velocity(to_floats<3>(odometry.velocity));
      message.angular_velocity(to_floats<3>(odometry.angular_velocity));
      message.position_variance(to_floats<3>(odometry.position_variance));
      message.orientation_variance(to_floats<3>(odometry.orientation_variance));
      message.velocity_variance(to_floats<3>(odometry.velocity_variance));
      message.reset_counter(0);
      message.quality(100);  // unused by PX4; 0 would say "invalid"
      publisher_.publish(message);
      ++sent_;
    }
  }

  Px4Frame frame_ = Px4Frame::Frd;
  Eigen::Isometry3d world_from_optical_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d board_from_vehicle_ = Eigen::Isometry3d::Identity();
  StampRate rate_;
  Publisher<VehicleOdometry> publisher_;
  uint64_t sent_ = 0, skipped_for_rate_ = 0, wrong_frame_ = 0;
};

}  // namespace
}  // namespace mocap::outputs

MOCAP_REGISTER_COMPONENT(mocap::outputs::Px4OdometryComponent, "px4_odometry")
