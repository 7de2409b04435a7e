// A two-wheeled base's velocity command: what geometry_msgs/Twist carries for it (linear.x,
// angular.z). Such a base can only drive along its heading and turn; both at once is an arc.
#pragma once

namespace mocap::drive {

struct Velocity {
  double linear_mps = 0;   // forward positive
  double angular_rps = 0;  // counter-clockwise (left) positive, seen from above

  friend bool operator==(const Velocity&, const Velocity&) = default;
};

}  // namespace mocap::drive
