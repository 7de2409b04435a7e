// Step 4 of the localizer: what is known of each robot between readings.
//
// A robot keeps its last pose until a new reading replaces it, so one standing still (its
// LEDs unchanged, or only its steady LED on) keeps being reported: the seed's earlier system
// lost such robots (seed 002 §1). A robot not read for `lost_after_s` is lost: it leaves the
// output, no longer lends its pose to the two- and one-LED readings, and comes back only
// through a three-LED reading. Each change (found, lost) is reported once as an event.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pixart/pixart_localizer/planar_fit.hpp"
#include "pixart/pixart_localizer/robot_recognition.hpp"

namespace mocap::pixart::localization {

struct TrackingOptions {
  double lost_after_s = 1.0;  // a robot not read for this long is dropped

  // Why these options cannot be used, naming the field ("lost_after_s: 0 is not above 0");
  // nullopt when they can. RobotTracker's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct TrackedRobot {
  std::string name;
  bool tracked = false;  // read within lost_after_s; false: never read, or lost
  PlanarPose pose;       // the last reading (kept while lost, for the log)
  int64_t last_seen_ns = 0;
  PoseEvidence evidence = PoseEvidence::AllLeds;  // how the last reading was made
};

struct TrackEvent {
  enum class Kind { Found, Lost };
  Kind kind = Kind::Found;
  size_t robot = 0;      // index into the rig's robots
  int64_t stamp_ns = 0;  // of the reading that found it, or when it was declared lost
};

class RobotTracker {
 public:
  RobotTracker(std::vector<std::string> robot_names, TrackingOptions options = {});

  // Applies the readings made from points of time `stamp_ns`. A reading older than the
  // robot's last one is ignored (samples of several cameras arrive in any order).
  void apply(const std::vector<Recognition>& readings, int64_t stamp_ns);

  // Declares lost every tracked robot not read since `now_ns` − lost_after_s.
  void expire(int64_t now_ns);

  // Per rig robot: its pose while tracked, else nullopt (what the recognizer needs).
  std::vector<std::optional<PlanarPose>> tracked_poses() const;
  // Per rig robot, tracked or not.
  const std::vector<TrackedRobot>& robots() const { return robots_; }
  // The events since the last call, in order.
  std::vector<TrackEvent> take_events();
  const TrackingOptions& options() const { return options_; }

 private:
  TrackingOptions options_;
  std::vector<TrackedRobot> robots_;
  std::vector<TrackEvent> events_;
};

}  // namespace mocap::pixart::localization
