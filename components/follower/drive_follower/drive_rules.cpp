#include "follower/drive_follower/drive_rules.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace mocap::drive {
namespace {

// Why `value` cannot be a distance, a gain or a limit, which must be positive: not above 0, or
// infinite.
std::optional<std::string> not_positive(const char* name, double value) {
  if (!(value > 0)) return fmt::format("{}: {} is not above 0", name, value);
  if (!std::isfinite(value)) return fmt::format("{}: {} is not finite", name, value);
  return std::nullopt;
}

double wrap_angle(double angle) {
  angle = std::remainder(angle, 2 * M_PI);
  return angle <= -M_PI ? angle + 2 * M_PI : angle;
}

double clamp_magnitude(double value, double limit) { return std::clamp(value, -limit, limit); }

}  // namespace

std::optional<std::string> DriveOptions::problem() const {
  if (auto problem = not_positive("goal_distance_m", goal_distance_m)) return problem;
  if (auto problem = not_positive("goal_tolerance_m", goal_tolerance_m)) return problem;
  if (auto problem = not_positive("arrival_tolerance_m", arrival_tolerance_m)) return problem;
  if (auto problem = not_positive("linear_gain", linear_gain)) return problem;
  if (auto problem = not_positive("angular_gain", angular_gain)) return problem;
  if (auto problem = not_positive("max_linear_mps", max_linear_mps)) return problem;
  if (auto problem = not_positive("max_angular_rps", max_angular_rps)) return problem;
  // Rule 2 would stop outside the circle in which rule 1 holds, and start again at once.
  if (arrival_tolerance_m > goal_tolerance_m) {
    return fmt::format("arrival_tolerance_m: {} is above goal_tolerance_m ({})",
                       arrival_tolerance_m, goal_tolerance_m);
  }
  return std::nullopt;
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

DriveRules::DriveRules(DriveOptions options) : options_(options) {
  if (auto problem = options_.problem()) throw std::invalid_argument("DriveOptions::" + *problem);
}

DriveCommand DriveRules::command(const ObjectInBase& object) {
  const double face_within = holding_ ? options_.goal_tolerance_m : options_.arrival_tolerance_m;
  DriveCommand command = drive_command(object, options_, face_within);
  holding_ = command.rule == DriveRule::Face;
  return command;
}

}  // namespace mocap::drive
