// The 6-DoF pose of a planar constellation from its identified image points (seed 000 §5.10),
// with the seed's proposed false-positive check (§7.3.2): reproject and reject.
//
// IPPE (ippe.hpp) on the undistorted rays gives the two poses a plane can have; each is
// refined by Gauss–Newton on the pixel reprojection error through the camera model, and the
// better one is kept. Any CameraModel works, so calibrated EUCM cameras plug in.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::pose {

struct PlanarPoseOptions {
  // A pose whose RMS reprojection error exceeds this is a false identification (a chance
  // alignment of distractors) and is rejected.
  double max_reprojection_rms_px = 1.5;
  // Fewest points for a pose, at least four (fewer throw std::invalid_argument): four fix a
  // plane's pose, more average the noise.
  int min_points = 4;
  int max_iterations = 15;

  // Why these options cannot be used, naming the field ("min_points: 3; four points at least
  // fix a plane's pose"); nullopt when they can. estimate_planar_pose and refine_planar_pose
  // throw std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct PlanarPose {
  bool valid = false;
  std::string rejection;  // why not valid
  // The object's frame in the camera frame (x right, y down, z forward).
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  double reprojection_rms_px = 0;
  int points_used = 0;
  // Row-major 6x6 over (x, y, z, rx, ry, rz) of the object origin in the camera frame (m,
  // rad; rotation as a small angle vector in the camera frame), from the residual scatter.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

// `object_points` (metres, coplanar, object frame) and `pixels` correspond index by index.
PlanarPose estimate_planar_pose(const calibration::CameraModel& camera,
                                const std::vector<Eigen::Vector3d>& object_points,
                                const std::vector<Eigen::Vector2d>& pixels,
                                const PlanarPoseOptions& options = {});

// The pose refined from `start` (a prediction from the previous frames) through the camera
// model, without IPPE: for tracking, where the start is near the answer and points may be as
// few as four in any arrangement. Same checks and covariance as estimate_planar_pose.
PlanarPose refine_planar_pose(const calibration::CameraModel& camera,
                              const Eigen::Isometry3d& start,
                              const std::vector<Eigen::Vector3d>& object_points,
                              const std::vector<Eigen::Vector2d>& pixels,
                              const PlanarPoseOptions& options = {});

// The angle between two rotations (seed eq. 10), radians.
double rotation_angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace mocap::pose
