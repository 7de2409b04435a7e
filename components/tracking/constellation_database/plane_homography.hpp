// The homography between a constellation's plane and the image: how the identifier checks
// that lines found separately belong to one flat board, and where a planar pose starts.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace mocap::constellations {

// Least-squares H with to ~ H * from (normalised DLT), from four or more pairs; nullopt when
// the points are degenerate (fewer than four, or all on one line).
std::optional<Eigen::Matrix3d> fit_homography(std::span<const Eigen::Vector2d> from,
                                              std::span<const Eigen::Vector2d> to);

inline Eigen::Vector2d apply_homography(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  Eigen::Vector3d q = h * Eigen::Vector3d(p.x(), p.y(), 1.0);
  return q.head<2>() / q.z();
}

}  // namespace mocap::constellations
