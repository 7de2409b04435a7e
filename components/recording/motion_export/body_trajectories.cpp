#include "recording/motion_export/body_trajectories.hpp"

#include <cmath>

namespace mocap::motion_export {

void BodyTrajectories::add(const std::string& body, int64_t stamp_ns,
                           const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation) {
  if (!position.allFinite() || !orientation.coeffs().allFinite() || orientation.norm() < 0.5) {
    ++invalid_;
    return;
  }
  StampedPose pose;
  pose.stamp_ns = stamp_ns;
  pose.world_from_body.translation() = position;
  pose.world_from_body.linear() = orientation.normalized().toRotationMatrix();
  bodies_[body].push_back(pose);
}

}  // namespace mocap::motion_export
