// Each body's poses over a recording, gathered from pose arrays in the order they come: what the
// export formats (tum_writer.hpp) write. Middleware-free.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace mocap::motion_export {

struct StampedPose {
  int64_t stamp_ns = 0;  // capture time
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
};

class BodyTrajectories {
 public:
  // One body's pose at `stamp_ns`; none (a pose message that is no pose) is counted and left
  // out.
  void add(const std::string& body, int64_t stamp_ns,
           const std::optional<Eigen::Isometry3d>& world_from_body);

  // By name; each in the order added.
  const std::map<std::string, std::vector<StampedPose>>& bodies() const { return bodies_; }
  uint64_t invalid_poses() const { return invalid_; }

 private:
  std::map<std::string, std::vector<StampedPose>> bodies_;
  uint64_t invalid_ = 0;
};

}  // namespace mocap::motion_export
