#include "multi_camera_pose.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "pose_refinement.hpp"

namespace mocap::volume {
namespace {

// Every view's pixel residuals, one after the other, at the body pose `world_from_body`.
std::optional<Eigen::VectorXd> residuals(const std::vector<CameraView>& views, int points,
                                         const Eigen::Isometry3d& world_from_body) {
  Eigen::VectorXd values(2 * points);
  Eigen::Index at = 0;
  for (const CameraView& view : views) {
    const Eigen::Isometry3d camera_from_body = view.camera_from_world * world_from_body;
    for (size_t i = 0; i < view.body_points.size(); ++i) {
      auto projected = view.camera->project(camera_from_body * view.body_points[i]);
      if (!projected) return std::nullopt;
      values.segment<2>(at) = *projected - view.pixels[i];
      at += 2;
    }
  }
  return values;
}

}  // namespace

MultiCameraPose estimate_multi_camera_pose(const std::vector<CameraView>& views,
                                           const Eigen::Isometry3d& start,
                                           const MultiCameraPoseOptions& options) {
  if (options.min_points < 3) {
    throw std::invalid_argument(
        fmt::format("MultiCameraPoseOptions::min_points is {}: three points at least fix a pose",
                    options.min_points));
  }
  MultiCameraPose result;
  for (const CameraView& view : views) {
    if (view.camera == nullptr || view.body_points.size() != view.pixels.size()) {
      throw std::invalid_argument("a CameraView needs a camera and as many pixels as points");
    }
    result.points_used += static_cast<int>(view.body_points.size());
    if (!view.body_points.empty()) ++result.cameras_used;
  }
  if (result.points_used < options.min_points) {
    result.rejection =
        fmt::format("{} points in all views, {} needed", result.points_used, options.min_points);
    return result;
  }
  const pose::RefinedPose refined = pose::refine_pose(
      [&](const Eigen::Isometry3d& pose) { return residuals(views, result.points_used, pose); },
      start, options.max_iterations);
  if (!refined.valid) {
    result.rejection = "no pose near the start puts every point in front of its camera";
    return result;
  }
  result.world_from_body = refined.pose;
  result.reprojection_rms_px = std::sqrt(refined.squared_error / result.points_used);
  result.covariance = pose::pose_covariance(refined, 2 * result.points_used);
  const Eigen::VectorXd final_residuals = *residuals(views, result.points_used, refined.pose);
  Eigen::Index at = 0;
  for (const CameraView& view : views) {
    const Eigen::Index length = 2 * static_cast<Eigen::Index>(view.body_points.size());
    result.view_rms_px.push_back(
        length > 0 ? std::sqrt(final_residuals.segment(at, length).squaredNorm() / (length / 2))
                   : 0.0);
    at += length;
  }
  if (result.reprojection_rms_px > options.max_reprojection_rms_px) {
    result.rejection = fmt::format("reprojection RMS {:.2f} px exceeds {:.2f} px",
                                   result.reprojection_rms_px, options.max_reprojection_rms_px);
  } else {
    result.valid = true;
  }
  return result;
}

std::vector<double> rms_without_each_view_px(const std::vector<CameraView>& views,
                                             const Eigen::Isometry3d& start,
                                             const MultiCameraPoseOptions& options) {
  MultiCameraPoseOptions lenient = options;
  lenient.max_reprojection_rms_px = std::numeric_limits<double>::infinity();
  std::vector<double> out;
  for (size_t left_out = 0; left_out < views.size(); ++left_out) {
    std::vector<CameraView> others;
    for (size_t i = 0; i < views.size(); ++i) {
      if (i != left_out) others.push_back(views[i]);
    }
    const MultiCameraPose without = estimate_multi_camera_pose(others, start, lenient);
    out.push_back(without.valid ? without.reprojection_rms_px
                                : std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

}  // namespace mocap::volume
