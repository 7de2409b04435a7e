#include "follower/drive_follower/drive_rules.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mocap::drive {
namespace {

void require_positive(double value, const char* name) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw std::invalid_argument(std::string(name) + " must be a positive number, not " +
                                std::to_string(value));
  }
}

double wrap_angle(double angle) {
  angle = std::remainder(angle, 2 * M_PI);
  return angle <= -M_PI ? angle + 2 * M_PI : angle;
}

double clamp_magnitude(double value, double limit) { return std::clamp(value, -limit, limit); }

}  // namespace

void validate(const DriveOptions& options) {
  require_positive(options.goal_distance_m, "goal_distance_m");
  require_positive(options.goal_tolerance_m, "goal_tolerance_m");
  require_positive(options.arrival_tolerance_m, "arrival_tolerance_m");
  require_positive(options.linear_gain, "linear_gain");
  require_positive(options.angular_gain, "angular_gain");
  require_positive(options.max_linear_mps, "max_linear_mps");
  require_positive(options.max_angular_rps, "max_angular_rps");
  if (options.arrival_tolerance_m > options.goal_tolerance_m) {
    throw std::invalid_argument("arrival_tolerance_m (" +
                                std::to_string(options.arrival_tolerance_m) +
                                ") must not be larger than goal_tolerance_m (" +
                                std::to_string(options.goal_tolerance_m) + ")");
  }
}

std::string_view to_string(DriveRule rule) {
  switch (rule) {
    case DriveRule::Face:
      return "face";
    case DriveRule::Forward:
      return "forward";
    case DriveRule::Backward:
      return "backward";
  }
  return "unknown";
}

Eigen::Vector2d goal_position(const ObjectInBase& object, const DriveOptions& options) {
  return object.position + options.goal_distance_m * object.facing;
}

double bearing(const Eigen::Vector2d& point) {
  if (point.isZero()) return 0;
  return std::atan2(point.y(), point.x());
}

DriveCommand drive_command(const ObjectInBase& object, const DriveOptions& options,
                           double face_within_m) {
  const Eigen::Vector2d goal = goal_position(object, options);
  const double distance = goal.norm();
  DriveCommand command;
  if (distance <= face_within_m) {
    command.rule = DriveRule::Face;
    command.angular_rps =
        clamp_magnitude(options.angular_gain * bearing(object.position), options.max_angular_rps);
    return command;
  }
  double error = bearing(goal);
  double speed = std::min(options.max_linear_mps, options.linear_gain * distance);
  command.rule = DriveRule::Forward;
  if (std::abs(error) > M_PI / 2) {
    // Turning round first would cost a half turn and then the same distance; backing up
    // steers the rear toward the goal instead.
    command.rule = DriveRule::Backward;
    error = wrap_angle(error - M_PI);
    speed = -speed;
  }
  command.linear_mps = speed;
  command.angular_rps = clamp_magnitude(options.angular_gain * error, options.max_angular_rps);
  return command;
}

DriveRules::DriveRules(DriveOptions options) : options_(options) { validate(options_); }

DriveCommand DriveRules::command(const ObjectInBase& object) {
  const double face_within = holding_ ? options_.goal_tolerance_m : options_.arrival_tolerance_m;
  DriveCommand command = drive_command(object, options_, face_within);
  holding_ = command.rule == DriveRule::Face;
  return command;
}

}  // namespace mocap::drive
