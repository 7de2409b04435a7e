#include "sim/mobile_base_sim/mobile_base_sim.hpp"

#include <algorithm>
#include <cmath>

namespace mocap::sim {
namespace {

double wrap_angle(double angle) {
  angle = std::remainder(angle, 2 * M_PI);
  return angle <= -M_PI ? angle + 2 * M_PI : angle;
}

double limited(double value, double limit) {
  if (!std::isfinite(value)) return 0;
  return limit > 0 ? std::clamp(value, -limit, limit) : value;
}

}  // namespace

UnicycleBase::UnicycleBase(BasePose start, UnicycleLimits limits) : limits_(limits) {
  set_pose(start);
}

void UnicycleBase::set_pose(const BasePose& pose) {
  pose_ = pose;
  pose_.yaw = wrap_angle(pose.yaw);
}

void UnicycleBase::step(double linear_mps, double angular_rps, double dt_s) {
  if (!(dt_s > 0)) return;
  const double v = limited(linear_mps, limits_.max_linear_mps);
  const double turn = limited(angular_rps, limits_.max_angular_rps) * dt_s;
  // The chord of the arc: length v·dt·sin(θ/2)/(θ/2), along the heading halfway through the
  // turn. Written this way it stays exact as θ goes to 0, where v/ω·(sin − sin) would divide
  // by nearly zero.
  const double half = turn / 2;
  const double chord_factor = std::abs(half) < 1e-6 ? 1 - half * half / 6 : std::sin(half) / half;
  const double chord = v * dt_s * chord_factor;
  const double heading = pose_.yaw + half;
  pose_.x += chord * std::cos(heading);
  pose_.y += chord * std::sin(heading);
  pose_.yaw = wrap_angle(pose_.yaw + turn);
  odometer_m_ += std::abs(v) * dt_s;
}

Eigen::Isometry3d UnicycleBase::world_from_base() const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(pose_.x, pose_.y, 0);
  pose.linear() = Eigen::AngleAxisd(pose_.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

}  // namespace mocap::sim
