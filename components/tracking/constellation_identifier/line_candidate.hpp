// What the identifier's searches share: four-point line candidates and how well a set of
// assigned points fits a constellation's plane.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "tracking/constellation_database/constellation_database.hpp"

namespace mocap::constellations {

// Four points of a collinear group, in order along the image line, whose cross-ratio matched
// a line type.
struct Candidate {
  std::array<int, 4> points;
  double cross_ratio;
};

// A candidate read in one direction: image point k is the model line's marker k.
struct Choice {
  const Candidate* candidate = nullptr;
  bool reversed = false;
  int image_point(int k) const { return candidate->points[reversed ? 3 - k : k]; }
};

struct PlaneFit {
  Eigen::Matrix3d homography = Eigen::Matrix3d::Identity();  // plane to image
  double rms = 0;
  double max = 0;
};

// The plane-to-image homography of the assigned points (`image_of`: per model point, an index
// into `points` or -1) and how well it explains them; nothing for fewer than four points, for
// points on one line, and for a mapping no camera could see a board through.
//
// The homography's third row gives each point of the plane its depth up to one scale, so the
// ratio of the farthest marker's depth to the nearest one's is known without a camera. A real
// board spans little depth (0.30 m seen from 0.5 m at 60° of skew: a ratio of 1.7); chance
// alignments of distractors fit with wild perspective, or with the plane crossing the camera.
// Ratios above kMaxDepthRatio are refused.
constexpr double kMaxDepthRatio = 3.0;
std::optional<PlaneFit> plane_fit(const ConstellationModel& model, const std::vector<int>& image_of,
                                  const std::vector<Eigen::Vector2d>& points);

}  // namespace mocap::constellations
