// A synthetic fiducial pattern: a stand-in for a tracked target, for demos and tests.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mocap::demo {

struct PatternPoint {
  double x;  // pixels, right
  double y;  // pixels, down
};

struct PatternOptions {
  int count = 12;
  double image_width = 1280;
  double image_height = 720;
  double radius_px = 200;
  double turns_per_second = 0.1;

  // Why these options cannot be used, naming the field ("count: 0 is below 1"); nullopt when
  // they can. fiducial_pattern throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// `options.count` points evenly spaced on a circle centred in the image, turning at
// `options.turns_per_second`; `t_seconds` is the time since the pattern started.
std::vector<PatternPoint> fiducial_pattern(const PatternOptions& options, double t_seconds);

}  // namespace mocap::demo
