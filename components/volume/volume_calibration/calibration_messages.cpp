#include "volume/volume_calibration/board_sighting_message.hpp"

#include <algorithm>
#include <cmath>

namespace mocap::volume {

std::optional<BoardSighting> board_sighting(const mocap_msgs::msg::ConstellationArray& array,
                                            size_t camera,
                                            const constellations::ConstellationModel& board) {
  for (const auto& constellation : array.constellations()) {
    if (constellation.name() != board.name) continue;
    BoardSighting sighting;
    sighting.camera = camera;
    sighting.pixels.resize(board.points.size());
    for (const auto& line : constellation.sub_constellations()) {
      const auto model_line = std::find_if(board.lines.begin(), board.lines.end(),
                                           [&](const auto& l) { return l.name == line.name(); });
      if (model_line == board.lines.end()) continue;
      const auto& fiducials = line.fiducial_array().fiducials();
      const auto& stamp = line.fiducial_array().header().stamp();
      sighting.stamp_ns = int64_t{stamp.sec()} * 1'000'000'000 + stamp.nanosec();
      for (size_t i = 0; i < fiducials.size() && i < model_line->points.size(); ++i) {
        if (!std::isfinite(fiducials[i].x()) || !std::isfinite(fiducials[i].y())) continue;
        sighting.pixels[static_cast<size_t>(model_line->points[i])] =
            Eigen::Vector2d(fiducials[i].x(), fiducials[i].y());
      }
    }
    return sighting;
  }
  return std::nullopt;
}

}  // namespace mocap::volume
