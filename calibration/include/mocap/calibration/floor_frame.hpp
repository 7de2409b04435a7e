// A volume's world frame from a board laid on the floor, after the cameras have been calibrated
// relative to one of them (CalibrationProblem::camera_poses): the world's z axis points up out of
// the floor towards the cameras, and trackers and outputs then speak of the room, not of a camera.
//
// Laid once, the board is the world: its centre (its origin, which is the shipped boards'
// centre) the world's origin, its x axis the room's. Its tilt and heading are then known only
// as well as its markers 0.3 m apart fix them, and every position in the volume turns with that
// error, metres from the board. Laid at three or more marks on the floor whose positions are
// known (taped, measured), the board's centres fix the floor over the marks' spread instead: an
// error e in a centre turns the frame by about e / spread.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Geometry>

namespace mocap::calibration {

// The world frame in the reference camera's frame, from the board's pose there, its centre
// lying at `mark` (world x, y) with its axes along the room's. A board whose z axis points into
// the floor (its face down) is turned over about its x axis: the reference camera looks at the
// floor from above, so it is on the world's positive side.
Eigen::Isometry3d reference_from_world_of_board(const Eigen::Isometry3d& reference_from_board,
                                                const Eigen::Vector2d& mark = {0, 0});

// The world frame in the reference camera's frame, from the board's centre measured at marks
// on the floor (`centres` in the reference frame, `marks` the same marks' world x, y): the
// rigid motion that carries the centres onto the marks in the least-squares sense. Nothing
// when there are fewer than three marks or they lie in a line (no plane), or when the cameras
// would come out under the floor (the marks' x and y swapped, or a mirror image).
std::optional<Eigen::Isometry3d> reference_from_world_of_marks(
    const std::vector<Eigen::Vector3d>& centres, const std::vector<Eigen::Vector2d>& marks);

// Each camera's camera_from_world, from its camera_from_reference.
std::vector<Eigen::Isometry3d> cameras_in_world(
    const std::vector<Eigen::Isometry3d>& camera_from_reference,
    const Eigen::Isometry3d& reference_from_world);

}  // namespace mocap::calibration
