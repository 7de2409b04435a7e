#include "volume/triangulation/triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include <Eigen/Cholesky>

namespace mocap::volume {
namespace {

struct Ray {
  Eigen::Vector3d origin, direction;  // world frame, direction of unit length
};

std::optional<Ray> ray_of(const CameraDetections& camera, const Eigen::Vector2d& pixel) {
  const std::optional<Eigen::Vector3d> ray = camera.camera->unproject(pixel);
  if (!ray) return std::nullopt;
  const Eigen::Isometry3d world_from_camera = camera.camera_from_world.inverse();
  return Ray{world_from_camera.translation(), (world_from_camera.linear() * *ray).normalized()};
}

// The reprojection residuals of `point` over `seen`, or nullopt when a camera cannot image it.
std::optional<Eigen::VectorXd> residuals(const std::vector<CameraDetections>& cameras,
                                         const std::vector<std::pair<int, int>>& seen,
                                         const Eigen::Vector3d& point) {
  Eigen::VectorXd values(2 * static_cast<Eigen::Index>(seen.size()));
  for (size_t i = 0; i < seen.size(); ++i) {
    const auto& [c, d] = seen[i];
    const Eigen::Vector3d in_camera = cameras[c].camera_from_world * point;
    if (in_camera.z() <= 0) return std::nullopt;
    const auto pixel = cameras[c].camera->project(in_camera);
    if (!pixel) return std::nullopt;
    values.segment<2>(2 * static_cast<Eigen::Index>(i)) = *pixel - cameras[c].pixels[d];
  }
  return values;
}

double rms(const Eigen::VectorXd& values) {
  return std::sqrt(values.squaredNorm() / static_cast<double>(values.size() / 2));
}

// The detection of camera `c` nearest to where `point` projects, within the tolerance, and
// not yet used; -1 if none.
int detection_near(const CameraDetections& camera, const Eigen::Vector3d& point, double tolerance,
                   const std::vector<bool>& used) {
  const Eigen::Vector3d in_camera = camera.camera_from_world * point;
  if (in_camera.z() <= 0) return -1;
  const auto pixel = camera.camera->project(in_camera);
  if (!pixel) return -1;
  int nearest = -1;
  double best = tolerance;
  for (size_t d = 0; d < camera.pixels.size(); ++d) {
    const double distance = (camera.pixels[d] - *pixel).norm();
    if (!used[d] && distance <= best) {
      best = distance;
      nearest = static_cast<int>(d);
    }
  }
  return nearest;
}

// The point nearest every ray: sum over rays of (I - d d^T) (X - o) = 0.
std::optional<Eigen::Vector3d> closest_to_rays(const std::vector<CameraDetections>& cameras,
                                               const std::vector<std::pair<int, int>>& seen) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& [c, d] : seen) {
    const std::optional<Ray> ray = ray_of(cameras[c], cameras[c].pixels[d]);
    if (!ray) return std::nullopt;
    const Eigen::Matrix3d across =
        Eigen::Matrix3d::Identity() - ray->direction * ray->direction.transpose();
    a += across;
    b += across * ray->origin;
  }
  const Eigen::Vector3d point = a.ldlt().solve(b);
  if (!point.allFinite()) return std::nullopt;
  return point;
}

}  // namespace

std::optional<Eigen::Vector3d> triangulate_point(const std::vector<CameraDetections>& cameras,
                                                 const std::vector<std::pair<int, int>>& seen) {
  std::optional<Eigen::Vector3d> start = closest_to_rays(cameras, seen);
  if (!start) return std::nullopt;
  Eigen::Vector3d point = *start;
  // Gauss–Newton on the pixels: the rays' closest point weighs far cameras' pixels less.
  std::optional<Eigen::VectorXd> current = residuals(cameras, seen, point);
  if (!current) return std::nullopt;
  Eigen::MatrixXd jacobian(current->size(), 3);
  for (int iteration = 0; iteration < 5; ++iteration) {
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d step = Eigen::Vector3d::Zero();
      step(k) = 1e-6;
      const std::optional<Eigen::VectorXd> plus = residuals(cameras, seen, point + step);
      if (!plus) return point;
      jacobian.col(k) = (*plus - *current) / 1e-6;
    }
    const Eigen::Vector3d delta =
        -(jacobian.transpose() * jacobian).ldlt().solve(jacobian.transpose() * *current);
    const std::optional<Eigen::VectorXd> next = residuals(cameras, seen, point + delta);
    if (!next || next->squaredNorm() >= current->squaredNorm()) break;
    point += delta;
    current = next;
  }
  return point;
}

std::optional<std::string> MarkerTriangulationOptions::problem() const {
  if (!(tolerance_px > 0)) return fmt::format("tolerance_px: {} is not above 0", tolerance_px);
  if (min_cameras < 2) return fmt::format("min_cameras: {}; two cameras at least", min_cameras);
  return std::nullopt;
}

std::vector<TriangulatedMarker> triangulate_markers(const std::vector<CameraDetections>& cameras,
                                                    const MarkerTriangulationOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("MarkerTriangulationOptions::" + *problem);
  }
  std::vector<std::vector<bool>> none_used;
  for (const CameraDetections& camera : cameras) none_used.emplace_back(camera.pixels.size());
  // Proposals from every pair of cameras, each grown with the other cameras' detections.
  std::vector<TriangulatedMarker> proposals;
  for (size_t i = 0; i < cameras.size(); ++i) {
    for (size_t j = i + 1; j < cameras.size(); ++j) {
      for (size_t a = 0; a < cameras[i].pixels.size(); ++a) {
        for (size_t b = 0; b < cameras[j].pixels.size(); ++b) {
          std::vector<std::pair<int, int>> seen = {{int(i), int(a)}, {int(j), int(b)}};
          // The rays' closest point is cheap, and near enough the best one to refuse most
          // pairs: twice the tolerance.
          const std::optional<Eigen::Vector3d> pair_point = closest_to_rays(cameras, seen);
          if (!pair_point) continue;
          const auto pair_residuals = residuals(cameras, seen, *pair_point);
          if (!pair_residuals || pair_residuals->cwiseAbs().maxCoeff() > 2 * options.tolerance_px) {
            continue;
          }
          for (size_t k = 0; k < cameras.size(); ++k) {
            if (k == i || k == j) continue;
            const int d =
                detection_near(cameras[k], *pair_point, options.tolerance_px, none_used[k]);
            if (d >= 0) seen.emplace_back(int(k), d);
          }
          if (static_cast<int>(seen.size()) < options.min_cameras) continue;
          std::sort(seen.begin(), seen.end());
          const std::optional<Eigen::Vector3d> point = triangulate_point(cameras, seen);
          if (!point) continue;
          const auto final_residuals = residuals(cameras, seen, *point);
          if (!final_residuals) continue;
          proposals.push_back({*point, std::move(seen), rms(*final_residuals)});
        }
      }
    }
  }
  std::sort(proposals.begin(), proposals.end(), [](const auto& x, const auto& y) {
    return x.observations.size() != y.observations.size()
               ? x.observations.size() > y.observations.size()
               : x.rms_px < y.rms_px;
  });
  std::vector<std::vector<bool>> used = none_used;
  std::vector<TriangulatedMarker> markers;
  for (TriangulatedMarker& proposal : proposals) {
    const bool free = std::none_of(proposal.observations.begin(), proposal.observations.end(),
                                   [&](const auto& o) { return used[o.first][o.second]; });
    if (!free || proposal.rms_px > options.tolerance_px) continue;
    for (const auto& [c, d] : proposal.observations) used[c][d] = true;
    markers.push_back(std::move(proposal));
  }
  return markers;
}

}  // namespace mocap::volume
