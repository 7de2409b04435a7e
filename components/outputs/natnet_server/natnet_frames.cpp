#include "outputs/natnet_server/natnet_frames.hpp"

#include <set>

#include <fmt/format.h>

namespace mocap::natnet {
namespace {

std::string marker_name(const std::string& body, size_t marker) {
  return fmt::format("{}_{}", body, marker + 1);
}

}  // namespace

std::vector<StreamedBody> streamed_bodies(const volume::RigidBodyDatabase& bodies,
                                          const volume::SwarmDatabase& robots) {
  struct Entry {
    StreamedBody body;
    std::optional<int32_t> asked;
  };
  std::vector<Entry> entries;
  for (const volume::RigidBody& body : bodies.bodies) {
    entries.push_back({{body.name, 0, body.markers}, body.streaming_id});
  }
  for (const volume::SwarmRobot& robot : robots.robots) {
    entries.push_back({{robot.name, 0, robots.layouts[robot.layout].markers}, robot.streaming_id});
  }
  std::map<int32_t, std::string> taken;
  std::set<std::string> names;
  for (const Entry& entry : entries) {
    if (!names.insert(entry.body.name).second) {
      throw volume::RigidBodyError(
          fmt::format("'{}' is both a body and a robot: NatNet clients would not tell them apart",
                      entry.body.name));
    }
    if (!entry.asked) continue;
    auto [found, added] = taken.emplace(*entry.asked, entry.body.name);
    if (!added) {
      throw volume::RigidBodyError(fmt::format("'{}' and '{}' have streaming_id {}", found->second,
                                               entry.body.name, *entry.asked));
    }
  }
  std::vector<StreamedBody> streamed;
  int32_t next = 1;
  for (Entry& entry : entries) {
    if (entry.asked) {
      entry.body.id = *entry.asked;
    } else {
      while (taken.count(next)) ++next;
      if (next > volume::kMaxStreamingId) {
        throw volume::RigidBodyError(fmt::format("no streaming id left for '{}'", entry.body.name));
      }
      entry.body.id = next;
      taken.emplace(next, entry.body.name);
    }
    streamed.push_back(std::move(entry.body));
  }
  return streamed;
}

std::optional<UpAxis> parse_up_axis(const std::string& text) {
  if (text == "z_up") return UpAxis::z_up;
  if (text == "y_up") return UpAxis::y_up;
  return std::nullopt;
}

std::optional<LegacyMarkers> parse_legacy_markers(const std::string& text) {
  if (text == "none") return LegacyMarkers::none;
  if (text == "unlabeled") return LegacyMarkers::unlabeled;
  if (text == "all") return LegacyMarkers::all;
  return std::nullopt;
}

FrameBuilder::FrameBuilder(std::vector<StreamedBody> known, FrameBuilderOptions options)
    : bodies_(std::move(known)), last_pose_(bodies_.size()), options_(options) {
  for (size_t b = 0; b < bodies_.size(); ++b) index_of_[bodies_[b].name] = b;
}

Eigen::Vector3f FrameBuilder::to_axes(const Eigen::Vector3d& world) const {
  if (options_.up_axis == UpAxis::z_up) return world.cast<float>();
  return Eigen::Vector3d(world.x(), world.z(), -world.y()).cast<float>();
}

Eigen::Quaternionf FrameBuilder::to_axes(const Eigen::Quaterniond& world) const {
  if (options_.up_axis == UpAxis::z_up) return world.cast<float>();
  // The rotation that takes our axes to y-up ones: -90 degrees about x.
  const Eigen::Quaterniond y_up_from_world(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  return (y_up_from_world * world).normalized().cast<float>();
}

Descriptions FrameBuilder::descriptions() const {
  Descriptions descriptions;
  for (const StreamedBody& body : bodies_) {
    RigidBodyDescription described;
    described.name = body.name;
    described.id = body.id;
    MarkerSetDescription set;
    set.name = body.name;
    for (size_t m = 0; m < body.markers.size(); ++m) {
      described.markers.push_back(body.markers[m].cast<float>());
      described.marker_names.push_back(marker_name(body.name, m));
    }
    set.marker_names = described.marker_names;
    descriptions.rigid_bodies.push_back(std::move(described));
    if (!set.marker_names.empty()) descriptions.marker_sets.push_back(std::move(set));
  }
  return descriptions;
}

FrameOfData FrameBuilder::build(const FusedFrame& fused, bool* new_bodies) {
  if (new_bodies) *new_bodies = false;
  if (!first_capture_ns_) first_capture_ns_ = fused.capture_ns;
  std::vector<std::optional<Eigen::Isometry3d>> posed(bodies_.size());
  for (const PosedBody& pose : fused.bodies) {
    auto found = index_of_.find(pose.name);
    if (found == index_of_.end()) {
      int32_t id = 1;
      for (const StreamedBody& body : bodies_) id = std::max(id, body.id + 1);
      found = index_of_.emplace(pose.name, bodies_.size()).first;
      bodies_.push_back({pose.name, std::min(id, volume::kMaxStreamingId), {}});
      last_pose_.emplace_back();
      posed.emplace_back();
      if (new_bodies) *new_bodies = true;
    }
    posed[found->second] = pose.world_from_body;
    last_pose_[found->second] = pose.world_from_body;
  }

  FrameOfData frame;
  frame.timestamp_s = static_cast<double>(fused.capture_ns - *first_capture_ns_) * 1e-9;
  frame.stamps.camera_mid_exposure = static_cast<uint64_t>(fused.capture_ns);
  frame.stamps.camera_data_received = static_cast<uint64_t>(fused.data_received_ns);

  // Each body's markers where seen this frame.
  std::vector<std::vector<std::optional<Eigen::Vector3f>>> seen(bodies_.size());
  for (size_t b = 0; b < bodies_.size(); ++b) seen[b].resize(bodies_[b].markers.size());
  for (const CloudMarker& marker : fused.markers) {
    LabeledMarkerData labeled;
    labeled.position = to_axes(marker.position.cast<double>());
    labeled.size_m = options_.marker_size_m;
    const auto body = static_cast<size_t>(marker.body);
    const bool owned =
        marker.body >= 0 && body < bodies_.size() && marker.marker < bodies_[body].markers.size();
    if (marker.body >= 0 && !owned) ++markers_of_unknown_bodies_;
    if (owned) {
      labeled.id = (bodies_[body].id << 16) | (marker.marker + 1);
      labeled.flags = kHasModel | kPointCloudSolved;
      if (posed[body]) {
        labeled.residual_m = static_cast<float>(
            (marker.position.cast<double>() - *posed[body] * bodies_[body].markers[marker.marker])
                .norm());
      }
      seen[body][marker.marker] = marker.position;
    } else {
      labeled.id = static_cast<int32_t>(marker.id & 0xFFFF);
      labeled.flags = kUnlabeled | kPointCloudSolved;
    }
    if (options_.legacy_markers == LegacyMarkers::all ||
        (options_.legacy_markers == LegacyMarkers::unlabeled && !owned)) {
      frame.other_markers.push_back(labeled.position);
    }
    frame.labeled_markers.push_back(labeled);
  }

  for (size_t b = 0; b < bodies_.size(); ++b) {
    const StreamedBody& body = bodies_[b];
    const std::optional<Eigen::Isometry3d>& pose = posed[b] ? posed[b] : last_pose_[b];
    RigidBodyData data;
    data.id = body.id;
    data.tracking_valid = posed[b].has_value();
    if (pose) {
      data.position = to_axes(Eigen::Vector3d(pose->translation()));
      data.orientation = to_axes(Eigen::Quaterniond(pose->linear()));
    }
    double error_sum = 0;
    int error_count = 0;
    MarkerSetData set;
    set.name = body.name;
    for (size_t m = 0; m < body.markers.size(); ++m) {
      const Eigen::Vector3d placed =
          pose ? Eigen::Vector3d(*pose * body.markers[m]) : Eigen::Vector3d::Zero();
      if (seen[b][m]) {
        if (posed[b]) {
          error_sum += (seen[b][m]->cast<double>() - placed).norm();
          ++error_count;
        }
        set.positions.push_back(to_axes(seen[b][m]->cast<double>()));
      } else {
        set.positions.push_back(to_axes(placed));
      }
    }
    data.mean_error_m = error_count > 0 ? static_cast<float>(error_sum / error_count) : 0.0f;
    frame.rigid_bodies.push_back(data);
    if (!set.positions.empty()) frame.marker_sets.push_back(std::move(set));
  }
  return frame;
}

}  // namespace mocap::natnet
