// The drive follower without middleware: observations of the tracked object go in as they
// arrive, a velocity comes out every control period. Ties the driving rules
// (drive_rules.hpp), the acceleration limits (acceleration_limiter.hpp) and the safety stop
// of the seed (§5.11.4): a track not seen for `lost_after_s` stops the base at once.
//
//   DriveFollower follower(options);
//   follower.observe(object, now_s);          // each pose of the tracked object
//   FollowerStep step = follower.step(now_s);  // each control period
//   if (step.event == TrackEvent::Lost) alert();
//
// Times are seconds on one steady clock, chosen by the caller.
#pragma once

#include <optional>
#include <string>

#include "follower/drive_follower/acceleration_limiter.hpp"
#include "follower/drive_follower/drive_rules.hpp"

namespace mocap::drive {

struct FollowerOptions {
  DriveOptions drive;
  AccelerationLimits acceleration;
  double lost_after_s = 0.25;  // no observation for this long: the track is lost
  // The nominal time between steps. The acceleration limits use the time since the previous
  // step but at most two periods, so a loop that stalled does not allow a jump.
  double control_period_s = 0.05;

  // Why these options cannot be used, naming the field (nested ones by their path:
  // "drive.linear_gain: 0 is not above 0"); nullopt when they can. DriveFollower's constructor
  // throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

enum class TrackEvent {
  None,
  Found,  // observations arrive again (or for the first time)
  Lost,   // none for lost_after_s: this step is a stop
};

struct FollowerStep {
  Velocity velocity;                    // to send to the base
  std::optional<DriveCommand> command;  // what the rules asked for; none while not tracking
  TrackEvent event = TrackEvent::None;
};

class DriveFollower {
 public:
  // Throws std::invalid_argument, naming the field, for options that cannot be used.
  explicit DriveFollower(FollowerOptions options = {});

  void observe(const ObjectInBase& object, double time_s);
  // The velocity for the period that starts at `time_s`.
  FollowerStep step(double time_s);

  bool tracking() const { return tracking_; }
  const DriveRules& rules() const { return rules_; }
  const FollowerOptions& options() const { return options_; }

 private:
  FollowerOptions options_;
  DriveRules rules_;
  AccelerationLimiter limiter_;
  std::optional<ObjectInBase> object_;
  double seen_s_ = 0;
  std::optional<double> previous_step_s_;
  bool tracking_ = false;
};

}  // namespace mocap::drive
