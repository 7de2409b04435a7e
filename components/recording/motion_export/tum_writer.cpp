#include "recording/motion_export/tum_writer.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

namespace mocap::motion_export {

void write_tum(std::ostream& out, const std::string& body, const std::vector<StampedPose>& poses) {
  fmt::print(out, "# {}: timestamp tx ty tz qx qy qz qw (s, m; world frame)\n", body);
  for (const StampedPose& pose : poses) {
    Eigen::Quaterniond q(pose.world_from_body.linear());
    if (q.w() < 0) q.coeffs() *= -1;  // one of the two quaternions of a rotation, always the same
    const Eigen::Vector3d& t = pose.world_from_body.translation();
    fmt::print(out, "{}.{:09d} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n",
               pose.stamp_ns / 1'000'000'000, pose.stamp_ns % 1'000'000'000, t.x(), t.y(), t.z(),
               q.x(), q.y(), q.z(), q.w());
  }
}

}  // namespace mocap::motion_export
