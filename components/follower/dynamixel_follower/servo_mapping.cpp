#include "follower/dynamixel_follower/servo_mapping.hpp"

#include <algorithm>
#include <cmath>

#include "follower/dynamixel/ax12_control_table.hpp"

namespace mocap::turret {

using dynamixel::ax12::kMaxPosition;
using dynamixel::ax12::kRadiansPerPositionUnit;

uint16_t servo_position(const Joint& joint, double angle) {
  const double units = std::round(joint.servo.zero_position +
                                  joint.servo.direction * angle / kRadiansPerPositionUnit);
  if (!(units > 0)) return 0;  // NaN as well
  return static_cast<uint16_t>(std::min(units, double{kMaxPosition}));
}

double joint_angle(const Joint& joint, uint16_t position) {
  return joint.servo.direction * (static_cast<int>(position) - joint.servo.zero_position) *
         kRadiansPerPositionUnit;
}

}  // namespace mocap::turret
