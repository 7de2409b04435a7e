// Joint angles of the turret (turret_model.hpp) as AX-12A servo positions and back: the
// servo's position register counts 0..1023 over 300 degrees from its centre, and the joint
// angle is direction × (servo angle from the joint's zero_position).
#pragma once

#include <cstdint>

#include "follower/turret_kinematics/turret_model.hpp"

namespace mocap::turret {

// The position register value that puts `joint` at `angle` (radians), clamped to 0..1023.
uint16_t servo_position(const Joint& joint, double angle);

// The joint angle (radians) of a present position register value.
double joint_angle(const Joint& joint, uint16_t position);

}  // namespace mocap::turret
