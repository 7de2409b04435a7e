// geometry_msgs/Pose <-> Eigen::Isometry3d for the components that publish or read poses.
#pragma once

#include <optional>

#include <Eigen/Geometry>
#include <geometry_msgs/msg/pose.hpp>

namespace mocap {

geometry_msgs::msg::Pose to_pose_message(const Eigen::Isometry3d& pose);

// The pose a message describes, its quaternion normalised; nothing when the position is not
// finite or the quaternion is not finite or (nearly) zero, since no rotation fits it.
std::optional<Eigen::Isometry3d> to_isometry(const geometry_msgs::msg::Pose& pose);

}  // namespace mocap
