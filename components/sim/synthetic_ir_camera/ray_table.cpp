#include "sim/synthetic_ir_camera/ray_table.hpp"

#include <algorithm>
#include <limits>

namespace mocap::synthetic {

RayTable::RayTable(std::shared_ptr<const calibration::CameraModel> camera)
    : camera_(std::move(camera)),
      width_(camera_->width()),
      height_(camera_->height()),
      tiles_across_(static_cast<size_t>(width_ / kTileSize + 1)) {
  corners_.resize(static_cast<size_t>(width_ + 1) * (height_ + 1));
  tile_ready_.assign(tiles_across_ * static_cast<size_t>(height_ / kTileSize + 1), 0);
}

void RayTable::fill_tile(size_t tile) const {
  constexpr float kNoRay = std::numeric_limits<float>::quiet_NaN();
  int u0 = static_cast<int>(tile % tiles_across_) * kTileSize;
  int v0 = static_cast<int>(tile / tiles_across_) * kTileSize;
  for (int v = v0; v < std::min(v0 + kTileSize, height_ + 1); ++v) {
    for (int u = u0; u < std::min(u0 + kTileSize, width_ + 1); ++u) {
      std::optional<Eigen::Vector3d> ray = camera_->unproject(Eigen::Vector2d(u - 0.5, v - 0.5));
      corners_[static_cast<size_t>(v) * (width_ + 1) + u] =
          ray ? Ray{static_cast<float>(ray->x() / ray->z()),
                    static_cast<float>(ray->y() / ray->z())}
              : Ray{kNoRay, kNoRay};
    }
  }
  tile_ready_[tile] = 1;
}

}  // namespace mocap::synthetic
