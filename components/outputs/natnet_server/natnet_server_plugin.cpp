// natnet_server: the volume's bodies, marker cloud and capture times to NatNet clients (OptiTrack's
// protocol: crazyswarm2's motion_capture_tracking, natnet_ros2, MOCAP4ROS2's OptiTrack driver,
// OptiTrack's samples), as a Motive host streams them. Each /mocap/poses array and the
// /mocap/markers cloud of the same capture time make one frame; until a cloud has come (a graph
// without one), poses go out alone.
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <mocap/component.hpp>
#include <mocap/component_spec.hpp>
#include <mocap/config_files.hpp>
#include <mocap/health.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>

#include "common/marker_cloud_message/marker_cloud_message.hpp"
#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "outputs/natnet_server/natnet_frames.hpp"
#include "outputs/natnet_server/natnet_server.hpp"

namespace mocap::natnet {
namespace {

using mocap_msgs::msg::ConstellationPose;
using mocap_msgs::msg::ConstellationPoseArray;
using sensor_msgs::msg::PointCloud2;

// The server's options with what only the plugin reads.
struct Settings : ServerOptions {
  std::string natnet_version = "4.1";
  std::string up_axis = "z_up";
  std::string bodies = mocap::config_file("volume/bodies.yaml");
  std::string robots;
  std::string legacy_markers = "none";
  double marker_size_m = 0.014;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("address",
             "IPv4 address to listen on: this machine only by default; 0.0.0.0 serves the "
             "network",
             &Settings::address)
        .add("command_port", "UDP port of NatNet's commands (0: any free port, logged)",
             &Settings::command_port)
        .range(0, 65535)
        .add("data_port", "UDP port frames leave from, and multicast goes to", &Settings::data_port)
        .range(1, 65535)
        .add("multicast",
             "frames to multicast_group on multicast_interface (TTL 1) instead of to each "
             "client",
             &Settings::multicast)
        .add("multicast_group", "IPv4 multicast group", &Settings::multicast_group)
        .add("multicast_interface",
             "interface multicast leaves by (eth0); empty: lo for a loopback address, else the "
             "address's own",
             &Settings::multicast_interface)
        .add("natnet_version",
             "bitstream for clients that ask for none, and multicast: 3.0 to 4.2 (4.1: what "
             "libmotioncapture reads)",
             &Settings::natnet_version)
        .add("up_axis",
             "z_up: our world frame (crazyswarm2, ROS drivers); y_up: Motive's default axes",
             &Settings::up_axis)
        .add("bodies", "the fusion's rigid bodies file (names, markers, streaming_id)",
             &Settings::bodies)
        .path()
        .add("robots", "the fusion's swarm file; empty: none", &Settings::robots)
        .path()
        .add("legacy_markers",
             "the legacy unlabeled list: none (every marker is in the labeled list; "
             "libmotioncapture counts both), unlabeled (as NatNet 2 servers) or all",
             &Settings::legacy_markers)
        .add("marker_size_m", "the size sent with each marker", &Settings::marker_size_m)
        .range(0, 1)
        .add("max_clients", "unicast clients served at once", &Settings::max_clients)
        .range(1, 1024)
        .add("client_timeout_s", "a unicast client silent this long is no longer sent to",
             &Settings::client_timeout_s)
        .range(0.1, 3600)
        .add("replies_per_s", "answers a second to one source address (burst: twice)",
             &Settings::replies_per_s)
        .range(1, 10000);

FrameBuilderOptions builder_options(const Settings& settings) {
  FrameBuilderOptions options;
  const std::optional<UpAxis> axis = parse_up_axis(settings.up_axis);
  if (!axis)
    throw std::invalid_argument("up_axis: '" + settings.up_axis + "'; expected z_up or y_up");
  options.up_axis = *axis;
  const std::optional<LegacyMarkers> legacy = parse_legacy_markers(settings.legacy_markers);
  if (!legacy) {
    throw std::invalid_argument("legacy_markers: '" + settings.legacy_markers +
                                "'; expected none, unlabeled or all");
  }
  options.legacy_markers = *legacy;
  options.marker_size_m = static_cast<float>(settings.marker_size_m);
  return options;
}

ServerOptions server_options(const Settings& settings) {
  ServerOptions options = settings;
  const std::optional<Version> version = parse_version(settings.natnet_version);
  if (!version || !version->supported()) {
    throw std::invalid_argument("natnet_version: '" + settings.natnet_version +
                                "'; expected 3.0 to 4.2");
  }
  options.version = *version;
  options.reply_burst = 2 * settings.replies_per_s;
  return options;
}

std::vector<StreamedBody> known_bodies(const Settings& settings) {
  const volume::RigidBodyDatabase bodies =
      settings.bodies.empty()
          ? volume::RigidBodyDatabase{}
          : volume::load_rigid_bodies(settings.bodies, 0, volume::kNoConfusionCheck);
  const volume::SwarmDatabase robots =
      settings.robots.empty() ? volume::SwarmDatabase{} : volume::load_swarm(settings.robots, 0);
  return streamed_bodies(bodies, robots);
}

class NatNetServer final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Serves the volume's bodies, marker cloud and capture times to NatNet clients "
        "(OptiTrack's protocol, as Motive streams it): descriptions with streaming ids, a frame "
        "per fused capture with rigid bodies, labeled and unlabeled markers and the camera, "
        "received and transmit stamps; unicast to each client or multicast.");
    kParameters.declare(spec);
    spec.subscribes<ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                            "the bodies, frame 'world' (volume_fusion)");
    spec.subscribes<PointCloud2>(topics::kMarkers, Qos::sensor_data(),
                                 "the fused markers, labeled by body (volume_fusion)");
  }

  explicit NatNetServer(Context& context)
      : Component(context), builder_(known_bodies(settings_), builder_options(settings_)) {
    try {
      server_ = std::make_unique<Server>(server_options(settings_));
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(e.what());  // names the parameter at fault
    }
    server_->set_descriptions(builder_.descriptions());
    create_subscription<ConstellationPoseArray>(
        topics::kPoses, [this](const ConstellationPoseArray& poses) { on_poses(poses); });
    create_subscription<PointCloud2>(topics::kMarkers,
                                     [this](const PointCloud2& cloud) { on_markers(cloud); });
    const std::string served = fmt::format(
        "NatNet {} on {}:{} ({} bodies described, {}, {})", settings_.natnet_version,
        settings_.address, server_->command_port(), builder_.descriptions().rigid_bodies.size(),
        settings_.up_axis,
        settings_.multicast
            ? fmt::format("multicast to {}:{}", settings_.multicast_group, settings_.data_port)
            : std::string("unicast to each client"));
    if (server_->loopback_only()) {
      log().info("{} (this machine only)", served);
    } else {
      log().warn("{}. Open to the network: any host that reaches port {} may ask for the stream",
                 served, server_->command_port());
    }
  }

  ~NatNetServer() override {
    const ServerStats s = server_->stats();
    log().info(
        "NatNet: {} frames ({} sent, {} dropped, {} cut to fit); {} clients served, {} timed "
        "out, {} disconnected, {} refused, {} dropped for malformed datagrams; {} requests, {} "
        "malformed, {} unrecognized, {} answers rate-limited",
        s.frames, s.datagrams_sent, s.datagrams_dropped, s.frames_too_large, s.clients_connected,
        s.clients_timed_out, s.clients_disconnected, s.clients_refused, s.clients_dropped_malformed,
        s.requests, s.malformed, s.unrecognized, s.replies_limited);
  }

  void report_health(HealthReport& report) override {
    const ServerStats s = server_->stats();
    latency_.report(report, "capture -> frames sent");
    report.add("clients", std::to_string(server_->clients()));
    report.add("frames", std::to_string(s.frames));
    report.add("frames without their cloud", std::to_string(frames_without_cloud_));
    report.add("datagrams dropped", std::to_string(s.datagrams_dropped));
    report.add("answers rate-limited", std::to_string(s.replies_limited));
    report.add("malformed datagrams", std::to_string(s.malformed));
    if (s.datagrams_dropped > datagrams_dropped_reported_) {
      report.flag(HealthLevel::warn,
                  fmt::format("{} frame datagrams the kernel could not take at once",
                              s.datagrams_dropped - datagrams_dropped_reported_));
    }
    datagrams_dropped_reported_ = s.datagrams_dropped;
    if (builder_.markers_of_unknown_bodies() > 0) {
      report.flag(HealthLevel::warn,
                  "markers of bodies this server does not know: give it the fusion's bodies and "
                  "robots files");
    }
  }

 private:
  void on_poses(const ConstellationPoseArray& array) {
    FusedFrame frame;
    frame.capture_ns = to_nanoseconds(array.header().stamp());
    frame.data_received_ns = to_nanoseconds(array.data_received());
    if (frame.data_received_ns == 0) {
      frame.data_received_ns =
          std::chrono::duration_cast<std::chrono::nanoseconds>(now().time_since_epoch()).count();
    }
    for (const ConstellationPose& pose : array.poses()) {
      if (const std::optional<Eigen::Isometry3d> placed = to_isometry(pose.pose().pose())) {
        frame.bodies.push_back({pose.name(), *placed});
      }
    }
    if (pending_poses_) send(*std::exchange(pending_poses_, std::nullopt), true);
    if (pending_cloud_ && pending_cloud_->first == frame.capture_ns) {
      frame.markers = std::move(pending_cloud_->second);
      pending_cloud_.reset();
      return send(frame, false);
    }
    if (!clouds_seen_) return send(frame, false);
    pending_poses_ = std::move(frame);
  }

  void on_markers(const PointCloud2& cloud) {
    clouds_seen_ = true;
    std::string problem;
    const auto markers = markers_from_point_cloud(cloud, &problem);
    if (!markers) {
      if (!bad_cloud_logged_)
        log().warn("{}: {}; such clouds are left out", topics::kMarkers, problem);
      bad_cloud_logged_ = true;
      return;
    }
    std::vector<CloudMarker> converted;
    for (const LabeledMarker& m : *markers)
      converted.push_back({m.position, m.body, m.marker, m.id});
    const int64_t stamp = to_nanoseconds(cloud.header().stamp());
    if (pending_poses_ && pending_poses_->capture_ns == stamp) {
      pending_poses_->markers = std::move(converted);
      return send(*std::exchange(pending_poses_, std::nullopt), false);
    }
    pending_cloud_ = {stamp, std::move(converted)};  // its poses still to come
  }

  void send(const FusedFrame& fused, bool without_cloud) {
    if (without_cloud) ++frames_without_cloud_;
    bool new_bodies = false;
    FrameOfData frame = builder_.build(fused, &new_bodies);
    if (new_bodies) server_->set_descriptions(builder_.descriptions());
    server_->send_frame(std::move(frame));
    latency_.add(
        std::chrono::nanoseconds(static_cast<int64_t>(Server::now_ticks()) - fused.capture_ns));
  }

  FrameBuilder builder_;
  std::unique_ptr<Server> server_;
  std::optional<FusedFrame> pending_poses_;
  std::optional<std::pair<int64_t, std::vector<CloudMarker>>> pending_cloud_;
  bool clouds_seen_ = false;
  bool bad_cloud_logged_ = false;
  uint64_t frames_without_cloud_ = 0;
  uint64_t datagrams_dropped_reported_ = 0;
  LatencyFigures latency_;
};

}  // namespace
}  // namespace mocap::natnet

MOCAP_REGISTER_COMPONENT(mocap::natnet::NatNetServer, "natnet_server")
