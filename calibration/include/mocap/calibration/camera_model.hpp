// How a camera maps points in its frame to pixels and back. Everything that reasons about
// pixels (the pose estimator, the synthetic camera, the PixArt localizer) goes through this
// interface, so a new lens model is one new class.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace mocap::calibration {

// Camera frame: x right, y down, z forward (optical axis); pixels: u right, v down, origin at
// the centre of the top-left pixel.
class CameraModel {
 public:
  virtual ~CameraModel() = default;

  // "pinhole", "eucm", ...
  virtual std::string type() const = 0;
  virtual int width() const = 0;
  virtual int height() const = 0;

  // The pixel that sees `point`, or nullopt when the model cannot image it (behind the
  // camera, outside the lens model's valid region). The pixel may lie outside the image.
  virtual std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point) const = 0;

  // The normalised ray (x/z, y/z, 1) seen by `pixel`, or nullopt outside the valid region.
  virtual std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d& pixel) const = 0;

  // Pixels per radian near the image centre: converts angular tolerances to pixels.
  virtual double focal_length_px() const = 0;

  virtual std::unique_ptr<CameraModel> clone() const = 0;

  bool in_image(const Eigen::Vector2d& pixel) const {
    return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < width() - 0.5 &&
           pixel.y() < height() - 0.5;
  }
};

}  // namespace mocap::calibration
