#include "recording/motion_export/point_table.hpp"

#include <algorithm>

#include <Eigen/Geometry>

namespace mocap::motion_export {
namespace {

double median_rate(const std::vector<int64_t>& frames) {
  if (frames.size() < 2) return 0;
  std::vector<int64_t> intervals;
  for (size_t i = 1; i < frames.size(); ++i) intervals.push_back(frames[i] - frames[i - 1]);
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  return 1e9 / static_cast<double>(intervals[intervals.size() / 2]);
}

// The index of `stamp` in the table's frames, if it is one.
std::optional<uint32_t> frame_of(const PointTable& table, int64_t stamp) {
  const auto found = std::lower_bound(table.frames.begin(), table.frames.end(), stamp);
  if (found == table.frames.end() || *found != stamp) return std::nullopt;
  return static_cast<uint32_t>(found - table.frames.begin());
}

}  // namespace

PointTable make_point_table(std::vector<int64_t> frames) {
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  PointTable table;
  table.rate_hz = median_rate(frames);
  table.frames = std::move(frames);
  return table;
}

void add_body_points(PointTable& table, const std::string& body,
                     const std::vector<StampedPose>& poses) {
  const std::pair<const char*, Eigen::Vector3d> points[] = {
      {"origin", Eigen::Vector3d::Zero()},
      {"x", Eigen::Vector3d(kAxisLength, 0, 0)},
      {"y", Eigen::Vector3d(0, kAxisLength, 0)},
      {"z", Eigen::Vector3d(0, 0, kAxisLength)}};
  for (const auto& [suffix, in_body] : points) {
    PointColumn column{body + "_" + suffix,
                       suffix == std::string("origin") ? "origin of " + body
                                                       : std::string(suffix) + " axis of " + body,
                       {}};
    for (const StampedPose& pose : poses) {
      if (const auto frame = frame_of(table, pose.stamp_ns)) {
        column.samples.push_back({*frame, pose.world_from_body * in_body, 0});
      }
    }
    std::sort(column.samples.begin(), column.samples.end(),
              [](const PointSample& a, const PointSample& b) { return a.frame < b.frame; });
    table.points.push_back(std::move(column));
  }
}

void add_marker_points(PointTable& table, const MarkerTrajectories& markers) {
  for (const auto& [key, samples] : markers.markers()) {
    PointColumn column{key.name(), key.description(), {}};
    for (const MarkerSample& sample : samples) {
      if (const auto frame = frame_of(table, sample.stamp_ns)) {
        column.samples.push_back({*frame, sample.position, sample.cameras});
      }
    }
    std::sort(column.samples.begin(), column.samples.end(),
              [](const PointSample& a, const PointSample& b) { return a.frame < b.frame; });
    table.points.push_back(std::move(column));
  }
}

void PointRows::go_to(uint32_t frame) {
  current_.assign(table_.points.size(), nullptr);
  for (size_t p = 0; p < table_.points.size(); ++p) {
    const std::vector<PointSample>& samples = table_.points[p].samples;
    size_t& next = next_[p];
    while (next < samples.size() && samples[next].frame < frame) ++next;
    if (next < samples.size() && samples[next].frame == frame) current_[p] = &samples[next];
  }
}

}  // namespace mocap::motion_export
