#include <mocap/calibration/pinhole_camera.hpp>

#include <cmath>
#include <stdexcept>

namespace mocap::calibration {

PinholeCamera::PinholeCamera(int width, int height, const PinholeIntrinsics& intrinsics)
    : width_(width), height_(height), intrinsics_(intrinsics) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("pinhole camera: image size must be positive");
  }
  if (!(intrinsics.fx > 0) || !(intrinsics.fy > 0) || !std::isfinite(intrinsics.fx) ||
      !std::isfinite(intrinsics.fy)) {
    throw std::invalid_argument("pinhole camera: focal lengths must be positive");
  }
  parameters_ = {intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy};
  for (size_t i = 0; i < intrinsics.distortion.size(); ++i) {
    parameters_[4 + i] = intrinsics.distortion[i];
  }
  has_distortion_ = false;
  for (double k : intrinsics.distortion) {
    if (!std::isfinite(k)) throw std::invalid_argument("pinhole camera: distortion is not finite");
    has_distortion_ = has_distortion_ || k != 0.0;
  }
}

std::optional<Eigen::Vector2d> PinholeCamera::project(const Eigen::Vector3d& point) const {
  Eigen::Vector2d pixel;
  if (!pinhole_project(parameters_.data(), point.data(), pixel.data())) return std::nullopt;
  return pixel;
}

std::optional<Eigen::Vector3d> PinholeCamera::unproject(const Eigen::Vector2d& pixel) const {
  Eigen::Vector2d target((pixel.x() - intrinsics_.cx) / intrinsics_.fx,
                         (pixel.y() - intrinsics_.cy) / intrinsics_.fy);
  if (!has_distortion_) return Eigen::Vector3d(target.x(), target.y(), 1.0);
  Eigen::Vector2d normalised;
  if (!pinhole_undistort(intrinsics_.distortion.data(), target.data(), normalised.data())) {
    return std::nullopt;
  }
  return Eigen::Vector3d(normalised.x(), normalised.y(), 1.0);
}

std::unique_ptr<CameraModel> PinholeCamera::clone() const {
  return std::make_unique<PinholeCamera>(*this);
}

}  // namespace mocap::calibration
