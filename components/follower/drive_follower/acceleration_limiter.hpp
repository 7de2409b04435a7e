// Limits how fast the commanded velocity changes, one control period at a time (the seed's
// proposed improvement: its base jerked when a rule switched or a track came back). Linear
// and angular velocity are limited independently.
//
//   AccelerationLimiter limiter({.max_linear_accel_mps2 = 1.0});
//   Velocity sent = limiter.limit(command.velocity(), period_s);
//   ...
//   sent = limiter.stop();  // track lost: zero at once
//
// A stop bypasses the limits: a base that cannot see what it follows must not coast on.
#pragma once

#include <optional>
#include <string>

#include "follower/drive_follower/velocity.hpp"

namespace mocap::drive {

struct AccelerationLimits {
  double max_linear_accel_mps2 = 1.0;  // infinite: no limit
  double max_angular_accel_rps2 = 3.0;

  // Why these limits cannot be used, naming the field ("max_linear_accel_mps2: 0 is not above
  // 0"); nullopt when they can. AccelerationLimiter's constructor throws
  // std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

class AccelerationLimiter {
 public:
  // Throws std::invalid_argument unless both limits are positive (problem()).
  explicit AccelerationLimiter(AccelerationLimits limits = {});

  // The velocity nearest `target` that the last one can reach in `period_s` (0 or less: the
  // last one); it becomes the last one.
  Velocity limit(const Velocity& target, double period_s);
  // Zero, at once.
  Velocity stop();

  const Velocity& last() const { return last_; }
  const AccelerationLimits& limits() const { return limits_; }

 private:
  AccelerationLimits limits_;
  Velocity last_;
};

}  // namespace mocap::drive
