// The unified camera model of catadioptric and fisheye lenses, in the two forms visgeom
// calibrates: "ucm" (xi, fu, fv, u0, v0) and "mei" (xi, k1, k2, k3, k4, k5, fu, fv, u0, v0),
// the same model with its normalised plane distorted (lens_models.hpp). A lab moving from
// visgeom keeps its camera files and configurations.
#pragma once

#include <span>
#include <vector>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::calibration {

class UnifiedCamera final : public CameraModel {
 public:
  // `parameters`: 5 for a UCM, 10 for a Mei camera, in the order above. Throws
  // std::invalid_argument for another count, xi < 0, a non-positive focal length or image
  // size, or a value that is not finite.
  UnifiedCamera(int width, int height, std::span<const double> parameters);

  // "ucm" or "mei".
  std::string type() const override { return mei() ? "mei" : "ucm"; }
  int width() const override { return width_; }
  int height() const override { return height_; }
  // ucm_project or mei_project: nullopt outside the model's validity region.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point) const override;
  // Undoes the distortion (pinhole_undistort), then lifts the normalised point onto the unit
  // sphere in closed form. Nullopt where the distortion cannot be undone, outside the image of
  // the valid region (xi > 1 and r² > 1 / (xi² − 1)) and for rays at or beyond 90 degrees.
  std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d& pixel) const override;
  // Near the optical axis z + xi·rho ≈ (1 + xi)·z: fu / (1 + xi) pixels per radian.
  double focal_length_px() const override;
  std::unique_ptr<CameraModel> clone() const override;

  bool mei() const { return parameters_.size() == 10; }
  double xi() const { return parameters_[0]; }
  const std::vector<double>& parameters() const { return parameters_; }

 private:
  int width_, height_;
  std::vector<double> parameters_;
};

}  // namespace mocap::calibration
