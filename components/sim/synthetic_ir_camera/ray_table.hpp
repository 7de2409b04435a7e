// The viewing ray of every pixel corner of a camera. Unprojecting through a lens model inverts
// the distortion iteratively; doing that for each of the thousands of sub-pixel rays a frame
// casts would cost more than the rest of the frame, while the rays vary so smoothly across one
// pixel that interpolating between its corners is exact to well below 1e-3 pixel.
//
// Corners are unprojected on first use, a tile at a time: a renderer made for one frame pays
// only for the parts of the image its markers cover (unprojecting all 1281 x 721 corners of
// the shipped camera takes about 0.2 s). Not thread-safe, even through const methods.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::synthetic {

class RayTable {
 public:
  explicit RayTable(std::shared_ptr<const calibration::CameraModel> camera);

  int width() const { return width_; }  // of the image, pixels
  int height() const { return height_; }

  // The normalised ray (x/z, y/z) through the top-left corner of pixel (u, v), i.e. through
  // the image point (u - 0.5, v - 0.5); u in [0, width], v in [0, height]. NaN where the camera
  // model has no ray.
  Eigen::Vector2d corner(int u, int v) const {
    size_t tile = static_cast<size_t>(v / kTileSize) * tiles_across_ + u / kTileSize;
    if (!tile_ready_[tile]) fill_tile(tile);
    const Ray& ray = corners_[static_cast<size_t>(v) * (width_ + 1) + u];
    return {ray.x, ray.y};
  }

 private:
  static constexpr int kTileSize = 16;  // corners a side
  struct Ray {
    float x, y;  // floats: 1e-7 relative is 1e-4 pixel, and the table stays 7 MB for 1280x720
  };
  void fill_tile(size_t tile) const;

  std::shared_ptr<const calibration::CameraModel> camera_;
  int width_, height_;
  size_t tiles_across_;
  mutable std::vector<Ray> corners_;  // (width + 1) x (height + 1), row-major
  mutable std::vector<uint8_t> tile_ready_;
};

}  // namespace mocap::synthetic
