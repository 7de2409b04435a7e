#include "led_plane_points.hpp"

namespace mocap::pixart::localization {

LedPlanePoints project_to_led_plane(const RigCamera& camera,
                                    const std::vector<Eigen::Vector2d>& pixels,
                                    double led_plane_height_m) {
  LedPlanePoints result;
  result.points.reserve(pixels.size());
  for (const Eigen::Vector2d& pixel : pixels) {
    if (!pixel.allFinite()) {
      ++result.non_finite_pixels;
      continue;
    }
    if (auto point = pixel_to_plane(camera, pixel, led_plane_height_m)) {
      result.points.push_back(*point);
    } else {
      ++result.unprojectable_pixels;
    }
  }
  return result;
}

}  // namespace mocap::pixart::localization
