// From an identified constellation's lines to the point pairs a pose needs.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tracking/constellation_database/constellation_database.hpp"

namespace mocap::pose {

// One identified line: its name in the model and its four pixels in the model's order A..D;
// a non-finite pixel is a marker not seen.
struct ObservedLine {
  std::string name;
  std::array<Eigen::Vector2d, 4> pixels;
};

struct Correspondences {
  std::vector<Eigen::Vector3d> object_points;  // model frame, metres
  std::vector<Eigen::Vector2d> pixels;
  std::vector<std::string> unknown_lines;  // names the model does not have
};

// Each model point once: a corner seen by two lines is one pair (its pixels averaged, which
// are the same fiducial when the identifier produced them).
Correspondences match_to_model(const constellations::ConstellationModel& model,
                               const std::vector<ObservedLine>& lines);

}  // namespace mocap::pose
