// A volume's world frame from a board laid on the floor, after the cameras have been calibrated
// relative to one of them (CalibrationProblem::camera_poses): the world's origin is the board's,
// its z axis points up out of the floor towards the cameras, its x axis runs along the board's.
// Trackers and outputs then speak of the room, not of a camera.
#pragma once

#include <vector>

#include <Eigen/Geometry>

namespace mocap::calibration {

// Each camera's camera_from_world, from its camera_from_reference and the floor board's pose
// seen in the reference camera's frame (a camera that saw the board: its pose moved into the
// reference frame). A board whose z axis points into the floor is turned over about its x axis.
std::vector<Eigen::Isometry3d> cameras_in_floor_frame(
    const std::vector<Eigen::Isometry3d>& camera_from_reference,
    const Eigen::Isometry3d& reference_from_board);

}  // namespace mocap::calibration
