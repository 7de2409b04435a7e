// geometry_msgs/Pose <-> Eigen::Isometry3d for the components that publish or read poses, and
// the transforms of /tf and /tf_static.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <geometry_msgs/msg/pose.hpp>
#include <geometry_msgs/msg/transform_stamped.hpp>
#include <geometry_msgs/msg/twist.hpp>
#include <std_msgs/msg/header.hpp>

namespace mocap {

geometry_msgs::msg::Pose to_pose_message(const Eigen::Isometry3d& pose);

// A body's linear (m/s) and angular (rad/s) velocity as a Twist.
geometry_msgs::msg::Twist to_twist_message(const Eigen::Vector3d& linear,
                                           const Eigen::Vector3d& angular);

// The pose a message describes, its quaternion normalised; nothing when the position is not
// finite or the quaternion is not finite or (nearly) zero, since no rotation fits it.
std::optional<Eigen::Isometry3d> to_isometry(const geometry_msgs::msg::Pose& pose);

// `child` in `header`'s frame, as tf2 has it: the quaternion with w >= 0, as
// static_transform_publisher writes it (q and -q are the same rotation).
geometry_msgs::msg::TransformStamped to_transform(const std_msgs::msg::Header& header,
                                                  const std::string& child,
                                                  const Eigen::Isometry3d& parent_from_child);

}  // namespace mocap
