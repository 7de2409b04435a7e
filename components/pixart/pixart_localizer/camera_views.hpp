// Step 2a of the localizer: the latest sample of each camera, on the LED plane.
//
// Cameras are sampled at about the same instants but their samples arrive one after the
// other; the localizer works on what every camera saw last, and a camera whose last sample
// has grown old (point_merging.hpp) contributes nothing.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace mocap::pixart::localization {

// What one camera saw in one sample, on the LED plane (world frame).
struct CameraView {
  bool received = false;  // false until the camera's first sample
  int64_t stamp_ns = 0;
  std::vector<Eigen::Vector2d> points;
};

class LatestCameraViews {
 public:
  explicit LatestCameraViews(size_t camera_count) : views_(camera_count) {}

  // Makes this sample camera `camera`'s view, unless the camera already has a newer one
  // (returns false: out of order, dropped). Throws std::out_of_range for an unknown camera.
  bool update(size_t camera, int64_t stamp_ns, std::vector<Eigen::Vector2d> points);

  // Indexed like the cameras given to the constructor.
  const std::vector<CameraView>& views() const { return views_; }

  // The stamp of the newest view, or nothing before the first sample.
  std::optional<int64_t> newest_stamp_ns() const { return newest_stamp_ns_; }

 private:
  std::vector<CameraView> views_;
  std::optional<int64_t> newest_stamp_ns_;
};

}  // namespace mocap::pixart::localization
