#include "tracking/pose_estimator/planar_pose.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/SVD>

#include "tracking/pose_estimator/ippe.hpp"
#include "tracking/pose_estimator/pose_refinement.hpp"

namespace mocap::pose {
namespace {

// The pixel residuals of `object` seen through `camera` at `pose`.
std::optional<Eigen::VectorXd> residuals(const calibration::CameraModel& camera,
                                         const Eigen::Isometry3d& pose,
                                         const std::vector<Eigen::Vector3d>& object,
                                         const std::vector<Eigen::Vector2d>& pixels) {
  Eigen::VectorXd values(2 * static_cast<Eigen::Index>(object.size()));
  for (size_t i = 0; i < object.size(); ++i) {
    auto projected = camera.project(pose * object[i]);
    if (!projected) return std::nullopt;
    values.segment<2>(2 * static_cast<Eigen::Index>(i)) = *projected - pixels[i];
  }
  return values;
}

struct Refined {
  RefinedPose refined;
  double rms = 0;
};

Refined refine(const calibration::CameraModel& camera, const Eigen::Isometry3d& start,
               const std::vector<Eigen::Vector3d>& object,
               const std::vector<Eigen::Vector2d>& pixels, int max_iterations) {
  Refined out;
  out.refined = refine_pose(
      [&](const Eigen::Isometry3d& pose) { return residuals(camera, pose, object, pixels); }, start,
      max_iterations);
  out.rms = std::sqrt(out.refined.squared_error / static_cast<double>(object.size()));
  return out;
}

// The pairs the camera can use: finite, and seen by a pixel the model can unproject.
struct UsablePoints {
  std::vector<Eigen::Vector3d> object;
  std::vector<Eigen::Vector2d> image;
  std::vector<Eigen::Vector2d> rays;  // normalised: x/z, y/z
};

UsablePoints usable_points(const calibration::CameraModel& camera,
                           const std::vector<Eigen::Vector3d>& object_points,
                           const std::vector<Eigen::Vector2d>& pixels) {
  UsablePoints usable;
  for (size_t i = 0; i < object_points.size() && i < pixels.size(); ++i) {
    if (!pixels[i].allFinite() || !object_points[i].allFinite()) continue;
    auto ray = camera.unproject(pixels[i]);
    if (!ray) continue;
    usable.object.push_back(object_points[i]);
    usable.image.push_back(pixels[i]);
    usable.rays.push_back(ray->head<2>());
  }
  return usable;
}

bool enough_points(const PlanarPoseOptions& options, PlanarPose& result) {
  if (result.points_used >= options.min_points) return true;
  result.rejection =
      fmt::format("{} usable points, {} needed", result.points_used, options.min_points);
  return false;
}

// The refined pose as the result: its covariance and the checks that reject it.
void accept_if_valid(const Refined& best, const PlanarPoseOptions& options, PlanarPose& result) {
  result.camera_from_object = best.refined.pose;
  result.reprojection_rms_px = best.rms;
  result.covariance = pose_covariance(best.refined, 2 * result.points_used);
  if (best.refined.pose.translation().z() <= 0) {
    result.rejection = "the pose puts the object behind the camera";
  } else if (best.rms > options.max_reprojection_rms_px) {
    result.rejection = fmt::format("reprojection RMS {:.2f} px exceeds {:.2f} px", best.rms,
                                   options.max_reprojection_rms_px);
  } else {
    result.valid = true;
  }
}

}  // namespace

std::optional<std::string> PlanarPoseOptions::problem() const {
  if (!(max_reprojection_rms_px > 0)) {
    return fmt::format("max_reprojection_rms_px: {} is not above 0", max_reprojection_rms_px);
  }
  if (min_points < 4) {
    return fmt::format("min_points: {}; four points at least fix a plane's pose", min_points);
  }
  if (max_iterations < 1) return fmt::format("max_iterations: {} is below 1", max_iterations);
  return std::nullopt;
}

PlanarPose estimate_planar_pose(const calibration::CameraModel& camera,
                                const std::vector<Eigen::Vector3d>& object_points,
                                const std::vector<Eigen::Vector2d>& pixels,
                                const PlanarPoseOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("PlanarPoseOptions::" + *problem);
  }
  PlanarPose result;
  // Points the camera model cannot unproject (or non-finite ones) are left out.
  UsablePoints usable = usable_points(camera, object_points, pixels);
  const auto& object = usable.object;
  const auto& image = usable.image;
  const auto& rays = usable.rays;
  result.points_used = static_cast<int>(object.size());
  if (!enough_points(options, result)) return result;
  // The object's plane as its own frame: IPPE wants z = 0 points.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const auto& p : object) origin += p;
  origin /= static_cast<double>(object.size());
  Eigen::MatrixXd centred(3, object.size());
  for (size_t i = 0; i < object.size(); ++i) centred.col(i) = object[i] - origin;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinU);
  if (svd.singularValues()(1) < 1e-6 * std::max(1.0, svd.singularValues()(0))) {
    result.rejection = "the points lie on one line";
    return result;
  }
  Eigen::Matrix3d plane_axes = svd.matrixU();
  plane_axes.col(2) = plane_axes.col(0).cross(plane_axes.col(1));  // right-handed
  Eigen::Isometry3d plane_from_object = Eigen::Isometry3d::Identity();
  plane_from_object.linear() = plane_axes.transpose();
  plane_from_object.translation() = -plane_axes.transpose() * origin;
  std::vector<Eigen::Vector2d> plane_points;
  for (const auto& p : object) plane_points.push_back((plane_from_object * p).head<2>());

  const auto camera_from_plane = plane_poses(plane_points, rays);
  if (!camera_from_plane) {
    result.rejection = "no homography maps the points onto their pixels";
    return result;
  }
  // IPPE's two poses, best first by their pixel error; the second is refined too only when
  // it is nearly as good (a distant or fronto-parallel plane), since refinement may swap them.
  std::vector<std::pair<double, Eigen::Isometry3d>> starts;
  for (const Eigen::Isometry3d& pose : *camera_from_plane) {
    const Eigen::Isometry3d start = pose * plane_from_object;
    if (auto r0 = residuals(camera, start, object, image)) starts.emplace_back(r0->norm(), start);
  }
  std::sort(starts.begin(), starts.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  Refined best;
  for (size_t s = 0; s < starts.size(); ++s) {
    if (s > 0 && starts[s].first > 3 * starts[0].first + 1.0) break;
    Refined refined = refine(camera, starts[s].second, object, image, options.max_iterations);
    if (refined.refined.valid && (!best.refined.valid || refined.rms < best.rms)) {
      best = refined;
    }
  }
  if (!best.refined.valid) {
    result.rejection = "no pose puts every point in front of the camera";
    return result;
  }
  accept_if_valid(best, options, result);
  return result;
}

PlanarPose refine_planar_pose(const calibration::CameraModel& camera,
                              const Eigen::Isometry3d& start,
                              const std::vector<Eigen::Vector3d>& object_points,
                              const std::vector<Eigen::Vector2d>& pixels,
                              const PlanarPoseOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("PlanarPoseOptions::" + *problem);
  }
  PlanarPose result;
  UsablePoints usable = usable_points(camera, object_points, pixels);
  result.points_used = static_cast<int>(usable.object.size());
  if (!enough_points(options, result)) return result;
  Refined refined = refine(camera, start, usable.object, usable.image, options.max_iterations);
  if (!refined.refined.valid) {
    result.rejection = "no pose near the start puts every point in front of the camera";
    return result;
  }
  accept_if_valid(refined, options, result);
  return result;
}

double rotation_angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  double dot = std::clamp(std::abs(a.normalized().dot(b.normalized())), 0.0, 1.0);
  return 2 * std::acos(dot);  // = acos(2<a,b>^2 - 1), better conditioned near zero
}

}  // namespace mocap::pose
