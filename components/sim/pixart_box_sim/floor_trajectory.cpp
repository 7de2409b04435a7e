#include "sim/pixart_box_sim/floor_trajectory.hpp"

#include <cmath>
#include <stdexcept>

namespace mocap::pixart {
namespace {

constexpr double kPi = 3.14159265358979323846;

FloorPose circle_pose(const CircleFloorTrajectory& circle, double time_s) {
  if (!(circle.period_s > 0))
    throw std::invalid_argument("circle trajectory: period_s must be > 0");
  const double direction = circle.clockwise ? -1.0 : 1.0;
  // The fraction of a lap keeps the angle small however long the run: no precision lost.
  const double laps = std::fmod(time_s / circle.period_s, 1.0);
  const double angle = circle.phase_deg * kPi / 180 + direction * 2 * kPi * laps;
  FloorPose pose;
  pose.x = circle.centre.x() + circle.radius_m * std::cos(angle);
  pose.y = circle.centre.y() + circle.radius_m * std::sin(angle);
  pose.theta = wrap_angle(angle + direction * kPi / 2);
  return pose;
}

FloorPose waypoint_pose(const WaypointFloorTrajectory& path, double time_s) {
  if (!(path.speed_mps > 0)) {
    throw std::invalid_argument("waypoints trajectory: speed_mps must be > 0");
  }
  // The segments that have a length, in travel order; with a loop, back to the start too.
  struct Segment {
    Eigen::Vector2d from, to;
    double length;
  };
  std::vector<Segment> segments;
  const size_t count = path.points.size();
  const size_t ends = path.loop ? count : (count == 0 ? 0 : count - 1);
  for (size_t i = 0; i < ends; ++i) {
    const Eigen::Vector2d& from = path.points[i];
    const Eigen::Vector2d& to = path.points[(i + 1) % count];
    const double length = (to - from).norm();
    if (length > 0) segments.push_back({from, to, length});
  }
  if (segments.empty()) {
    throw std::invalid_argument("waypoints trajectory: needs at least two distinct points");
  }
  double total = 0;
  for (const Segment& segment : segments) total += segment.length;

  double distance = std::max(time_s, 0.0) * path.speed_mps;
  if (path.loop) {
    distance = std::fmod(distance, total);
  } else if (distance >= total) {
    const Segment& last = segments.back();
    const Eigen::Vector2d direction = last.to - last.from;
    return {last.to.x(), last.to.y(), std::atan2(direction.y(), direction.x())};
  }
  for (const Segment& segment : segments) {
    if (distance < segment.length || &segment == &segments.back()) {
      const Eigen::Vector2d direction = (segment.to - segment.from) / segment.length;
      const Eigen::Vector2d position =
          segment.from + std::min(distance, segment.length) * direction;
      return {position.x(), position.y(), std::atan2(direction.y(), direction.x())};
    }
    distance -= segment.length;
  }
  return {};  // not reached: the last segment always returns
}

}  // namespace

double wrap_angle(double angle) {
  double wrapped = std::remainder(angle, 2 * kPi);  // [-pi, pi]
  if (wrapped <= -kPi) wrapped += 2 * kPi;
  return wrapped;
}

FloorPose pose_at(const FloorTrajectory& trajectory, double time_s) {
  if (const auto* still = std::get_if<StaticFloorTrajectory>(&trajectory)) {
    FloorPose pose = still->pose;
    pose.theta = wrap_angle(pose.theta);
    return pose;
  }
  if (const auto* circle = std::get_if<CircleFloorTrajectory>(&trajectory)) {
    return circle_pose(*circle, time_s);
  }
  return waypoint_pose(std::get<WaypointFloorTrajectory>(trajectory), time_s);
}

}  // namespace mocap::pixart
