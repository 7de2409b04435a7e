#include "outputs/px4_odometry/px4_odometry.hpp"

#include <limits>

namespace mocap::outputs {
namespace {

// Ours to PX4's: FRD from FLU (and body FRD from body FLU) turns half a turn about x; NED from
// ENU swaps x and y and turns z over.
Eigen::Matrix3d world_to_px4(Px4Frame frame) {
  Eigen::Matrix3d rotation;
  if (frame == Px4Frame::Ned) {
    rotation << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  } else {
    rotation = Eigen::Vector3d(1, -1, -1).asDiagonal();
  }
  return rotation;
}

const Eigen::Matrix3d& flu_to_frd() {
  static const Eigen::Matrix3d rotation = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return rotation;
}

Eigen::Vector3d diagonal(const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& covariance) {
  return (rotation * covariance * rotation.transpose()).diagonal();
}

}  // namespace

Px4Odometry to_px4(const BodyState& vehicle, Px4Frame frame) {
  const Eigen::Matrix3d world = world_to_px4(frame);
  const Eigen::Matrix3d& body = flu_to_frd();
  const Eigen::Matrix3d attitude = vehicle.parent_from_body.linear();  // world FLU <- body FLU
  // PX4's world <- PX4's body: into our world from the FRD body, then into PX4's world.
  Eigen::Quaterniond q(world * attitude * body.transpose());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  // Body FRD <- our world: angular velocity and attitude covariance about the body's axes.
  const Eigen::Matrix3d body_from_world = body * attitude.transpose();

  Px4Odometry odometry;
  odometry.frame = frame;
  odometry.position = world * vehicle.parent_from_body.translation();
  odometry.q = {q.w(), q.x(), q.y(), q.z()};
  odometry.velocity = world * vehicle.linear_velocity;
  odometry.angular_velocity = body_from_world * vehicle.angular_velocity;
  odometry.position_variance = diagonal(world, vehicle.pose_covariance.topLeftCorner<3, 3>());
  odometry.orientation_variance =
      diagonal(body_from_world, vehicle.pose_covariance.bottomRightCorner<3, 3>());
  odometry.velocity_variance = diagonal(world, vehicle.velocity_covariance.topLeftCorner<3, 3>());
  if (orientation_unknown(vehicle.pose_covariance)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    odometry.q = {nan, nan, nan, nan};
    odometry.angular_velocity.setConstant(nan);
    odometry.orientation_variance.setConstant(nan);
  }
  return odometry;
}

}  // namespace mocap::outputs
