#include "sim/fiducial_pattern_source/fiducial_pattern_source.hpp"

#include <cmath>
#include <numbers>

namespace mocap::demo {

std::vector<PatternPoint> fiducial_pattern(const PatternOptions& options, double t_seconds) {
  std::vector<PatternPoint> points;
  points.reserve(static_cast<size_t>(std::max(options.count, 0)));
  double start = 2 * std::numbers::pi * options.turns_per_second * t_seconds;
  for (int i = 0; i < options.count; ++i) {
    double angle = start + 2 * std::numbers::pi * i / options.count;
    points.push_back({options.image_width / 2 + options.radius_px * std::cos(angle),
                      options.image_height / 2 + options.radius_px * std::sin(angle)});
  }
  return points;
}

}  // namespace mocap::demo
