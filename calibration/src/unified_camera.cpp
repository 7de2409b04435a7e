#include <mocap/calibration/unified_camera.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

#include <mocap/calibration/lens_models.hpp>

namespace mocap::calibration {

UnifiedCamera::UnifiedCamera(int width, int height, std::span<const double> parameters)
    : width_(width), height_(height), parameters_(parameters.begin(), parameters.end()) {
  if (parameters.size() != kUcmParameters && parameters.size() != kMeiParameters) {
    throw std::invalid_argument("unified camera: 5 parameters (ucm) or 10 (mei), not " +
                                std::to_string(parameters.size()));
  }
  const std::string name = type() + " camera: ";
  if (width <= 0 || height <= 0) throw std::invalid_argument(name + "image size must be positive");
  for (double value : parameters) {
    if (!std::isfinite(value)) throw std::invalid_argument(name + "a parameter is not finite");
  }
  if (!(xi() >= 0)) throw std::invalid_argument(name + "xi must not be negative");
  const size_t fu = parameters_.size() - 4;
  if (!(parameters_[fu] > 0) || !(parameters_[fu + 1] > 0)) {
    throw std::invalid_argument(name + "focal lengths fu, fv must be positive");
  }
}

std::optional<Eigen::Vector2d> UnifiedCamera::project(const Eigen::Vector3d& point) const {
  Eigen::Vector2d pixel;
  const bool valid = mei() ? mei_project(parameters_.data(), point.data(), pixel.data())
                           : ucm_project(parameters_.data(), point.data(), pixel.data());
  if (!valid) return std::nullopt;
  return pixel;
}

std::optional<Eigen::Vector3d> UnifiedCamera::unproject(const Eigen::Vector2d& pixel) const {
  const double* focal = parameters_.data() + parameters_.size() - 4;  // fu, fv, u0, v0
  Eigen::Vector2d m((pixel.x() - focal[2]) / focal[0], (pixel.y() - focal[3]) / focal[1]);
  if (mei()) {
    const double* k = parameters_.data() + 1;
    const double distortion[5] = {k[0], k[1], k[3], k[4], k[2]};
    Eigen::Vector2d undistorted;
    if (!pinhole_undistort(distortion, m.data(), undistorted.data())) return std::nullopt;
    m = undistorted;
  }
  // The sphere point s·(mx, my, 1) − (0, 0, xi) with |·| = 1; of the two roots, the one on the
  // valid side (the other lies behind the sphere's horizon seen from (0, 0, −xi)).
  const double r2 = m.squaredNorm();
  const double discriminant = 1 + (1 - xi() * xi()) * r2;
  if (discriminant < 0) return std::nullopt;
  const double s = (xi() + std::sqrt(discriminant)) / (1 + r2);
  const double z = s - xi();
  if (!(z > 0)) return std::nullopt;
  return Eigen::Vector3d(s * m.x() / z, s * m.y() / z, 1.0);
}

double UnifiedCamera::focal_length_px() const {
  const double* focal = parameters_.data() + parameters_.size() - 4;
  return 0.5 * (focal[0] + focal[1]) / (1 + xi());
}

std::unique_ptr<CameraModel> UnifiedCamera::clone() const {
  return std::make_unique<UnifiedCamera>(*this);
}

}  // namespace mocap::calibration
