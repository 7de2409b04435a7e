#include "volume/pose_fusion/pose_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include "tracking/pose_estimator/pose_refinement.hpp"

namespace mocap::volume {
namespace {

// A sigma this small or smaller counts as this: a zero from a detector cannot weigh infinitely.
constexpr double kSmallestSigmaPx = 1e-3;

// The standard deviations about the best and the worst axes of a 3x3 covariance block; the
// worst infinite when the block is not finite or all zeros (pose_covariance's answer to points
// that leave the information singular, which no sigma of at least min_variance gives).
std::pair<double, double> best_and_worst_sigma(const Eigen::Matrix3d& covariance) {
  if (!covariance.allFinite() || covariance.isZero(0)) {
    return {0, std::numeric_limits<double>::infinity()};
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d variances = solver.eigenvalues().cwiseMax(0);
  return {std::sqrt(variances.minCoeff()), std::sqrt(variances.maxCoeff())};
}

// Every view's pixel residuals, one after the other, at the body pose `world_from_body`;
// `weighted`: each divided by its pixel's sigma.
std::optional<Eigen::VectorXd> residuals(const std::vector<CameraView>& views, int points,
                                         const Eigen::Isometry3d& world_from_body, bool weighted) {
  Eigen::VectorXd values(2 * points);
  Eigen::Index at = 0;
  for (const CameraView& view : views) {
    const Eigen::Isometry3d camera_from_body = view.camera_from_world * world_from_body;
    for (size_t i = 0; i < view.body_points.size(); ++i) {
      auto projected = view.camera->project(camera_from_body * view.body_points[i]);
      if (!projected) return std::nullopt;
      values.segment<2>(at) = *projected - view.pixels[i];
      if (weighted && !view.pixel_sigma_px.empty()) {
        values.segment<2>(at) /= std::max(view.pixel_sigma_px[i], kSmallestSigmaPx);
      }
      at += 2;
    }
  }
  return values;
}

}  // namespace

std::vector<CameraView> views_near(const std::vector<CameraDetections>& cameras,
                                   const std::vector<Eigen::Vector3d>& body_points,
                                   const Eigen::Isometry3d& world_from_body, double radius_px) {
  std::vector<CameraView> views;
  for (const CameraDetections& camera : cameras) {
    CameraView view{camera.camera, camera.camera_from_world, {}, {}, {}};
    std::vector<std::optional<Eigen::Vector2d>> projected;
    for (const Eigen::Vector3d& point : body_points) {
      const Eigen::Vector3d in_camera = camera.camera_from_world * world_from_body * point;
      projected.push_back(in_camera.z() > 0 ? camera.camera->project(in_camera) : std::nullopt);
    }
    auto distance = [&](size_t m, size_t d) {
      return projected[m] ? (camera.pixels[d] - *projected[m]).norm()
                          : std::numeric_limits<double>::infinity();
    };
    // Pairs that are each other's nearest: a hidden marker that projects near another's
    // detection does not take it, as the other projects nearer.
    for (size_t m = 0; m < body_points.size(); ++m) {
      size_t nearest = camera.pixels.size();
      for (size_t d = 0; d < camera.pixels.size(); ++d) {
        if (distance(m, d) <= radius_px &&
            (nearest == camera.pixels.size() || distance(m, d) < distance(m, nearest))) {
          nearest = d;
        }
      }
      if (nearest == camera.pixels.size()) continue;
      bool mutual = true;
      for (size_t other = 0; other < body_points.size() && mutual; ++other) {
        mutual = other == m || distance(other, nearest) > distance(m, nearest);
      }
      if (!mutual) continue;
      view.body_points.push_back(body_points[m]);
      view.pixels.push_back(camera.pixels[nearest]);
      if (!camera.pixel_sigma_px.empty()) {
        view.pixel_sigma_px.push_back(camera.pixel_sigma_px[nearest]);
      }
    }
    views.push_back(std::move(view));
  }
  return views;
}

std::optional<std::string> MultiCameraPoseOptions::problem() const {
  if (!(max_reprojection_rms_px > 0)) {
    return fmt::format("max_reprojection_rms_px: {} is not above 0", max_reprojection_rms_px);
  }
  if (min_points < 3) {
    return fmt::format("min_points: {}; three points at least fix a pose", min_points);
  }
  if (max_iterations < 1) return fmt::format("max_iterations: {} is below 1", max_iterations);
  if (!(max_orientation_sigma_ratio >= 1)) {
    return fmt::format("max_orientation_sigma_ratio: {} is below 1", max_orientation_sigma_ratio);
  }
  return std::nullopt;
}

MultiCameraPose estimate_multi_camera_pose(const std::vector<CameraView>& views,
                                           const Eigen::Isometry3d& start,
                                           const MultiCameraPoseOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("MultiCameraPoseOptions::" + *problem);
  }
  MultiCameraPose result;
  for (const CameraView& view : views) {
    if (view.camera == nullptr || view.body_points.size() != view.pixels.size() ||
        (!view.pixel_sigma_px.empty() && view.pixel_sigma_px.size() != view.pixels.size())) {
      throw std::invalid_argument(
          "a CameraView needs a camera, as many pixels as points and a sigma for each pixel or "
          "none");
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
      [&](const Eigen::Isometry3d& pose) {
        return residuals(views, result.points_used, pose, /*weighted=*/true);
      },
      start, options.max_iterations);
  if (!refined.valid) {
    result.rejection = "no pose near the start puts every point in front of its camera";
    return result;
  }
  result.world_from_body = refined.pose;
  result.covariance = pose::pose_covariance(refined, 2 * result.points_used, /*min_variance=*/1);
  result.normalized_rms = std::sqrt(refined.squared_error / (2 * result.points_used));
  const Eigen::VectorXd final_residuals =
      *residuals(views, result.points_used, refined.pose, /*weighted=*/false);
  result.reprojection_rms_px = std::sqrt(final_residuals.squaredNorm() / result.points_used);
  Eigen::Index at = 0;
  for (const CameraView& view : views) {
    const Eigen::Index length = 2 * static_cast<Eigen::Index>(view.body_points.size());
    result.view_rms_px.push_back(
        length > 0 ? std::sqrt(final_residuals.segment(at, length).squaredNorm() / (length / 2))
                   : 0.0);
    at += length;
  }
  const auto [best_sigma, worst_sigma] =
      best_and_worst_sigma(result.covariance.bottomRightCorner<3, 3>());
  if (result.reprojection_rms_px > options.max_reprojection_rms_px) {
    result.rejection = fmt::format("reprojection RMS {:.2f} px exceeds {:.2f} px",
                                   result.reprojection_rms_px, options.max_reprojection_rms_px);
  } else if (!(worst_sigma <= options.max_orientation_sigma_ratio * best_sigma)) {
    result.rejection = fmt::format(
        "the points do not fix the pose (on one line of the body?): its orientation's sigma "
        "about its worst axis, {:.3f} deg, is {:.0f} times that about its best",
        worst_sigma * 180 / M_PI, worst_sigma / best_sigma);
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
