#include "outputs/body_frames/body_state_message.hpp"

#include "common/pose_message/pose_message.hpp"

namespace mocap::outputs {
namespace {

Matrix6d to_matrix(const std::array<double, 36>& row_major) {
  return Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(row_major.data());
}

}  // namespace

std::optional<BodyState> body_state(const mocap_msgs::msg::ConstellationPose& pose) {
  std::optional<Eigen::Isometry3d> parent_from_body = to_isometry(pose.pose().pose());
  if (!parent_from_body) return std::nullopt;
  const auto& v = pose.velocity();
  return BodyState{*parent_from_body, to_matrix(pose.covariance()),
                   Eigen::Vector3d(v.linear().x(), v.linear().y(), v.linear().z()),
                   Eigen::Vector3d(v.angular().x(), v.angular().y(), v.angular().z()),
                   to_matrix(pose.velocity_covariance())};
}

}  // namespace mocap::outputs
