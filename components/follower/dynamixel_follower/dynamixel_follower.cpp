#include "follower/dynamixel_follower/dynamixel_follower.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace mocap::turret {
namespace {

// Why `value` cannot be a speed or a time that must be positive: not above 0, or infinite.
std::optional<std::string> not_positive(const char* name, double value) {
  if (!(value > 0)) return fmt::format("{}: {} is not above 0", name, value);
  if (!std::isfinite(value)) return fmt::format("{}: {} is not finite", name, value);
  return std::nullopt;
}

}  // namespace

const char* to_string(TurretMode mode) {
  switch (mode) {
    case TurretMode::Idle:
      return "idle";
    case TurretMode::Tracking:
      return "tracking";
    case TurretMode::Holding:
      return "holding";
    case TurretMode::Searching:
      return "searching";
  }
  return "?";
}

std::optional<std::string> TurretFollowerOptions::problem() const {
  if (auto problem = not_positive("pan_speed_rps", pan_speed_rps)) return problem;
  if (auto problem = not_positive("tilt_speed_rps", tilt_speed_rps)) return problem;
  if (auto problem = not_positive("lost_after_s", lost_after_s)) return problem;
  if (!(max_lead_s >= 0)) return fmt::format("max_lead_s: {} is below 0", max_lead_s);
  if (auto problem = not_positive("velocity_window_s", velocity_window_s)) return problem;
  if (!(hold_s >= 0)) return fmt::format("hold_s: {} is below 0", hold_s);
  if (auto problem = not_positive("search_speed_rps", search_speed_rps)) return problem;
  return std::nullopt;
}

TurretFollower::TurretFollower(TurretModel turret, TurretFollowerOptions options)
    : turret_(std::move(turret)), options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("TurretFollowerOptions::" + *problem);
  }
}

void TurretFollower::observe(int64_t stamp_ns, const Eigen::Vector3d& in_camera,
                             const JointAngles& angles) {
  if (object_in_base_ && stamp_ns < last_seen_ns_) return;  // an older image arriving late
  object_in_base_ = turret_.base_from_camera(angles) * in_camera;
  // A track lost and found again starts its motion afresh.
  if (!recent_.empty() && (stamp_ns - recent_.back().first) * 1e-9 > options_.lost_after_s) {
    recent_.clear();
  }
  last_seen_ns_ = stamp_ns;
  recent_.emplace_back(stamp_ns, *object_in_base_);
  const auto window_ns = static_cast<int64_t>(options_.velocity_window_s * 1e9);
  while (stamp_ns - recent_.front().first > window_ns) recent_.pop_front();
  velocity_in_base_.reset();
  if (recent_.size() < 3 || (stamp_ns - recent_.front().first) * 1e-9 < 0.1) return;
  // The least-squares line through (time, position): its slope is the velocity.
  double mean_t = 0;
  Eigen::Vector3d mean_p = Eigen::Vector3d::Zero();
  for (const auto& [stamp, position] : recent_) {
    mean_t += (stamp - stamp_ns) * 1e-9;
    mean_p += position;
  }
  mean_t /= static_cast<double>(recent_.size());
  mean_p /= static_cast<double>(recent_.size());
  double spread = 0;
  Eigen::Vector3d covariance = Eigen::Vector3d::Zero();
  for (const auto& [stamp, position] : recent_) {
    const double t = (stamp - stamp_ns) * 1e-9 - mean_t;
    spread += t * t;
    covariance += t * (position - mean_p);
  }
  velocity_in_base_ = covariance / spread;
}

TurretCommand TurretFollower::update(int64_t now_ns, const JointAngles& present) {
  TurretCommand command;
  command.speed = {options_.pan_speed_rps, options_.tilt_speed_rps};
  if (!object_in_base_) {
    command.goal = present;
    return command;
  }
  const double since_seen_s = static_cast<double>(now_ns - last_seen_ns_) * 1e-9;
  if (since_seen_s <= options_.lost_after_s) {
    held_.reset();
    Eigen::Vector3d target = *object_in_base_;
    if (velocity_in_base_) {
      target += *velocity_in_base_ * std::clamp(since_seen_s, 0.0, options_.max_lead_s);
    }
    const Aim aim = turret_.aim_at(target, present);
    command.mode = TurretMode::Tracking;
    command.goal = aim.angles;
    command.out_of_reach = !aim.within_limits;
    command.pointing_error_rad = turret_.pointing_error(present, target);
    return command;
  }
  if (!held_) held_ = present;
  if (!options_.search || since_seen_s <= options_.lost_after_s + options_.hold_s) {
    command.mode = TurretMode::Holding;
    command.goal = *held_;
    return command;
  }
  // Sweep: head for one pan limit at the search speed; turn round there.
  command.mode = TurretMode::Searching;
  const Joint& pan = turret_.pan();
  if (present.pan >= pan.max_rad - 0.01) search_direction_ = -1;
  if (present.pan <= pan.min_rad + 0.01) search_direction_ = 1;
  command.goal = {search_direction_ > 0 ? pan.max_rad : pan.min_rad, 0.0};
  command.speed = {options_.search_speed_rps, options_.tilt_speed_rps};
  return command;
}

}  // namespace mocap::turret
