#include "follower/follower_monitor/follower_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::evaluation {

std::optional<std::string> FollowEvaluationOptions::problem() const {
  // A negative speed would count every object as walking, and none would ever stand.
  if (!(walking_speed_mps >= 0)) {
    return fmt::format("walking_speed_mps: {} is below 0", walking_speed_mps);
  }
  if (!(speed_window_s >= 0)) return fmt::format("speed_window_s: {} is below 0", speed_window_s);
  if (!(settle_s >= 0)) return fmt::format("settle_s: {} is below 0", settle_s);
  return std::nullopt;
}

FollowEvaluator::FollowEvaluator(FollowEvaluationOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("FollowEvaluationOptions::" + *problem);
  }
}

void FollowEvaluator::add_truth(int64_t stamp_ns, const Eigen::Vector3d& object_in_camera,
                                const Eigen::Isometry3d& world_from_camera, bool trackable) {
  const Eigen::Vector2d object = (world_from_camera * object_in_camera).head<2>();
  if (!recent_.empty() && stamp_ns <= recent_.back().first) return;  // out of order
  recent_.emplace_back(stamp_ns, object);
  const auto window_ns = static_cast<int64_t>(options_.speed_window_s * 1e9);
  while (recent_.size() > 2 && recent_[1].first <= stamp_ns - window_ns) recent_.pop_front();
  if (recent_.size() > 1) {
    speed_mps_ = (object - recent_.front().second).norm() /
                 (static_cast<double>(stamp_ns - recent_.front().first) * 1e-9);
  }
  const bool walking = speed_mps_ > options_.walking_speed_mps;
  if (walking || !trackable) {
    standing_since_ns_.reset();
  } else if (!standing_since_ns_) {
    standing_since_ns_ = stamp_ns;
  }
  if (!trackable) return;
  const double error =
      std::acos(std::clamp(object_in_camera.normalized().z(), -1.0, 1.0)) * 180 / M_PI;
  figures_.pointing_error_deg.push_back(error);
  if (walking) figures_.pointing_error_walking_deg.push_back(error);
  if (base_ && standing_since_ns_ &&
      static_cast<double>(stamp_ns - *standing_since_ns_) * 1e-9 >= options_.settle_s) {
    figures_.steady_distance_m.push_back((object - *base_).norm());
  }
}

void FollowEvaluator::add_velocity_command(int64_t received_ns, double linear, double angular) {
  const bool stop = linear == 0 && angular == 0;
  if (stop && moving_ && last_pose_ns_) {
    figures_.stop_latency_s.push_back(static_cast<double>(received_ns - *last_pose_ns_) * 1e-9);
  }
  moving_ = !stop;
}

Spread spread(std::vector<double> values) {
  if (values.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan};
  }
  std::sort(values.begin(), values.end());
  return {values[values.size() / 2], values[std::min(values.size() - 1, values.size() * 95 / 100)],
          values.back()};
}

}  // namespace mocap::evaluation
