// The TUM RGB-D benchmark's trajectory format, which evo and most VIO/SLAM evaluation read: one
// line per pose, "timestamp tx ty tz qx qy qz qw" (seconds, metres, the unit quaternion of the
// body's orientation in the world frame), '#' starting a comment.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "recording/motion_export/body_trajectories.hpp"

namespace mocap::motion_export {

// `poses` as TUM lines, after a comment naming the body: timestamps with nanoseconds (9
// decimals), positions to the nanometre (9 decimals), quaternions with w >= 0 to 1e-9.
void write_tum(std::ostream& out, const std::string& body, const std::vector<StampedPose>& poses);

}  // namespace mocap::motion_export
