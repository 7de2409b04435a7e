// The pinhole model with OpenCV's radial-tangential ("plumb_bob") distortion.
#pragma once

#include <array>

#include <mocap/calibration/camera_model.hpp>
#include <mocap/calibration/lens_models.hpp>

namespace mocap::calibration {

struct PinholeIntrinsics {
  double fx = 0, fy = 0;  // focal lengths, pixels
  double cx = 0, cy = 0;  // principal point, pixels
  // k1, k2, p1, p2, k3 as in OpenCV; all zero for an ideal lens.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};
};

class PinholeCamera final : public CameraModel {
 public:
  // Throws std::invalid_argument for a non-positive size or focal length.
  PinholeCamera(int width, int height, const PinholeIntrinsics& intrinsics);

  std::string type() const override { return "pinhole"; }
  int width() const override { return width_; }
  int height() const override { return height_; }
  // pinhole_project: nullopt for z <= 0.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point) const override;
  // Inverts the distortion (pinhole_undistort); nullopt where that does not converge.
  std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d& pixel) const override;
  double focal_length_px() const override { return 0.5 * (intrinsics_.fx + intrinsics_.fy); }
  std::unique_ptr<CameraModel> clone() const override;

  const PinholeIntrinsics& intrinsics() const { return intrinsics_; }
  // fx, fy, cx, cy, k1, k2, p1, p2, k3, the order of pinhole_project.
  const std::array<double, kPinholeParameters>& parameters() const { return parameters_; }

 private:
  int width_, height_;
  PinholeIntrinsics intrinsics_;
  std::array<double, kPinholeParameters> parameters_;
  bool has_distortion_;
};

}  // namespace mocap::calibration
