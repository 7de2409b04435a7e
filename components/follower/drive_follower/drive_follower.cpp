#include "follower/drive_follower/drive_follower.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace mocap::drive {
namespace {

// The options, once they are known to be usable: the rules and the limiter are built from them.
const FollowerOptions& checked(const FollowerOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("FollowerOptions::" + *problem);
  }
  return options;
}

}  // namespace

std::optional<std::string> FollowerOptions::problem() const {
  if (auto problem = drive.problem()) return "drive." + *problem;
  if (auto problem = acceleration.problem()) return "acceleration." + *problem;
  if (!(lost_after_s > 0)) return fmt::format("lost_after_s: {} is not above 0", lost_after_s);
  if (!(control_period_s > 0)) {
    return fmt::format("control_period_s: {} is not above 0", control_period_s);
  }
  return std::nullopt;
}

DriveFollower::DriveFollower(FollowerOptions options)
    : options_(checked(options)), rules_(options_.drive), limiter_(options_.acceleration) {}

void DriveFollower::observe(const ObjectInBase& object, double time_s) {
  object_ = object;
  seen_s_ = time_s;
}

FollowerStep DriveFollower::step(double time_s) {
  const double period_s =
      previous_step_s_ ? std::min(time_s - *previous_step_s_, 2 * options_.control_period_s) : 0;
  previous_step_s_ = time_s;
  FollowerStep step;
  const bool fresh = object_ && time_s - seen_s_ <= options_.lost_after_s;
  if (!fresh) {
    if (tracking_) {
      tracking_ = false;
      step.event = TrackEvent::Lost;
      rules_.reset();
    }
    step.velocity = limiter_.stop();
    return step;
  }
  if (!tracking_) {
    tracking_ = true;
    step.event = TrackEvent::Found;
  }
  step.command = rules_.command(*object_);
  step.velocity = limiter_.limit(step.command->velocity(), period_s);
  return step;
}

}  // namespace mocap::drive
