#include "tracking/pose_estimator/constellation_pose.hpp"

namespace mocap::pose {

Correspondences match_to_model(const constellations::ConstellationModel& model,
                               const std::vector<ObservedLine>& lines) {
  std::vector<Eigen::Vector2d> sum(model.points.size(), Eigen::Vector2d::Zero());
  std::vector<int> seen(model.points.size(), 0);
  Correspondences result;
  for (const ObservedLine& line : lines) {
    const constellations::ConstellationLine* model_line = nullptr;
    for (const auto& candidate : model.lines) {
      if (candidate.name == line.name) model_line = &candidate;
    }
    if (model_line == nullptr) {
      result.unknown_lines.push_back(line.name);
      continue;
    }
    for (int k = 0; k < 4; ++k) {
      if (!line.pixels[k].allFinite()) continue;  // a marker not seen
      sum[model_line->points[k]] += line.pixels[k];
      ++seen[model_line->points[k]];
    }
  }
  for (size_t i = 0; i < model.points.size(); ++i) {
    if (seen[i] == 0) continue;
    result.object_points.push_back(model.points[i]);
    result.pixels.push_back(sum[i] / seen[i]);
  }
  return result;
}

}  // namespace mocap::pose
