// Step 1 of the localizer: a camera's pixels to points on the robots' LED plane, world frame.
//
// Every LED of every robot is at the same height (the rig's led_plane_height_m), so one
// camera alone places a point: the ray through the pixel meets that plane once.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "pixart/pixart_rig/pixart_rig.hpp"

namespace mocap::pixart::localization {

struct LedPlanePoints {
  std::vector<Eigen::Vector2d> points;  // world x, y on the LED plane, in the pixels' order
  uint64_t non_finite_pixels = 0;       // NaN or infinite coordinates: skipped
  uint64_t unprojectable_pixels = 0;    // outside the lens model, or a ray missing the plane
};

// The pixels of one camera sample on the LED plane, through `camera`'s model and pose
// (pixel_to_plane). Bad pixels are skipped and counted, never thrown.
LedPlanePoints project_to_led_plane(const RigCamera& camera,
                                    const std::vector<Eigen::Vector2d>& pixels,
                                    double led_plane_height_m);

// What `camera` sees of the LED plane: its image's corners there, world x, y, in the order
// (0, 0), (width, 0), (width, height), (0, height); nullopt when a corner's ray misses it.
std::optional<std::array<Eigen::Vector2d, 4>> led_plane_footprint(const RigCamera& camera,
                                                                  double led_plane_height_m);

}  // namespace mocap::pixart::localization
