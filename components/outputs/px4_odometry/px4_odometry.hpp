// A vehicle's state in PX4's frames, for px4_msgs/VehicleOdometry (external vision or motion
// capture through PX4's uXRCE-DDS bridge).
//
// Our world and bodies follow REP 103: a world with z up, bodies x forward, y left, z up
// (FLU). PX4 wants z down: the world NED (north, east, down) when ours is ENU (x east, y north),
// or FRD (a fixed arbitrary heading, z down) when ours points anywhere; the body FRD (forward,
// right, down). Quaternions PX4 writes w first, the body's attitude in the world frame.
#pragma once

#include <array>

#include "outputs/body_frames/body_frames.hpp"

namespace mocap::outputs {

// px4_msgs/VehicleOdometry's POSE_FRAME_* and VELOCITY_FRAME_* values.
enum class Px4Frame : uint8_t { Ned = 1, Frd = 2 };

struct Px4Odometry {
  Px4Frame frame = Px4Frame::Frd;  // of the pose and of the velocity
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::array<double, 4> q{1, 0, 0, 0};                         // w, x, y, z; w >= 0
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // in `frame`
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // in the body FRD frame
  Eigen::Vector3d position_variance = Eigen::Vector3d::Zero();
  Eigen::Vector3d orientation_variance = Eigen::Vector3d::Zero();  // about the body FRD axes
  Eigen::Vector3d velocity_variance = Eigen::Vector3d::Zero();
};

// `vehicle`: its FLU body in our world (ENU for Ned, any heading for Frd), as BodyState holds it.
// A vehicle whose orientation is unknown (a robot of one marker: orientation_unknown()) gets
// NaN in q, the angular velocity and their variances: PX4's mark of a field not measured.
Px4Odometry to_px4(const BodyState& vehicle, Px4Frame frame);

}  // namespace mocap::outputs
