// vrpn_server: every tracked board as a VRPN tracker named as the board, for VRPN clients
// (vrpn_client_ros, vrpn_mocap, Unity, MotionBuilder, a lab's own code): "board_a@host".
// Positions and orientations in the camera's optical frame, or the world's (camera_in_world,
// as pose_outputs); each report carries the image's capture time.
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/component.hpp>
#include <mocap/component_spec.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "outputs/body_frames/body_state_message.hpp"
#include "outputs/vrpn_server/vrpn_server.hpp"

namespace mocap::vrpn {
namespace {

using mocap_msgs::msg::ConstellationPose;
using mocap_msgs::msg::ConstellationPoseArray;

// The server's options with what only the plugin reads.
struct Settings : TrackerServerOptions {
  std::string frame = "camera";
  std::vector<double> camera_in_world = {0, 0, 0, 0, 0, 0};  // x y z roll pitch yaw
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("address",
             "IPv4 address to listen on: this machine only by default; 0.0.0.0 serves the "
             "network",
             &Settings::address)
        .add("port", "TCP and UDP port (0: any free port, logged)", &Settings::port)
        .range(0, 65535)
        .add("frame",
             "camera: the camera's optical frame, as /mocap/poses; world: through "
             "camera_in_world",
             &Settings::frame)
        .add("camera_in_world",
             "the camera's REP 103 body frame in the world: x, y, z (m), roll, pitch, yaw "
             "(rad)",
             &Settings::camera_in_world)
        .add("max_queued_bytes", "bytes a client may have waiting; beyond, it is dropped",
             &Settings::max_queued_bytes)
        .range(4096, 1 << 30);

class VrpnServer final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Serves every tracked board as a VRPN tracker named as the board (sensor 0: "
        "vrpn_Tracker Pos_Quat and Velocity reports, capture-time stamps) to VRPN clients: "
        "board_a@host, or board_a@tcp://host:port. Slow or dead clients are dropped, never "
        "waited for.");
    kParameters.declare(spec);
    spec.subscribes<ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                            "the tracked boards in the camera's optical frame");
  }

  explicit VrpnServer(Context& context) : Component(context) {
    const std::string frame = settings_.frame;
    if (frame != "camera" && frame != "world") {
      throw std::invalid_argument("frame: '" + frame + "'; expected camera or world");
    }
    const Eigen::Isometry3d world_from_camera =
        outputs::from_xyz_rpy(settings_.camera_in_world, "camera_in_world");
    if (frame == "world") world_from_optical_ = outputs::world_from_optical(world_from_camera);
    try {
      server_ = std::make_unique<TrackerServer>(settings_);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(e.what());  // names the parameter at fault
    }
    create_subscription<ConstellationPoseArray>(
        topics::kPoses, [this](const ConstellationPoseArray& poses) { on_poses(poses); });
    const std::string served = fmt::format(
        "VRPN trackers (one per board, in the {} frame) on {}:{} TCP and UDP; clients ask for "
        "BOARD@HOST",
        frame, settings_.address, server_->port());
    if (server_->loopback_only()) {
      log().info("{} (this machine only)", served);
    } else {
      log().warn(
          "{}. Open to the network: any host that reaches port {} may connect, and ask "
          "the server to connect back to it",
          served, server_->port());
    }
  }

  ~VrpnServer() override {
    const TrackerServerStats s = server_->stats();
    log().info(
        "VRPN: {} reports; {} clients served, {} left, {} dropped too slow, {} refused; "
        "{} connection requests ({} malformed, {} naming another host than their source, {} not "
        "followed), {} pongs",
        s.reports, s.clients_connected, s.clients_closed, s.clients_too_slow, s.clients_refused,
        s.connection_requests, s.bad_requests, s.requests_naming_another_host,
        s.connect_backs_limited, s.pongs);
  }

 private:
  void on_poses(const ConstellationPoseArray& poses) {
    for (const ConstellationPose& pose : poses.poses()) {
      const std::optional<outputs::BodyState> measured = outputs::body_state(pose);
      if (!measured) continue;
      const outputs::BodyState board = outputs::seen_from(world_from_optical_, *measured);
      TrackerReport report;
      report.stamp_ns = to_nanoseconds(pose.pose().header().stamp());
      report.position = board.parent_from_body.translation();
      report.orientation = Eigen::Quaterniond(board.parent_from_body.linear());
      report.linear_velocity = board.linear_velocity;
      report.angular_velocity = board.angular_velocity;
      server_->report(pose.name(), report);
    }
  }

  Eigen::Isometry3d world_from_optical_ = Eigen::Isometry3d::Identity();
  std::unique_ptr<TrackerServer> server_;
};

}  // namespace
}  // namespace mocap::vrpn

MOCAP_REGISTER_COMPONENT(mocap::vrpn::VrpnServer, "vrpn_server")
