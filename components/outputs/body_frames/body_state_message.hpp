// A tracked board of /mocap/poses as a BodyState, for the plugins that hand it to other tools.
#pragma once

#include <optional>

#include <mocap_msgs/msg/constellation_pose.hpp>

#include "outputs/body_frames/body_frames.hpp"

namespace mocap::outputs {

// The board in the camera's optical frame (the message's frame) with its velocities and both
// covariances; nullopt when its pose is no pose (a position or quaternion not finite, or a
// quaternion of nearly zero length).
std::optional<BodyState> body_state(const mocap_msgs::msg::ConstellationPose& pose);

}  // namespace mocap::outputs
