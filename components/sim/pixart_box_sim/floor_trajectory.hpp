// How a robot (or a calibration board) moves on the floor under the PixArt rig: its planar
// pose over scene time. World frame as in pixart_rig.hpp: x, y on the floor, z up, metres;
// headings counter-clockwise from world x, radians.
#pragma once

#include <variant>
#include <vector>

#include <Eigen/Core>

namespace mocap::pixart {

// Where a robot is and which way it faces; its frame has x forward and y to its left.
struct FloorPose {
  double x = 0;
  double y = 0;
  double theta = 0;  // radians, in (-pi, pi]
};

// Standing still.
struct StaticFloorTrajectory {
  FloorPose pose;
};

// Round a circle at constant speed, facing along it (the tangent in the direction of travel).
// At time t the angle around the centre is phase + 2 pi t / period_s (counter-clockwise), or
// phase − 2 pi t / period_s when clockwise; angle 0 is the +x side of the centre.
struct CircleFloorTrajectory {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.3;
  double period_s = 20;  // one lap
  double phase_deg = 0;
  bool clockwise = false;
};

// Along a polyline at constant speed, facing along the segment it is on, from the first point
// at time 0. Without `loop` it stops at the last point, keeping the heading of the last
// segment; with `loop` it returns to the first point and goes round again. Repeated
// consecutive points are skipped (a zero-length segment has no heading).
struct WaypointFloorTrajectory {
  std::vector<Eigen::Vector2d> points;  // at least two distinct ones
  double speed_mps = 0.2;
  bool loop = false;
};

using FloorTrajectory =
    std::variant<StaticFloorTrajectory, CircleFloorTrajectory, WaypointFloorTrajectory>;

// The pose at scene time `time_s`. Times before 0 give the pose at 0 for waypoints (a circle
// and a static pose are defined at every time). Throws std::invalid_argument for a trajectory
// that cannot move (period or speed not positive, waypoints without two distinct points).
FloorPose pose_at(const FloorTrajectory& trajectory, double time_s);

// `angle` wrapped into (-pi, pi].
double wrap_angle(double angle);

}  // namespace mocap::pixart
