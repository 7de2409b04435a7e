#include "pixart/pixart_localizer/robot_tracking.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace mocap::pixart::localization {

std::optional<std::string> TrackingOptions::problem() const {
  if (!(lost_after_s > 0)) return fmt::format("lost_after_s: {} is not above 0", lost_after_s);
  if (!std::isfinite(lost_after_s)) {
    return fmt::format("lost_after_s: {} is not finite", lost_after_s);
  }
  return std::nullopt;
}

RobotTracker::RobotTracker(std::vector<std::string> robot_names, TrackingOptions options)
    : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("TrackingOptions::" + *problem);
  }
  for (std::string& name : robot_names) {
    TrackedRobot robot;
    robot.name = std::move(name);
    robots_.push_back(std::move(robot));
  }
}

void RobotTracker::apply(const std::vector<Recognition>& readings, int64_t stamp_ns) {
  for (const Recognition& reading : readings) {
    TrackedRobot& robot = robots_.at(reading.robot);
    if (robot.tracked && stamp_ns < robot.last_seen_ns) continue;
    if (!robot.tracked) events_.push_back({TrackEvent::Kind::Found, reading.robot, stamp_ns});
    robot.tracked = true;
    robot.pose = reading.pose;
    robot.pose.theta = wrap_angle(robot.pose.theta);
    robot.last_seen_ns = stamp_ns;
    robot.evidence = reading.evidence;
  }
}

void RobotTracker::expire(int64_t now_ns) {
  const auto lost_after_ns = static_cast<int64_t>(std::llround(options_.lost_after_s * 1e9));
  for (size_t r = 0; r < robots_.size(); ++r) {
    TrackedRobot& robot = robots_[r];
    if (robot.tracked && now_ns - robot.last_seen_ns > lost_after_ns) {
      robot.tracked = false;
      events_.push_back({TrackEvent::Kind::Lost, r, now_ns});
    }
  }
}

std::vector<std::optional<PlanarPose>> RobotTracker::tracked_poses() const {
  std::vector<std::optional<PlanarPose>> poses(robots_.size());
  for (size_t r = 0; r < robots_.size(); ++r) {
    if (robots_[r].tracked) poses[r] = robots_[r].pose;
  }
  return poses;
}

std::vector<TrackEvent> RobotTracker::take_events() { return std::exchange(events_, {}); }

}  // namespace mocap::pixart::localization
