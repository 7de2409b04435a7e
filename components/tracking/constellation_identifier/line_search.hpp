// Finds every group of at least four collinear image points (seed 000 §5.8), points shared
// between lines allowed. A group may hold several lines (boards in a row put their sides on
// one line) and stray points; the identifier picks four-point candidates out of it.
//
// The seed tried every pair of points as a line and tested every other point against it,
// keeping each hit: O(n³) tests, each line found once per pair of its points, and 6 Hz at 38
// points (Table A.3). Here a pair is kept only when it spans its group (no inlier lies
// beyond either end), so each group is reported once. Most pairs have no point between them:
// those between a pair lie in its bounding box, so the pair first counts its neighbours along
// the box's narrower axis (sorted once, four at a time), and only a pair with enough points
// between them gets the full test; see bench/tracking_pipeline_bench for the figures.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace mocap::constellations {

struct LineSearchOptions {
  // Largest distance of a point from the line through the group's end points, pixels (the
  // seed's "tolerance"). Looser finds lines in noisier images and more chance alignments.
  double tolerance_px = 1.5;
  // Fewest points in a group: a cross-ratio needs 4.
  int min_points = 4;
  // Shorter groups (end to end, pixels) are too small to measure a cross-ratio on.
  double min_length_px = 8.0;

  // Why these options cannot be used, naming the field ("tolerance_px: 0 is not above 0");
  // nullopt when they can. find_collinear_groups throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct CollinearGroup {
  // Indices into the input, in order along the line from points.front() to points.back().
  std::vector<int> points;
  double largest_offset_px = 0;  // of any point from the line through the ends
};

std::vector<CollinearGroup> find_collinear_groups(const std::vector<Eigen::Vector2d>& points,
                                                  const LineSearchOptions& options = {});

}  // namespace mocap::constellations
