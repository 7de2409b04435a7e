// What a transform read from a file must be once a parser accepted it: a rotation and a
// translation, all finite. The calibration configuration, rig and turret fuzzers check it.
#pragma once

#include <Eigen/Geometry>

namespace fuzz {

inline bool is_rigid(const Eigen::Isometry3d& transform) {
  const Eigen::Matrix3d r = transform.linear();
  return transform.matrix().allFinite() &&
         (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-9 && r.determinant() > 0;
}

}  // namespace fuzz
