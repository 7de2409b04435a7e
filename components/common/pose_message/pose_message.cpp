#include "common/pose_message/pose_message.hpp"

#include <cmath>

namespace mocap {

geometry_msgs::msg::Pose to_pose_message(const Eigen::Isometry3d& pose) {
  geometry_msgs::msg::Pose message;
  const Eigen::Vector3d& t = pose.translation();
  message.position().x(t.x());
  message.position().y(t.y());
  message.position().z(t.z());
  const Eigen::Quaterniond q(pose.linear());
  message.orientation().x(q.x());
  message.orientation().y(q.y());
  message.orientation().z(q.z());
  message.orientation().w(q.w());
  return message;
}

geometry_msgs::msg::Twist to_twist_message(const Eigen::Vector3d& linear,
                                           const Eigen::Vector3d& angular) {
  geometry_msgs::msg::Twist message;
  message.linear().x(linear.x());
  message.linear().y(linear.y());
  message.linear().z(linear.z());
  message.angular().x(angular.x());
  message.angular().y(angular.y());
  message.angular().z(angular.z());
  return message;
}

std::optional<Eigen::Isometry3d> to_isometry(const geometry_msgs::msg::Pose& pose) {
  const auto& p = pose.position();
  const auto& q = pose.orientation();
  const Eigen::Quaterniond rotation(q.w(), q.x(), q.y(), q.z());
  const double norm = rotation.norm();
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()) ||
      !std::isfinite(norm) || norm < 1e-6) {
    return std::nullopt;
  }
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = rotation.normalized().toRotationMatrix();
  isometry.translation() = Eigen::Vector3d(p.x(), p.y(), p.z());
  return isometry;
}

geometry_msgs::msg::TransformStamped to_transform(const std_msgs::msg::Header& header,
                                                  const std::string& child,
                                                  const Eigen::Isometry3d& parent_from_child) {
  geometry_msgs::msg::TransformStamped message;
  message.header(header);
  message.child_frame_id(child);
  Eigen::Quaterniond q(parent_from_child.linear());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  message.transform().translation().x(parent_from_child.translation().x());
  message.transform().translation().y(parent_from_child.translation().y());
  message.transform().translation().z(parent_from_child.translation().z());
  message.transform().rotation().x(q.x());
  message.transform().rotation().y(q.y());
  message.transform().rotation().z(q.z());
  message.transform().rotation().w(q.w());
  return message;
}

}  // namespace mocap
