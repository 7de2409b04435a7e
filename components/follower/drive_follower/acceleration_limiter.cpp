#include "follower/drive_follower/acceleration_limiter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::drive {
namespace {

double step_toward(double from, double to, double max_step) {
  return from + std::clamp(to - from, -max_step, max_step);
}

}  // namespace

std::optional<std::string> AccelerationLimits::problem() const {
  if (!(max_linear_accel_mps2 > 0)) {
    return fmt::format("max_linear_accel_mps2: {} is not above 0", max_linear_accel_mps2);
  }
  if (!(max_angular_accel_rps2 > 0)) {
    return fmt::format("max_angular_accel_rps2: {} is not above 0", max_angular_accel_rps2);
  }
  return std::nullopt;
}

AccelerationLimiter::AccelerationLimiter(AccelerationLimits limits) : limits_(limits) {
  if (auto problem = limits_.problem()) {
    throw std::invalid_argument("AccelerationLimits::" + *problem);
  }
}

Velocity AccelerationLimiter::limit(const Velocity& target, double period_s) {
  if (!(period_s > 0)) return last_;  // also keeps infinite limits from making 0 × inf
  last_.linear_mps =
      step_toward(last_.linear_mps, target.linear_mps, limits_.max_linear_accel_mps2 * period_s);
  last_.angular_rps =
      step_toward(last_.angular_rps, target.angular_rps, limits_.max_angular_accel_rps2 * period_s);
  return last_;
}

Velocity AccelerationLimiter::stop() {
  last_ = {};
  return last_;
}

}  // namespace mocap::drive
