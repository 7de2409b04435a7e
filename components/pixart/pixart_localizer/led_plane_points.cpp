#include "pixart/pixart_localizer/led_plane_points.hpp"

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

std::optional<std::array<Eigen::Vector2d, 4>> led_plane_footprint(const RigCamera& camera,
                                                                  double led_plane_height_m) {
  const double w = camera.model->width();
  const double h = camera.model->height();
  std::array<Eigen::Vector2d, 4> corners = {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0),
                                            Eigen::Vector2d(w, h), Eigen::Vector2d(0, h)};
  for (Eigen::Vector2d& corner : corners) {
    std::optional<Eigen::Vector2d> on_plane = pixel_to_plane(camera, corner, led_plane_height_m);
    if (!on_plane) return std::nullopt;
    corner = *on_plane;
  }
  return corners;
}

}  // namespace mocap::pixart::localization
