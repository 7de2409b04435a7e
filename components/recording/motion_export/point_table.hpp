// A recording as named 3D points sampled at its frames: the rows C3D and TRC write. A body
// becomes four virtual points (its origin and the ends of its axes), a common way analysis tools
// read a rigid body from point trajectories; a marker is one point. Middleware-free.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "recording/motion_export/body_trajectories.hpp"
#include "recording/motion_export/marker_trajectories.hpp"

namespace mocap::motion_export {

// How far along its axes a body's virtual points "<body>_x", "_y", "_z" lie.
inline constexpr double kAxisLength = 0.1;  // metres

struct PointSample {
  uint32_t frame = 0;                                  // index into PointTable::frames
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame (z up), metres
  uint32_t cameras = 0;                                // bit c: camera c saw it; 0: virtual
};

struct PointColumn {
  std::string name;                  // "drone_origin", "drone_3", "unlabeled_1234"
  std::string description;           // "origin of drone", "marker 3 of drone"
  std::vector<PointSample> samples;  // ascending frames; a frame without one is a gap
};

struct PointTable {
  std::vector<int64_t> frames;  // capture stamps, ascending, each once
  double rate_hz = 0;           // of the median interval between frames (0: fewer than two)
  std::vector<PointColumn> points;
};

// A table of no points at `frames` (any order, repeats allowed).
PointTable make_point_table(std::vector<int64_t> frames);

// `poses`' body as four columns "<body>_origin", "_x", "_y", "_z"; a pose at a stamp that is no
// frame of the table is left out.
void add_body_points(PointTable& table, const std::string& body,
                     const std::vector<StampedPose>& poses);

// Every marker of `markers` as a column, in MarkerKey's order.
void add_marker_points(PointTable& table, const MarkerTrajectories& markers);

// Walks a table frame by frame: at(point) is that point's sample at the current frame, if any.
class PointRows {
 public:
  explicit PointRows(const PointTable& table) : table_(table), next_(table.points.size(), 0) {}
  // Moves to `frame` (ascending from 0, one call per frame).
  void go_to(uint32_t frame);
  const PointSample* at(size_t point) const { return current_[point]; }

 private:
  const PointTable& table_;
  std::vector<size_t> next_;
  std::vector<const PointSample*> current_;
};

}  // namespace mocap::motion_export
