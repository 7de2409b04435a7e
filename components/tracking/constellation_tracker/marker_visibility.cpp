#include "tracking/constellation_tracker/marker_visibility.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::tracking {

std::optional<std::string> VisibilityOptions::problem() const {
  // Beyond 90 degrees a disc faces away from the camera; the cosine would not tell a negative
  // angle from its opposite.
  if (!(max_view_angle_deg >= 0 && max_view_angle_deg <= 90)) {
    return fmt::format("max_view_angle_deg: {} is not in [0, 90]", max_view_angle_deg);
  }
  if (!(border_margin_px >= 0)) {
    return fmt::format("border_margin_px: {} is below 0", border_margin_px);
  }
  return std::nullopt;
}

std::vector<MarkerImage> marker_images(const calibration::CameraModel& camera,
                                       const constellations::ConstellationModel& model,
                                       const Eigen::Isometry3d& camera_from_body,
                                       const VisibilityOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("VisibilityOptions::" + *problem);
  }
  const double min_cosine = std::cos(options.max_view_angle_deg * M_PI / 180);
  const Eigen::Vector3d normal = camera_from_body.linear().col(2);
  const double margin = options.border_margin_px;
  std::vector<MarkerImage> images(model.points.size());
  for (size_t m = 0; m < model.points.size(); ++m) {
    const Eigen::Vector3d position = camera_from_body * model.points[m];
    auto pixel = camera.project(position);
    if (!pixel || position.z() <= 0) continue;
    images[m].pixel = *pixel;
    const double distance = position.norm();
    if (!(normal.dot(-position) >= min_cosine * distance)) {
      images[m].sight = MarkerSight::FacingAway;
    } else if (pixel->x() < margin - 0.5 || pixel->y() < margin - 0.5 ||
               pixel->x() > camera.width() - 0.5 - margin ||
               pixel->y() > camera.height() - 0.5 - margin) {
      images[m].sight = MarkerSight::OutOfFrame;
    } else {
      images[m].sight = MarkerSight::InView;
    }
  }
  return images;
}

bool one_band_covers(const std::vector<Eigen::Vector2d>& hidden,
                     const std::vector<Eigen::Vector2d>& seen, int spare) {
  if (static_cast<int>(hidden.size()) <= spare || seen.empty()) return true;
  // Seen along a direction n, a band is an interval of projections; it works when it holds
  // all but `spare` hidden points and no seen one. Which points an interval can hold changes
  // only where n is perpendicular to the difference of two points, so trying each side of
  // every such critical direction tries every case.
  std::vector<std::pair<double, int>> along;  // projection, 1 = hidden / 0 = seen
  auto covers_along = [&](const Eigen::Vector2d& n) {
    along.clear();
    for (const auto& h : hidden) along.emplace_back(n.dot(h), 1);
    for (const auto& s : seen) along.emplace_back(n.dot(s), 0);
    std::sort(along.begin(), along.end());
    // The longest run of hidden points between seen ones.
    int run = 0, longest = 0;
    for (const auto& [position, is_hidden] : along) {
      run = is_hidden ? run + 1 : 0;
      longest = std::max(longest, run);
    }
    return longest + spare >= static_cast<int>(hidden.size());
  };
  std::vector<Eigen::Vector2d> points = hidden;
  points.insert(points.end(), seen.begin(), seen.end());
  constexpr double kTurn = 1e-6;  // radians either side of a critical direction
  for (size_t a = 0; a < points.size(); ++a) {
    for (size_t b = a + 1; b < points.size(); ++b) {
      const Eigen::Vector2d difference = points[b] - points[a];
      if (difference.squaredNorm() < 1e-18) continue;
      const double critical = std::atan2(difference.y(), difference.x()) + M_PI / 2;
      for (double angle : {critical - kTurn, critical + kTurn}) {
        if (covers_along({std::cos(angle), std::sin(angle)})) return true;
      }
    }
  }
  return false;
}

bool behind_board(const Eigen::Vector3d& point, const constellations::ConstellationModel& model,
                  const Eigen::Isometry3d& camera_from_board, double margin_m) {
  const Eigen::Vector3d normal = camera_from_board.linear().col(2);
  const double towards = normal.dot(point);
  if (std::abs(towards) < 1e-12) return false;
  // The line of sight s·point meets the board's plane at s; between the camera and the point
  // when 0 < s < 1.
  const double s = normal.dot(camera_from_board.translation()) / towards;
  if (!(s > 0 && s < 1 - 1e-9)) return false;
  const Eigen::Vector3d on_board = camera_from_board.inverse() * (s * point);
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const auto& p : model.points) {
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  return on_board.x() >= x0 - margin_m && on_board.x() <= x1 + margin_m &&
         on_board.y() >= y0 - margin_m && on_board.y() <= y1 + margin_m;
}

}  // namespace mocap::tracking
