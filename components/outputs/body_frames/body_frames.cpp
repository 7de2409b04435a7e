#include "outputs/body_frames/body_frames.hpp"

#include <stdexcept>
#include <string>

namespace mocap::outputs {
namespace {

// The 6x6 block-diagonal rotation of a (translation, rotation) or (linear, angular) vector.
Matrix6d twice(const Eigen::Matrix3d& rotation) {
  Matrix6d both = Matrix6d::Zero();
  both.topLeftCorner<3, 3>() = rotation;
  both.bottomRightCorner<3, 3>() = rotation;
  return both;
}

}  // namespace

const Eigen::Quaterniond& optical_in_body() {
  static const Eigen::Quaterniond rotation(0.5, -0.5, 0.5, -0.5);  // w, x, y, z
  return rotation;
}

BodyState seen_from(const Eigen::Isometry3d& new_from_parent, const BodyState& body) {
  const Eigen::Matrix3d rotation = new_from_parent.linear();
  const Matrix6d both = twice(rotation);
  BodyState seen;
  seen.parent_from_body = new_from_parent * body.parent_from_body;
  seen.pose_covariance = both * body.pose_covariance * both.transpose();
  seen.linear_velocity = rotation * body.linear_velocity;
  seen.angular_velocity = rotation * body.angular_velocity;
  seen.velocity_covariance = both * body.velocity_covariance * both.transpose();
  return seen;
}

BodyTwist twist_in_body(const BodyState& body) {
  const Eigen::Matrix3d body_from_parent = body.parent_from_body.linear().transpose();
  const Matrix6d both = twice(body_from_parent);
  return {body_from_parent * body.linear_velocity, body_from_parent * body.angular_velocity,
          both * body.velocity_covariance * both.transpose()};
}

BodyState attached(const BodyState& body, const Eigen::Isometry3d& body_from_attached) {
  // The lever arm from the body's origin to the attached one, in the parent frame. With the
  // rotation perturbed on the left, R = exp(δθ) R̂: r = exp(δθ) r̂, so ∂r/∂δθ = -[r]x; with
  // the angular velocity, ∂(ω x r)/∂ω = -[r]x.
  const Eigen::Vector3d arm = body.parent_from_body.linear() * body_from_attached.translation();
  Eigen::Matrix3d arm_cross;
  arm_cross << 0, -arm.z(), arm.y(), arm.z(), 0, -arm.x(), -arm.y(), arm.x(), 0;
  Matrix6d lever = Matrix6d::Identity();
  lever.topRightCorner<3, 3>() = -arm_cross;
  BodyState result;
  result.parent_from_body = body.parent_from_body * body_from_attached;
  result.pose_covariance = lever * body.pose_covariance * lever.transpose();
  result.linear_velocity = body.linear_velocity + body.angular_velocity.cross(arm);
  result.angular_velocity = body.angular_velocity;
  result.velocity_covariance = lever * body.velocity_covariance * lever.transpose();
  return result;
}

Eigen::Isometry3d from_xyz_rpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.translate(xyz);
  transform.rotate(Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()));
  return transform;
}

Eigen::Isometry3d from_xyz_rpy(const std::vector<double>& xyz_rpy, std::string_view parameter) {
  if (xyz_rpy.size() != 6) {
    throw std::invalid_argument(std::string(parameter) +
                                ": expected 6 numbers (x, y, z, roll, pitch, yaw), got " +
                                std::to_string(xyz_rpy.size()));
  }
  return from_xyz_rpy({xyz_rpy[0], xyz_rpy[1], xyz_rpy[2]}, {xyz_rpy[3], xyz_rpy[4], xyz_rpy[5]});
}

Eigen::Isometry3d world_from_optical(const Eigen::Isometry3d& world_from_camera) {
  Eigen::Isometry3d camera_from_optical = Eigen::Isometry3d::Identity();
  camera_from_optical.linear() = optical_in_body().toRotationMatrix();
  return world_from_camera * camera_from_optical;
}

}  // namespace mocap::outputs
