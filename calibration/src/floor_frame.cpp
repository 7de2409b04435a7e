#include <mocap/calibration/floor_frame.hpp>

namespace mocap::calibration {

std::vector<Eigen::Isometry3d> cameras_in_floor_frame(
    const std::vector<Eigen::Isometry3d>& camera_from_reference,
    const Eigen::Isometry3d& reference_from_board) {
  Eigen::Isometry3d reference_from_world = reference_from_board;
  // The reference camera looks at the floor from above: it is on the world's positive side.
  const Eigen::Vector3d camera_in_board = reference_from_board.inverse().translation();
  if (camera_in_board.z() < 0) {
    reference_from_world = reference_from_board * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  }
  std::vector<Eigen::Isometry3d> out;
  for (const Eigen::Isometry3d& camera : camera_from_reference) {
    out.push_back(camera * reference_from_world);
  }
  return out;
}

}  // namespace mocap::calibration
