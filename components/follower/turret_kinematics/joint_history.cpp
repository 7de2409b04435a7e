#include "follower/turret_kinematics/joint_history.hpp"

#include <algorithm>

namespace mocap::turret {

void JointHistory::add(int64_t stamp_ns, const JointAngles& angles) {
  if (!readings_.empty() && stamp_ns < readings_.back().stamp_ns) return;
  readings_.push_back({stamp_ns, angles});
  while (readings_.front().stamp_ns < stamp_ns - span_ns_) readings_.pop_front();
}

std::optional<JointAngles> JointHistory::at(int64_t stamp_ns) const {
  if (readings_.empty()) return std::nullopt;
  if (stamp_ns <= readings_.front().stamp_ns) return readings_.front().angles;
  if (stamp_ns >= readings_.back().stamp_ns) return readings_.back().angles;
  auto after = std::lower_bound(
      readings_.begin(), readings_.end(), stamp_ns,
      [](const Reading& reading, int64_t stamp) { return reading.stamp_ns < stamp; });
  auto before = after - 1;
  const double f = static_cast<double>(stamp_ns - before->stamp_ns) /
                   static_cast<double>(after->stamp_ns - before->stamp_ns);
  return JointAngles{before->angles.pan + f * (after->angles.pan - before->angles.pan),
                     before->angles.tilt + f * (after->angles.tilt - before->angles.tilt)};
}

std::optional<JointAngles> JointHistory::latest() const {
  if (readings_.empty()) return std::nullopt;
  return readings_.back().angles;
}

}  // namespace mocap::turret
