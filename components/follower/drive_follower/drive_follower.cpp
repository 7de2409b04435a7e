#include "follower/drive_follower/drive_follower.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mocap::drive {

DriveFollower::DriveFollower(FollowerOptions options)
    : options_(options), rules_(options.drive), limiter_(options.acceleration) {
  if (!(options_.lost_after_s > 0)) {
    throw std::invalid_argument("lost_after_s must be positive, not " +
                                std::to_string(options_.lost_after_s));
  }
  if (!(options_.control_period_s > 0)) {
    throw std::invalid_argument("control_period_s must be positive, not " +
                                std::to_string(options_.control_period_s));
  }
}

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
