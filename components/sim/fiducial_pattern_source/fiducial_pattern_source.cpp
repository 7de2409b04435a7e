#include "sim/fiducial_pattern_source/fiducial_pattern_source.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::demo {

std::optional<std::string> PatternOptions::problem() const {
  if (count < 1) return fmt::format("count: {} is below 1", count);
  if (!(image_width > 0)) return fmt::format("image_width: {} is not above 0", image_width);
  if (!(image_height > 0)) return fmt::format("image_height: {} is not above 0", image_height);
  if (!(radius_px >= 0)) return fmt::format("radius_px: {} is below 0", radius_px);
  if (!std::isfinite(turns_per_second)) {
    return fmt::format("turns_per_second: {} is not finite", turns_per_second);
  }
  return std::nullopt;
}

std::vector<PatternPoint> fiducial_pattern(const PatternOptions& options, double t_seconds) {
  if (auto problem = options.problem()) throw std::invalid_argument("PatternOptions::" + *problem);
  std::vector<PatternPoint> points;
  points.reserve(static_cast<size_t>(options.count));
  double start = 2 * std::numbers::pi * options.turns_per_second * t_seconds;
  for (int i = 0; i < options.count; ++i) {
    double angle = start + 2 * std::numbers::pi * i / options.count;
    points.push_back({options.image_width / 2 + options.radius_px * std::cos(angle),
                      options.image_height / 2 + options.radius_px * std::sin(angle)});
  }
  return points;
}

}  // namespace mocap::demo
