#include "planar_pose.hpp"

#include <algorithm>
#include <cmath>

#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>

namespace mocap::pose {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Applies a small motion (translation, rotation vector in the camera frame) to a pose.
Eigen::Isometry3d perturbed(const Eigen::Isometry3d& pose, const Vector6d& delta) {
  Eigen::Isometry3d result = pose;
  double angle = delta.tail<3>().norm();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  if (angle > 0) rotation = Eigen::AngleAxisd(angle, delta.tail<3>() / angle).toRotationMatrix();
  result.linear() = rotation * pose.linear();
  result.translation() = pose.translation() + delta.head<3>();
  return result;
}

struct Residuals {
  Eigen::VectorXd values;
  bool valid = true;
};

Residuals residuals(const calibration::CameraModel& camera, const Eigen::Isometry3d& pose,
                    const std::vector<Eigen::Vector3d>& object,
                    const std::vector<Eigen::Vector2d>& pixels) {
  Residuals r;
  r.values.resize(2 * static_cast<Eigen::Index>(object.size()));
  for (size_t i = 0; i < object.size(); ++i) {
    auto projected = camera.project(pose * object[i]);
    if (!projected) {
      r.valid = false;
      return r;
    }
    r.values.segment<2>(2 * static_cast<Eigen::Index>(i)) = *projected - pixels[i];
  }
  return r;
}

struct Refined {
  Eigen::Isometry3d pose;
  double rms = 0;
  Matrix6d information = Matrix6d::Zero();  // J^T J at the solution
  bool valid = false;
};

// Levenberg–Marquardt on the pixel residuals, numeric Jacobian (the camera model is opaque).
Refined refine(const calibration::CameraModel& camera, Eigen::Isometry3d pose,
               const std::vector<Eigen::Vector3d>& object,
               const std::vector<Eigen::Vector2d>& pixels, int max_iterations) {
  Refined out;
  Residuals current = residuals(camera, pose, object, pixels);
  if (!current.valid) return out;
  double cost = current.values.squaredNorm();
  double lambda = 1e-3;
  Eigen::MatrixXd jacobian(current.values.size(), 6);
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    // Forward differences while iterating (half the projections); the covariance below
    // uses central ones.
    for (int k = 0; k < 6; ++k) {
      double h = k < 3 ? 1e-7 * std::max(1.0, pose.translation().norm()) : 1e-7;
      Vector6d step = Vector6d::Zero();
      step(k) = h;
      Residuals plus = residuals(camera, perturbed(pose, step), object, pixels);
      if (!plus.valid) return out;
      jacobian.col(k) = (plus.values - current.values) / h;
    }
    Matrix6d jtj = jacobian.transpose() * jacobian;
    Vector6d jtr = jacobian.transpose() * current.values;
    bool improved = false;
    for (int attempt = 0; attempt < 8 && !improved; ++attempt) {
      Matrix6d damped = jtj;
      damped.diagonal() *= 1 + lambda;
      Vector6d delta = -damped.ldlt().solve(jtr);
      Eigen::Isometry3d candidate = perturbed(pose, delta);
      Residuals next = residuals(camera, candidate, object, pixels);
      if (next.valid && next.values.squaredNorm() < cost) {
        bool converged = cost - next.values.squaredNorm() < 1e-8 * (1 + cost);
        pose = candidate;
        current = next;
        cost = next.values.squaredNorm();
        lambda = std::max(lambda / 10, 1e-9);
        improved = true;
        if (converged) iteration = max_iterations;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  // The information matrix at the final pose, for the covariance.
  for (int k = 0; k < 6; ++k) {
    double h = k < 3 ? 1e-6 * std::max(1.0, pose.translation().norm()) : 1e-6;
    Vector6d step = Vector6d::Zero();
    step(k) = h;
    Residuals plus = residuals(camera, perturbed(pose, step), object, pixels);
    Residuals minus = residuals(camera, perturbed(pose, -step), object, pixels);
    if (!plus.valid || !minus.valid) return out;
    jacobian.col(k) = (plus.values - minus.values) / (2 * h);
  }
  out.information = jacobian.transpose() * jacobian;
  out.pose = pose;
  out.rms = std::sqrt(cost / static_cast<double>(object.size()));
  out.valid = true;
  return out;
}

// The pairs the camera can use: finite, and seen by a pixel the model can unproject.
struct UsablePoints {
  std::vector<Eigen::Vector3d> object;
  std::vector<Eigen::Vector2d> image;
  std::vector<cv::Point2d> rays;
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
    usable.rays.emplace_back(ray->x(), ray->y());
  }
  return usable;
}

bool enough_points(const PlanarPoseOptions& options, PlanarPose& result) {
  if (options.min_points < 4) {
    throw std::invalid_argument(
        fmt::format("PlanarPoseOptions::min_points is {}: four points at least fix a pose",
                    options.min_points));
  }
  if (result.points_used >= options.min_points) return true;
  result.rejection =
      fmt::format("{} usable points, {} needed", result.points_used, options.min_points);
  return false;
}

// The refined pose as the result: its covariance and the checks that reject it.
void accept_if_valid(const Refined& best, const PlanarPoseOptions& options, PlanarPose& result) {
  result.camera_from_object = best.pose;
  result.reprojection_rms_px = best.rms;
  // Residual variance per coordinate, with the 6 pose parameters taken out.
  int dof = 2 * result.points_used - 6;
  double sigma2 = dof > 0 ? best.rms * best.rms * result.points_used / dof : 0;
  Eigen::FullPivLU<Matrix6d> lu(best.information);
  if (lu.isInvertible()) result.covariance = sigma2 * lu.inverse();
  if (best.pose.translation().z() <= 0) {
    result.rejection = "the pose puts the object behind the camera";
  } else if (best.rms > options.max_reprojection_rms_px) {
    result.rejection = fmt::format("reprojection RMS {:.2f} px exceeds {:.2f} px", best.rms,
                                   options.max_reprojection_rms_px);
  } else {
    result.valid = true;
  }
}

}  // namespace

PlanarPose estimate_planar_pose(const calibration::CameraModel& camera,
                                const std::vector<Eigen::Vector3d>& object_points,
                                const std::vector<Eigen::Vector2d>& pixels,
                                const PlanarPoseOptions& options) {
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
  std::vector<cv::Point3d> plane_points;
  for (const auto& p : object) {
    Eigen::Vector3d q = plane_from_object * p;
    plane_points.emplace_back(q.x(), q.y(), 0.0);
  }

  std::vector<cv::Mat> rotations, translations;
  try {
    cv::solvePnPGeneric(plane_points, rays, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rotations,
                        translations, false, cv::SOLVEPNP_IPPE);
  } catch (const cv::Exception& e) {
    result.rejection = fmt::format("IPPE failed: {}", e.what());
    return result;
  }
  // IPPE's two poses, best first by their pixel error; the second is refined too only when
  // it is nearly as good (a distant or fronto-parallel plane), since refinement may swap them.
  std::vector<std::pair<double, Eigen::Isometry3d>> starts;
  for (size_t s = 0; s < rotations.size(); ++s) {
    cv::Mat r;
    cv::Rodrigues(rotations[s], r);
    Eigen::Isometry3d camera_from_plane = Eigen::Isometry3d::Identity();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) camera_from_plane.linear()(i, j) = r.at<double>(i, j);
      camera_from_plane.translation()(i) = translations[s].at<double>(i);
    }
    Eigen::Isometry3d start = camera_from_plane * plane_from_object;
    Residuals r0 = residuals(camera, start, object, image);
    if (r0.valid) starts.emplace_back(r0.values.norm(), start);
  }
  std::sort(starts.begin(), starts.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  Refined best;
  for (size_t s = 0; s < starts.size(); ++s) {
    if (s > 0 && starts[s].first > 3 * starts[0].first + 1.0) break;
    Refined refined = refine(camera, starts[s].second, object, image, options.max_iterations);
    if (refined.valid && (!best.valid || refined.rms < best.rms)) best = refined;
  }
  if (!best.valid) {
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
  PlanarPose result;
  UsablePoints usable = usable_points(camera, object_points, pixels);
  result.points_used = static_cast<int>(usable.object.size());
  if (!enough_points(options, result)) return result;
  Refined refined = refine(camera, start, usable.object, usable.image, options.max_iterations);
  if (!refined.valid) {
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
