// pose_outputs: the tracked boards as ROS 2 tools read them. Per board a
// geometry_msgs/PoseStamped on /mocap/<board>/pose and a nav_msgs/Odometry on
// /mocap/<board>/odom; every board on /tf, and the camera's mounting on /tf_static; every board
// of a frame in one motion_capture_tracking_interfaces/NamedPoseArray on /poses, as crazyswarm2's
// crazyflie_server reads a swarm's poses. Stamps are the poses' own, the capture time of their
// image; rates are kept by those stamps, so a replayed bag gives the live run's messages.
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <geometry_msgs/msg/pose_stamped.hpp>
#include <mocap/component.hpp>
#include <mocap/component_spec.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <motion_capture_tracking_interfaces/msg/named_pose_array.hpp>
#include <nav_msgs/msg/odometry.hpp>
#include <tf2_msgs/msg/tf_message.hpp>

#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "outputs/body_frames/body_state_message.hpp"
#include "outputs/body_frames/stamp_rate.hpp"

namespace mocap::outputs {
namespace {

using geometry_msgs::msg::PoseStamped;
using mocap_msgs::msg::ConstellationPose;
using mocap_msgs::msg::ConstellationPoseArray;
using motion_capture_tracking_interfaces::msg::NamedPoseArray;
using nav_msgs::msg::Odometry;
using tf2_msgs::msg::TFMessage;

std::array<double, 36> to_row_major(const Matrix6d& matrix) {
  std::array<double, 36> values{};
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(values.data()) = matrix;
  return values;
}

geometry_msgs::msg::Vector3 to_vector3(const Eigen::Vector3d& v) {
  geometry_msgs::msg::Vector3 message;
  message.x(v.x());
  message.y(v.y());
  message.z(v.z());
  return message;
}

// tf2_ros's TransformBroadcaster: reliable, volatile, the last 100 kept.
Qos tf_qos() {
  Qos qos = Qos::reliable();
  qos.history = History::KeepLast;
  qos.depth = 100;
  return qos;
}

struct Settings {
  std::string parent = "camera";
  std::string world_frame = "world";
  std::string camera_frame = "camera_ir";
  std::string optical_frame = "camera_ir_optical";
  std::vector<double> camera_in_world = {0, 0, 0, 0, 0, 0};
  std::string child_frame_prefix;
  double pose_rate_hz = 0.0;
  double odom_rate_hz = 0.0;
  double tf_rate_hz = 0.0;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("parent",
             "frame of the poses: camera (the camera's optical frame, as /mocap/poses) or "
             "world (through camera_in_world)",
             &Settings::parent)
        .add("world_frame", "name of the world frame", &Settings::world_frame)
        .add("camera_frame", "name of the camera's REP 103 body frame (x forward, y left, z up)",
             &Settings::camera_frame)
        .add("optical_frame",
             "name of the camera's optical frame (z forward, x right, y down), the frame "
             "of /mocap/poses; poses in world_frame (a volume's) pass as they are, poses "
             "in any other frame are counted and skipped",
             &Settings::optical_frame)
        .add("camera_in_world",
             "camera_frame in world_frame: x, y, z (m), roll, pitch, yaw (rad); [] for no "
             "camera (a volume's poses, in world_frame already): nothing on /tf_static",
             &Settings::camera_in_world)
        .add("child_frame_prefix", "prefix of the boards' frame names (the board's name follows)",
             &Settings::child_frame_prefix)
        .add("pose_rate_hz", "most PoseStamped a second per board (0: every frame)",
             &Settings::pose_rate_hz)
        .min(0)
        .add("odom_rate_hz", "most Odometry a second per board (0: every frame)",
             &Settings::odom_rate_hz)
        .min(0)
        .add("tf_rate_hz", "most /tf transforms a second per board (0: every frame)",
             &Settings::tf_rate_hz)
        .min(0);

class PoseOutputs final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "The tracked boards as ROS 2 tools read them: per board geometry_msgs/PoseStamped on "
        "/mocap/<board>/pose and nav_msgs/Odometry (pose and twist with covariances, twist in "
        "the board's frame) on /mocap/<board>/odom, every board on /tf, the camera's mounting "
        "on /tf_static. Frames follow REP 103/105; stamps are the images' capture times.");
    kParameters.declare(spec);
    spec.subscribes<ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                            "the tracked boards in the camera's optical frame");
    spec.publishes<PoseStamped>(topics::kBoardPose, Qos::sensor_data(), "each board's pose");
    spec.publishes<Odometry>(topics::kBoardOdometry, Qos::sensor_data(),
                             "each board's pose and velocity with their covariances");
    // tf2's own QoS: its listeners are reliable readers, which a best-effort writer never meets.
    spec.publishes<TFMessage>(topics::kTf, tf_qos(), "the boards in the parent frame");
    spec.publishes<TFMessage>(topics::kTfStatic, Qos::latched(),
                              "world -> camera_frame -> optical_frame, once");
    spec.publishes<NamedPoseArray>(topics::kNamedPoses, Qos::sensor_data(),
                                   "every board of a frame by name, in the parent frame (a "
                                   "swarm's poses as crazyswarm2's crazyflie_server reads them)");
  }

  explicit PoseOutputs(Context& context)
      : Component(context),
        in_world_(settings_.parent == "world"),
        pose_rate_(settings_.pose_rate_hz),
        odom_rate_(settings_.odom_rate_hz),
        tf_rate_(settings_.tf_rate_hz) {
    const std::string parent = settings_.parent;
    if (parent != "camera" && parent != "world") {
      throw std::invalid_argument("parent: '" + parent + "'; expected camera or world");
    }
    const std::string camera_frame = settings_.camera_frame;
    for (const auto& [name, value] : {std::pair{"world_frame", settings_.world_frame},
                                      {"camera_frame", camera_frame},
                                      {"optical_frame", settings_.optical_frame}}) {
      if (value.empty()) throw std::invalid_argument(std::string(name) + " is empty");
    }
    // No camera: a volume's poses, in the world frame already; nothing to mount.
    const bool camera = !settings_.camera_in_world.empty();
    const Eigen::Isometry3d world_from_camera =
        camera ? from_xyz_rpy(settings_.camera_in_world, "camera_in_world")
               : Eigen::Isometry3d::Identity();
    Eigen::Isometry3d camera_from_optical = Eigen::Isometry3d::Identity();
    camera_from_optical.linear() = optical_in_body().toRotationMatrix();
    world_from_optical_ = world_from_camera * camera_from_optical;

    tf_ = create_publisher<TFMessage>(topics::kTf);
    named_ = create_publisher<NamedPoseArray>(topics::kNamedPoses);
    create_subscription<ConstellationPoseArray>(
        topics::kPoses, [this](const ConstellationPoseArray& poses) { on_poses(poses); });

    if (!camera) {
      log().info("bodies of {} in frame {} on /mocap/<board>/pose, /mocap/<board>/odom and /tf",
                 topics::kPoses, settings_.world_frame);
      return;
    }
    // Latched: a tf2 listener that starts later still gets the camera's place.
    TFMessage mounted;
    std_msgs::msg::Header header;
    header.stamp(to_time_msg(now()));
    header.frame_id(settings_.world_frame);
    mounted.transforms().push_back(to_transform(header, camera_frame, world_from_camera));
    header.frame_id(camera_frame);
    mounted.transforms().push_back(
        to_transform(header, settings_.optical_frame, camera_from_optical));
    create_publisher<TFMessage>(topics::kTfStatic).publish(mounted);

    log().info(
        "boards of {} in frame {} on /mocap/<board>/pose, /mocap/<board>/odom and /tf; "
        "{} -> {} -> {} on /tf_static",
        topics::kPoses, in_world_ ? settings_.world_frame : settings_.optical_frame,
        settings_.world_frame, camera_frame, settings_.optical_frame);
  }

  ~PoseOutputs() override {
    log().info(
        "{} pose arrays: {} boards published; {} poses in another frame than {}, {} "
        "invalid, {} boards without per-board topics",
        arrays_, boards_published_, wrong_frame_, settings_.optical_frame, invalid_,
        unpublishable_.size());
  }

  void report_health(HealthReport& report) override {
    latency_.report(report, "capture -> outputs sent");
    report.add("poses in another frame", std::to_string(wrong_frame_));
    report.add("invalid poses", std::to_string(invalid_));
    if (wrong_frame_ > 0) {
      report.flag(HealthLevel::warn, fmt::format("{} pose(s) in another frame than '{}' skipped",
                                                 wrong_frame_, settings_.optical_frame));
    }
  }

 private:
  struct BoardOutputs {
    Publisher<PoseStamped> pose;
    Publisher<Odometry> odom;
  };

  void on_poses(const ConstellationPoseArray& poses) {
    ++arrays_;
    TFMessage transforms;
    NamedPoseArray named;
    for (const ConstellationPose& pose : poses.poses()) {
      std_msgs::msg::Header header = pose.pose().header();
      if (header.frame_id().empty()) header.frame_id(poses.header().frame_id());
      if (header.frame_id().empty()) header.frame_id(settings_.optical_frame);
      // A volume's poses (volume_fusion) are in the world frame already.
      const bool already_in_world = header.frame_id() == settings_.world_frame;
      if (header.frame_id() != settings_.optical_frame && !already_in_world) {
        if (wrong_frame_++ == 0) {
          log().warn("a pose in frame '{}', not optical_frame '{}': skipped (and counted)",
                     header.frame_id(), settings_.optical_frame);
        }
        continue;
      }
      std::optional<BodyState> measured = body_state(pose);
      if (!measured) {
        ++invalid_;
        continue;
      }
      BodyState board = *measured;
      if (in_world_ && !already_in_world) {
        board = seen_from(world_from_optical_, board);
        header.frame_id(settings_.world_frame);
      }
      const int64_t stamp_ns = to_nanoseconds(header.stamp());
      const std::string child = settings_.child_frame_prefix + pose.name();
      ++boards_published_;
      if (named.poses().empty()) named.header(header);
      motion_capture_tracking_interfaces::msg::NamedPose by_name;
      by_name.name(pose.name());
      by_name.pose(to_pose_message(board.parent_from_body));
      named.poses().push_back(std::move(by_name));
      if (tf_rate_.due(pose.name(), stamp_ns)) {
        transforms.transforms().push_back(to_transform(header, child, board.parent_from_body));
      }
      BoardOutputs* outputs = outputs_of(pose.name());
      if (outputs == nullptr) continue;
      if (pose_rate_.due(pose.name(), stamp_ns)) {
        PoseStamped message;
        message.header(header);
        message.pose(to_pose_message(board.parent_from_body));
        outputs->pose.publish(message);
      }
      if (odom_rate_.due(pose.name(), stamp_ns)) {
        const BodyTwist twist = twist_in_body(board);
        Odometry message;
        message.header(header);
        message.child_frame_id(child);
        message.pose().pose(to_pose_message(board.parent_from_body));
        message.pose().covariance(to_row_major(board.pose_covariance));
        message.twist().twist().linear(to_vector3(twist.linear));
        message.twist().twist().angular(to_vector3(twist.angular));
        message.twist().covariance(to_row_major(twist.covariance));
        outputs->odom.publish(message);
      }
    }
    if (!transforms.transforms().empty()) tf_.publish(transforms);
    if (!named.poses().empty()) named_.publish(named);
    latency_.add(now() - from_time_msg(poses.header().stamp()));
  }

  // The board's publishers, made when it is first seen; null when its name makes no topic
  // name (it is still on /tf).
  BoardOutputs* outputs_of(const std::string& board) {
    if (auto found = outputs_.find(board); found != outputs_.end()) return &found->second;
    if (unpublishable_.count(board) > 0) return nullptr;
    try {
      BoardOutputs outputs{
          create_publisher<PoseStamped>(topics::member_of(topics::kBoardPose, board)),
          create_publisher<Odometry>(topics::member_of(topics::kBoardOdometry, board))};
      return &outputs_.emplace(board, std::move(outputs)).first->second;
    } catch (const std::exception& e) {
      unpublishable_.insert(board);
      log().warn("board '{}' gets no /mocap/<board>/pose or /odom (still on /tf): {}", board,
                 e.what());
      return nullptr;
    }
  }

  const bool in_world_;
  Eigen::Isometry3d world_from_optical_ = Eigen::Isometry3d::Identity();
  StampRate pose_rate_, odom_rate_, tf_rate_;
  Publisher<TFMessage> tf_;
  std::map<std::string, BoardOutputs> outputs_;
  std::set<std::string> unpublishable_;
  Publisher<NamedPoseArray> named_;
  uint64_t arrays_ = 0, boards_published_ = 0, wrong_frame_ = 0, invalid_ = 0;
  LatencyFigures latency_;
};

}  // namespace
}  // namespace mocap::outputs

MOCAP_REGISTER_COMPONENT(mocap::outputs::PoseOutputs, "pose_outputs")
