// A tracked body's pose, velocity and their covariances, seen from another frame, in the
// conventions of ROS's REP 103 and nav_msgs/Odometry.
//
// A camera's optical frame (REP 103's "_optical" suffix) has z forward, x right, y down: the
// frame our poses are in. Its body frame ("camera_ir", say) has x forward, y left, z up, as
// every other body in ROS. The optical frame in the body frame is a fixed rotation,
// kOpticalInBody. Odometry carries the pose in the parent frame (header.frame_id) and the twist
// in the body's own frame (child_frame_id).
#pragma once

#include <string_view>
#include <vector>

#include <Eigen/Geometry>

namespace mocap::outputs {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The camera's optical frame in its REP 103 body frame: optical z is body x, optical x is body
// -y, optical y is body -z. As a quaternion (x, y, z, w): (-0.5, 0.5, -0.5, 0.5), what
// `static_transform_publisher 0 0 0 -1.5708 0 -1.5708 camera camera_optical` publishes.
const Eigen::Quaterniond& optical_in_body();

// One body at one instant, in a parent frame. The pose covariance is over (x, y, z, rx, ry, rz),
// the rotations a small rotation vector about the parent's axes (R = exp(δθ) R̂); the velocity
// covariance over (vx, vy, vz, wx, wy, wz). Velocities are the body origin's linear velocity
// and the body's angular velocity, both expressed in the parent frame.
struct BodyState {
  Eigen::Isometry3d parent_from_body = Eigen::Isometry3d::Identity();
  Matrix6d pose_covariance = Matrix6d::Zero();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Matrix6d velocity_covariance = Matrix6d::Zero();
};

// A pose whose orientation variances (rad², each axis) are all this large or more has no
// orientation: a robot of one marker, whose pose carries 1e9 there as ROS's Odometry readers
// expect.
inline constexpr double kUnknownOrientationVariance = 1e6;
inline bool orientation_unknown(const Matrix6d& pose_covariance) {
  return (pose_covariance.diagonal().tail<3>().array() >= kUnknownOrientationVariance).all();
}

// `body` seen from another frame, fixed to its parent: `new_from_parent` the parent in the new
// frame. Pose composed; velocities and both covariances rotated.
BodyState seen_from(const Eigen::Isometry3d& new_from_parent, const BodyState& body);

// The body's velocity expressed in its own frame, with its covariance: what
// nav_msgs/Odometry's twist holds.
struct BodyTwist {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
  Matrix6d covariance = Matrix6d::Zero();
};
BodyTwist twist_in_body(const BodyState& body);

// A body rigidly attached to `body` (a drone carrying the board), `body_from_attached` its
// place on it: pose composed; its origin's velocity gains the lever arm's ω × r; both
// covariances carried through the lever arm (to first order).
BodyState attached(const BodyState& body, const Eigen::Isometry3d& body_from_attached);

// The rigid transform of x, y, z (m) and roll, pitch, yaw (rad, about fixed x, then y, then
// z: ROS's convention, R = Rz(yaw) Ry(pitch) Rx(roll)).
Eigen::Isometry3d from_xyz_rpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy);
// The same from a parameter's six numbers. Throws std::invalid_argument naming `parameter`
// unless there are six: "camera_in_world: expected 6 numbers (x, y, z, roll, pitch, yaw), got 3".
Eigen::Isometry3d from_xyz_rpy(const std::vector<double>& xyz_rpy, std::string_view parameter);

// The camera's optical frame in the world, from its REP 103 body frame in the world.
Eigen::Isometry3d world_from_optical(const Eigen::Isometry3d& world_from_camera);

}  // namespace mocap::outputs
