// A robot's pose on the LED plane, and the rigid motion that carries an LED layout (robot
// frame) onto the points where the cameras saw those LEDs (world frame).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace mocap::pixart::localization {

// x, y in metres and θ in radians (counter-clockwise from world x), the robot's x axis being
// its heading: the transform from the robot frame to the world frame on the LED plane.
struct PlanarPose {
  double x = 0;
  double y = 0;
  double theta = 0;

  Eigen::Vector2d position() const { return {x, y}; }
  // A point of the robot frame (an LED's layout position) in the world frame.
  Eigen::Vector2d to_world(const Eigen::Vector2d& robot_point) const;
};

struct PlanarFit {
  PlanarPose pose;
  double rms_residual_m = 0;  // between the fitted layout and the observed points
  double max_residual_m = 0;
};

// The least-squares rigid motion (rotation and translation, never a reflection) taking
// `layout[i]` onto `observed[i]` (2D Kabsch). Needs at least two correspondences whose layout
// points are not all the same; throws std::invalid_argument otherwise. With two points it
// aligns their directions and their midpoints.
PlanarFit fit_planar_pose(const std::vector<Eigen::Vector2d>& layout,
                          const std::vector<Eigen::Vector2d>& observed);

// θ wrapped into (−π, π].
double wrap_angle(double theta);

}  // namespace mocap::pixart::localization
