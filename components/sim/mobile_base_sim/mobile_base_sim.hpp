// A two-wheeled (differential-drive) base on the floor: its pose in the world moved by
// velocity commands, the way ROS's turtlesim moved the seed's simulated turtlebot (seed 000
// §5.11.5), but integrated exactly: at constant (v, ω) the base runs along a circular arc,
// and each step lands on that arc whatever its length.
//
//   UnicycleBase base({.x = 1, .y = 0, .yaw = M_PI / 2});
//   base.step(0.5, 0.2, 0.01);  // v m/s, ω rad/s, for dt s
//   Eigen::Isometry3d world_from_base = base.world_from_base();
//
// World and base frames: x forward, y left, z up (REP 103); yaw counter-clockwise from the
// world's x axis.
#pragma once

#include <Eigen/Geometry>

namespace mocap::sim {

struct BasePose {
  double x = 0;    // m
  double y = 0;    // m
  double yaw = 0;  // rad, in (-pi, pi]
};

struct UnicycleLimits {
  double max_linear_mps = 0;   // 0: no limit
  double max_angular_rps = 0;  // 0: no limit
};

class UnicycleBase {
 public:
  explicit UnicycleBase(BasePose start = {}, UnicycleLimits limits = {});

  // Drives at (`linear_mps`, `angular_rps`), each clamped to its limit, for `dt_s` seconds
  // (nothing for dt_s <= 0). Non-finite commands are taken as zero.
  void step(double linear_mps, double angular_rps, double dt_s);

  const BasePose& pose() const { return pose_; }
  void set_pose(const BasePose& pose);
  // The base frame in the world, on the floor (z = 0).
  Eigen::Isometry3d world_from_base() const;
  // Path length driven so far, forward and backward alike.
  double odometer_m() const { return odometer_m_; }
  const UnicycleLimits& limits() const { return limits_; }

 private:
  BasePose pose_;
  UnicycleLimits limits_;
  double odometer_m_ = 0;
};

}  // namespace mocap::sim
