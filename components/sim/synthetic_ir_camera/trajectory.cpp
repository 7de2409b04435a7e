#include "sim/synthetic_ir_camera/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace mocap::synthetic {
namespace {

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

Eigen::Isometry3d make_pose(const Eigen::Vector3d& position, const Eigen::Matrix3d& rotation) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = position;
  return pose;
}

// x mod period in [0, period).
double wrap(double x, double period) {
  double wrapped = std::fmod(x, period);
  return wrapped < 0 ? wrapped + period : wrapped;
}

Eigen::Isometry3d pose_of(const StaticTrajectory& motion, double) {
  return make_pose(motion.position, facing_orientation(motion.rpy_deg));
}

Eigen::Isometry3d pose_of(const KeyframeTrajectory& motion, double time_s) {
  const std::vector<Keyframe>& keys = motion.keyframes;
  if (keys.empty()) throw std::invalid_argument("keyframes trajectory without keyframes");
  double start = keys.front().time_s;
  double duration = keys.back().time_s - start;
  if (motion.loop && duration > 0) time_s = start + wrap(time_s - start, duration);
  if (time_s <= start)
    return make_pose(keys.front().position, facing_orientation(keys.front().rpy_deg));
  if (time_s >= keys.back().time_s) {
    return make_pose(keys.back().position, facing_orientation(keys.back().rpy_deg));
  }
  // The first keyframe later than time_s ends the segment.
  auto after = std::upper_bound(keys.begin(), keys.end(), time_s,
                                [](double t, const Keyframe& key) { return t < key.time_s; });
  const Keyframe& a = *(after - 1);
  const Keyframe& b = *after;
  double alpha = (time_s - a.time_s) / (b.time_s - a.time_s);
  Eigen::Quaterniond qa(facing_orientation(a.rpy_deg));
  Eigen::Quaterniond qb(facing_orientation(b.rpy_deg));
  return make_pose((1 - alpha) * a.position + alpha * b.position,
                   qa.slerp(alpha, qb).toRotationMatrix());
}

Eigen::Isometry3d pose_of(const OrbitTrajectory& motion, double time_s) {
  if (!(motion.period_s > 0)) throw std::invalid_argument("orbit trajectory: period_s must be > 0");
  double angle = radians(motion.phase_deg) + 2 * std::numbers::pi * time_s / motion.period_s;
  Eigen::Vector3d offset =
      motion.plane == OrbitTrajectory::Plane::Frontal
          ? Eigen::Vector3d(std::cos(angle), -std::sin(angle), 0)  // y down: -sin goes up
          : Eigen::Vector3d(std::cos(angle), 0, std::sin(angle));
  // Positive tilt about camera x takes "up" (-y) towards +z, i.e. away from the camera.
  Eigen::AngleAxisd tilt(-radians(motion.tilt_deg), Eigen::Vector3d::UnitX());
  return make_pose(motion.centre + motion.radius_m * (tilt * offset),
                   facing_orientation(motion.rpy_deg));
}

Eigen::Isometry3d pose_of(const WalkTrajectory& motion, double time_s) {
  if (!(motion.speed_mps > 0))
    throw std::invalid_argument("walk trajectory: speed_mps must be > 0");
  double length = (motion.to - motion.from).norm();
  double round_trip_s = 2 * length / motion.speed_mps;
  double fraction = 0;  // 0 at `from`, 1 at `to`
  if (length > 0) {
    double travelled = wrap(time_s, round_trip_s) * motion.speed_mps / length;  // in [0, 2)
    fraction = travelled <= 1 ? travelled : 2 - travelled;
  }
  Eigen::Vector3d rpy = motion.rpy_deg;
  double swing_period_s = motion.swing_period_s > 0 ? motion.swing_period_s : round_trip_s;
  if (motion.yaw_swing_deg != 0 && swing_period_s > 0) {
    rpy.z() += motion.yaw_swing_deg * std::sin(2 * std::numbers::pi * time_s / swing_period_s);
  }
  return make_pose(motion.from + fraction * (motion.to - motion.from), facing_orientation(rpy));
}

Eigen::Isometry3d pose_of(const SpinTrajectory& motion, double time_s) {
  if (!(motion.axis.norm() > 0)) throw std::invalid_argument("spin trajectory: axis is zero");
  Eigen::AngleAxisd turn(radians(motion.rate_deg_s * time_s), motion.axis.normalized());
  return make_pose(motion.position, facing_orientation(motion.rpy_deg) * turn.toRotationMatrix());
}

}  // namespace

Eigen::Matrix3d facing_orientation(const Eigen::Vector3d& rpy_deg) {
  // Board x = camera x, board y = -camera y, board z = -camera z: half a turn about x.
  static const Eigen::Matrix3d kFacing = Eigen::Vector3d(1, -1, -1).asDiagonal();
  Eigen::Matrix3d relative = (Eigen::AngleAxisd(radians(rpy_deg.z()), Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(radians(rpy_deg.y()), Eigen::Vector3d::UnitX()) *
                              Eigen::AngleAxisd(radians(rpy_deg.x()), Eigen::Vector3d::UnitZ()))
                                 .toRotationMatrix();
  return kFacing * relative;
}

Eigen::Isometry3d pose_at(const Trajectory& trajectory, double time_s) {
  return std::visit([time_s](const auto& motion) { return pose_of(motion, time_s); }, trajectory);
}

std::string_view type_name(const Trajectory& trajectory) {
  static constexpr std::string_view kNames[] = {"static", "keyframes", "orbit", "walk", "spin"};
  return kNames[trajectory.index()];
}

}  // namespace mocap::synthetic
