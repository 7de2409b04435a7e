#include <mocap/calibration/pinhole_camera.hpp>

#include <cmath>
#include <stdexcept>

#include <Eigen/LU>

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

Eigen::Vector2d PinholeCamera::distort(const Eigen::Vector2d& p) const {
  if (!has_distortion_) return p;
  Eigen::Vector2d distorted;
  pinhole_distort(intrinsics_.distortion.data(), p.data(), distorted.data());
  return distorted;
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
  // Newton's method on distort(p) = target, with a numeric Jacobian: converges in a few
  // steps wherever the distortion is monotonic.
  Eigen::Vector2d p = target;
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Vector2d residual = distort(p) - target;
    if (residual.squaredNorm() < 1e-24) break;
    constexpr double h = 1e-7;
    Eigen::Matrix2d jacobian;
    jacobian.col(0) = (distort(p + Eigen::Vector2d(h, 0)) - distort(p)) / h;
    jacobian.col(1) = (distort(p + Eigen::Vector2d(0, h)) - distort(p)) / h;
    p -= jacobian.lu().solve(residual);
    if (!p.allFinite()) return std::nullopt;
  }
  if ((distort(p) - target).norm() > 1e-9) return std::nullopt;
  return Eigen::Vector3d(p.x(), p.y(), 1.0);
}

std::unique_ptr<CameraModel> PinholeCamera::clone() const {
  return std::make_unique<PinholeCamera>(*this);
}

}  // namespace mocap::calibration
