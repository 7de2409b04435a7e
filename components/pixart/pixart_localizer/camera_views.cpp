#include "pixart/pixart_localizer/camera_views.hpp"

#include <stdexcept>
#include <string>

namespace mocap::pixart::localization {

bool LatestCameraViews::update(size_t camera, int64_t stamp_ns,
                               std::vector<Eigen::Vector2d> points) {
  if (camera >= views_.size()) {
    throw std::out_of_range("camera index " + std::to_string(camera) + " of " +
                            std::to_string(views_.size()) + " cameras");
  }
  CameraView& view = views_[camera];
  if (view.received && stamp_ns < view.stamp_ns) return false;
  view.received = true;
  view.stamp_ns = stamp_ns;
  view.points = std::move(points);
  if (!newest_stamp_ns_ || stamp_ns > *newest_stamp_ns_) newest_stamp_ns_ = stamp_ns;
  return true;
}

}  // namespace mocap::pixart::localization
