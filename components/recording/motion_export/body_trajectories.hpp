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

  // A frame of the recording (a pose array, whichever bodies it holds): the frames a format of
  // fixed rows writes, with gaps where a body was not posed.
  void add_frame(int64_t stamp_ns) { frames_.push_back(stamp_ns); }

  // By name; each in the order added.
  const std::map<std::string, std::vector<StampedPose>>& bodies() const { return bodies_; }
  const std::vector<int64_t>& frames() const { return frames_; }
  uint64_t invalid_poses() const { return invalid_; }

 private:
  std::map<std::string, std::vector<StampedPose>> bodies_;
  std::vector<int64_t> frames_;
  uint64_t invalid_ = 0;
};

}  // namespace mocap::motion_export
