// What a NatNet client is told of our bodies and markers: the bodies' descriptions with their
// streaming ids, and each fused frame (poses and marker cloud) as a NatNet frame, in the up axis
// the client expects.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "outputs/natnet_server/natnet_protocol.hpp"
#include "volume/rigid_bodies/rigid_body_database.hpp"
#include "volume/swarm/swarm_database.hpp"

namespace mocap::natnet {

// A body as streamed: its streaming id and its markers in its own frame (one for a single-marker
// robot; none for a body known only by name, as a board of a single-camera pipeline).
struct StreamedBody {
  std::string name;
  int32_t id = 0;
  std::vector<Eigen::Vector3d> markers;
};

// The bodies then the robots (the volume's order: a marker cloud's `body` indexes this list),
// each with its streaming_id or, where none is given, the lowest id no other body takes.
// Throws volume::RigidBodyError naming both when a body and a robot share a name or an id.
std::vector<StreamedBody> streamed_bodies(const volume::RigidBodyDatabase& bodies,
                                          const volume::SwarmDatabase& robots);

enum class UpAxis {
  z_up,  // our world frame as it is (REP 103: x forward, y left, z up)
  y_up,  // Motive's default: (x, z, -y) of ours, y up
};

// "z_up" or "y_up"; nullopt otherwise.
std::optional<UpAxis> parse_up_axis(const std::string& text);

// What the legacy unlabeled list ("other markers", before NatNet 2.3's labeled list) holds. Every
// marker is in the labeled list, flagged unlabeled or not; libmotioncapture (crazyswarm2) makes
// its point cloud of both lists, so anything here it counts twice.
enum class LegacyMarkers {
  none,       // nothing
  unlabeled,  // the markers no body claims, as NatNet 2 servers sent them
  all,        // every marker
};

// "none", "unlabeled" or "all"; nullopt otherwise.
std::optional<LegacyMarkers> parse_legacy_markers(const std::string& text);

struct FrameBuilderOptions {
  UpAxis up_axis = UpAxis::z_up;
  LegacyMarkers legacy_markers = LegacyMarkers::none;
  float marker_size_m = 0.014f;  // NatNet's marker size; ours are not measured
};

// One pose of a frame, in the world frame.
struct PosedBody {
  std::string name;
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
};

// One marker of the frame's cloud, world frame: `body` indexes streamed_bodies() (-1: unlabeled),
// `marker` its marker in that body, `id` its track's.
struct CloudMarker {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  int32_t body = -1;
  uint16_t marker = 0;
  uint32_t id = 0;
};

struct FusedFrame {
  int64_t capture_ns = 0;        // the frame's capture time (mid-exposure), system clock
  int64_t data_received_ns = 0;  // when the graph had the frame's camera data
  std::vector<PosedBody> bodies;
  std::vector<CloudMarker> markers;
};

class FrameBuilder {
 public:
  FrameBuilder(std::vector<StreamedBody> known, FrameBuilderOptions options);

  // Every body known or met so far, with a marker set per body that has markers.
  Descriptions descriptions() const;

  // The frame (frame number and transmit stamp left to the server): every body described, those
  // not posed in this frame with their last pose and tracking_valid false; the labeled markers
  // (every cloud marker: a body's as model id << 16 | marker + 1, the others flagged unlabeled
  // with the low 16 bits of their track id), each body's marker set (its markers where seen, else
  // where its pose puts them) and mean error (metres, over its markers seen). A pose whose name is
  // not known is given the next free id; `new_bodies` tells that the descriptions changed.
  FrameOfData build(const FusedFrame& fused, bool* new_bodies);

  // Cloud markers whose body index was beyond the known bodies (the server's bodies/robots files
  // are not the fusion's): sent as unlabeled.
  uint64_t markers_of_unknown_bodies() const { return markers_of_unknown_bodies_; }

 private:
  Eigen::Vector3f to_axes(const Eigen::Vector3d& world) const;
  Eigen::Quaternionf to_axes(const Eigen::Quaterniond& world) const;

  std::vector<StreamedBody> bodies_;
  std::map<std::string, size_t> index_of_;
  std::vector<std::optional<Eigen::Isometry3d>> last_pose_;
  FrameBuilderOptions options_;
  std::optional<int64_t> first_capture_ns_;
  uint64_t markers_of_unknown_bodies_ = 0;
};

}  // namespace mocap::natnet
