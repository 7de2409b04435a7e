// The Enhanced Unified Camera Model (lens_models.hpp): one model for lenses from a plain
// pinhole to fisheyes that see beyond 90 degrees, with six parameters and a closed-form
// inverse, which is what the PixArt calibration fits (seed 002 §8).
#pragma once

#include <array>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::calibration {

class EucmCamera final : public CameraModel {
 public:
  // `parameters`: alpha, beta, fu, fv, u0, v0 (lens_models.hpp). Throws std::invalid_argument
  // for alpha outside [0, 1], beta <= 0, a non-positive focal length or image size, or a value
  // that is not finite.
  EucmCamera(int width, int height, const std::array<double, 6>& parameters);

  std::string type() const override { return "eucm"; }
  int width() const override { return width_; }
  int height() const override { return height_; }
  // eucm_project: nullopt outside the model's validity region.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point) const override;
  // The closed-form inverse. Nullopt outside the image of the valid region (alpha > 0.5 and
  // r² > 1 / (beta·(2·alpha − 1)), r² from the centred, focal-scaled pixel) and for rays at or
  // beyond 90 degrees from the optical axis, which a ray (x/z, y/z, 1) cannot express.
  std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d& pixel) const override;
  // Near the optical axis rho ≈ z and d ≈ z whatever alpha and beta, so u ≈ fu·x/z + u0: fu
  // and fv are the pixels per radian at the image centre, as a pinhole's focal lengths are.
  // Away from the centre alpha and beta bend the scale (a fisheye's shrinks).
  double focal_length_px() const override { return 0.5 * (parameters_[2] + parameters_[3]); }
  std::unique_ptr<CameraModel> clone() const override;

  const std::array<double, 6>& parameters() const { return parameters_; }
  double alpha() const { return parameters_[0]; }
  double beta() const { return parameters_[1]; }

 private:
  int width_, height_;
  std::array<double, 6> parameters_;
};

}  // namespace mocap::calibration
