#include "pixart/pixart_localizer/planar_fit.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mocap::pixart::localization {

Eigen::Vector2d PlanarPose::to_world(const Eigen::Vector2d& robot_point) const {
  double c = std::cos(theta), s = std::sin(theta);
  return {x + c * robot_point.x() - s * robot_point.y(),
          y + s * robot_point.x() + c * robot_point.y()};
}

double wrap_angle(double theta) {
  double wrapped = std::remainder(theta, 2 * M_PI);  // [−π, π]
  return wrapped <= -M_PI ? wrapped + 2 * M_PI : wrapped;
}

PlanarFit fit_planar_pose(const std::vector<Eigen::Vector2d>& layout,
                          const std::vector<Eigen::Vector2d>& observed) {
  if (layout.size() != observed.size() || layout.size() < 2) {
    throw std::invalid_argument("fit_planar_pose needs two or more correspondences");
  }
  const double n = static_cast<double>(layout.size());
  Eigen::Vector2d layout_centre = Eigen::Vector2d::Zero(),
                  observed_centre = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < layout.size(); ++i) {
    layout_centre += layout[i] / n;
    observed_centre += observed[i] / n;
  }
  // In 2D the optimal rotation has a closed form: the angle of Σ conj(a)·b over the centred
  // pairs seen as complex numbers, which cannot produce a reflection.
  double dot = 0, cross = 0, spread = 0;
  for (size_t i = 0; i < layout.size(); ++i) {
    Eigen::Vector2d a = layout[i] - layout_centre, b = observed[i] - observed_centre;
    dot += a.dot(b);
    cross += a.x() * b.y() - a.y() * b.x();
    spread += a.squaredNorm();
  }
  if (spread < 1e-18) throw std::invalid_argument("fit_planar_pose: the layout points coincide");

  PlanarFit fit;
  fit.pose.theta = std::atan2(cross, dot);
  // Translation: the rotated layout centre lands on the observed centre.
  PlanarPose rotation_only{0, 0, fit.pose.theta};
  Eigen::Vector2d translation = observed_centre - rotation_only.to_world(layout_centre);
  fit.pose.x = translation.x();
  fit.pose.y = translation.y();
  double squares = 0;
  for (size_t i = 0; i < layout.size(); ++i) {
    double residual = (fit.pose.to_world(layout[i]) - observed[i]).norm();
    squares += residual * residual;
    fit.max_residual_m = std::max(fit.max_residual_m, residual);
  }
  fit.rms_residual_m = std::sqrt(squares / n);
  return fit;
}

}  // namespace mocap::pixart::localization
