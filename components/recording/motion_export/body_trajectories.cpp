#include "recording/motion_export/body_trajectories.hpp"

namespace mocap::motion_export {

void BodyTrajectories::add(const std::string& body, int64_t stamp_ns,
                           const std::optional<Eigen::Isometry3d>& world_from_body) {
  if (!world_from_body) {
    ++invalid_;
    return;
  }
  bodies_[body].push_back({stamp_ns, *world_from_body});
}

}  // namespace mocap::motion_export
