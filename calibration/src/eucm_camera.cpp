#include <mocap/calibration/eucm_camera.hpp>

#include <cmath>
#include <stdexcept>

#include <mocap/calibration/lens_models.hpp>

namespace mocap::calibration {

static_assert(kEucmParameters == 6);

EucmCamera::EucmCamera(int width, int height, const std::array<double, 6>& parameters)
    : width_(width), height_(height), parameters_(parameters) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("eucm camera: image size must be positive");
  }
  for (double value : parameters) {
    if (!std::isfinite(value))
      throw std::invalid_argument("eucm camera: a parameter is not finite");
  }
  const auto& [alpha, beta, fu, fv, u0, v0] = parameters;
  if (alpha < 0 || alpha > 1) {
    throw std::invalid_argument("eucm camera: alpha must be in [0, 1]");
  }
  if (!(beta > 0)) throw std::invalid_argument("eucm camera: beta must be positive");
  if (!(fu > 0) || !(fv > 0)) {
    throw std::invalid_argument("eucm camera: focal lengths fu, fv must be positive");
  }
}

std::optional<Eigen::Vector2d> EucmCamera::project(const Eigen::Vector3d& point) const {
  Eigen::Vector2d pixel;
  if (!eucm_project(parameters_.data(), point.data(), pixel.data())) return std::nullopt;
  return pixel;
}

std::optional<Eigen::Vector3d> EucmCamera::unproject(const Eigen::Vector2d& pixel) const {
  const auto& [alpha, beta, fu, fv, u0, v0] = parameters_;
  double mx = (pixel.x() - u0) / fu;
  double my = (pixel.y() - v0) / fv;
  double r2 = mx * mx + my * my;
  // The point (mx, my, mz) with d = 1 lies on the ray; squaring α·rho = 1 − (1 − α)·mz gives a
  // quadratic in mz whose root on the valid side is this (written without the cancellation
  // of the textbook root, which divides by 2α − 1).
  double discriminant = 1 - (2 * alpha - 1) * beta * r2;
  if (discriminant < 0) return std::nullopt;  // alpha > 0.5 and outside the valid disc
  double mz = (1 - beta * alpha * alpha * r2) / (alpha * std::sqrt(discriminant) + (1 - alpha));
  if (!(mz > 0)) return std::nullopt;
  return Eigen::Vector3d(mx / mz, my / mz, 1.0);
}

std::unique_ptr<CameraModel> EucmCamera::clone() const {
  return std::make_unique<EucmCamera>(*this);
}

}  // namespace mocap::calibration
