// The cross-ratio of four collinear points (seed 000 §5.9.3, eq. 7): invariant under every
// projection of the line, so a line of markers keeps it in any image of it.
#pragma once

#include <Eigen/Core>

namespace mocap::constellations {

// R(A,C;B,D) = (AC/BC) / (AD/BD) for points in order A, B, C, D along the line. Reversing
// the order (D, C, B, A) gives the same value, so it names a line but not its direction.
// For distinct points in order the value is > 1.
inline double cross_ratio(double a, double b, double c, double d) {
  return ((c - a) * (d - b)) / ((c - b) * (d - a));
}

inline double cross_ratio(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                          const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  return ((c - a).norm() * (d - b).norm()) / ((c - b).norm() * (d - a).norm());
}

// |measured - truth| / truth (seed eq. 8).
inline double relative_difference(double measured, double truth) {
  return std::abs((measured - truth) / truth);
}

}  // namespace mocap::constellations
