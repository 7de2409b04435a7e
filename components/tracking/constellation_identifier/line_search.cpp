#include "line_search.hpp"

#include <algorithm>
#include <cmath>

namespace mocap::constellations {

std::vector<CollinearGroup> find_collinear_groups(const std::vector<Eigen::Vector2d>& points,
                                                  const LineSearchOptions& options) {
  std::vector<CollinearGroup> groups;
  const int n = static_cast<int>(points.size());
  std::vector<std::pair<double, int>> inliers;
  inliers.reserve(n);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      Eigen::Vector2d d = points[j] - points[i];
      double length = d.norm();
      if (!(length >= options.min_length_px)) continue;
      // With u along the line (0 at i, 1 at j) and the signed distance scaled by the length,
      // each point costs two dot products and no square root.
      double tolerance = options.tolerance_px * length;
      double length2 = length * length;
      inliers.clear();
      inliers.emplace_back(0.0, i);
      inliers.emplace_back(1.0, j);
      double largest_offset = 0;
      bool spans = true;
      for (int k = 0; k < n && spans; ++k) {
        if (k == i || k == j) continue;
        Eigen::Vector2d r = points[k] - points[i];
        double cross = d.x() * r.y() - d.y() * r.x();
        if (std::abs(cross) > tolerance) continue;
        double u = d.dot(r) / length2;
        if (u <= 0.0 || u >= 1.0) {
          spans = false;  // a longer group contains this one; its own end pair reports it
        } else {
          inliers.emplace_back(u, k);
          largest_offset = std::max(largest_offset, std::abs(cross) / length);
        }
      }
      if (!spans || static_cast<int>(inliers.size()) < options.min_points) continue;
      std::sort(inliers.begin(), inliers.end());
      CollinearGroup group;
      group.largest_offset_px = largest_offset;
      for (const auto& [u, index] : inliers) group.points.push_back(index);
      groups.push_back(std::move(group));
    }
  }
  return groups;
}

}  // namespace mocap::constellations
