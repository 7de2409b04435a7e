#include "tracking/pose_estimator/ippe.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "tracking/constellation_database/plane_homography.hpp"

namespace mocap::pose {
namespace {

// The translation that, with `rotation`, best images `plane` at `rays` in the linear sense:
// each point X = R p + t must satisfy X.x - u X.z = 0 and X.y - w X.z = 0, linear in t.
Eigen::Vector3d translation_for(const Eigen::Matrix3d& rotation,
                                std::span<const Eigen::Vector2d> plane,
                                std::span<const Eigen::Vector2d> rays) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d right = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < plane.size(); ++i) {
    const Eigen::Vector3d turned = rotation.leftCols<2>() * plane[i];
    const double u = rays[i].x(), w = rays[i].y();
    const Eigen::Vector3d row_u(1, 0, -u), row_w(0, 1, -w);
    normal.noalias() += row_u * row_u.transpose() + row_w * row_w.transpose();
    right += row_u * (u * turned.z() - turned.x()) + row_w * (w * turned.z() - turned.y());
  }
  return normal.inverse() * right;
}

}  // namespace

std::optional<std::array<Eigen::Isometry3d, 2>> plane_poses(std::span<const Eigen::Vector2d> plane,
                                                            std::span<const Eigen::Vector2d> rays) {
  const std::optional<Eigen::Matrix3d> found = constellations::fit_homography(plane, rays);
  if (!found) return std::nullopt;
  const Eigen::Matrix3d& h = *found;  // h(2, 2) = 1
  // Where the plane's origin is imaged, and the homography's Jacobian there.
  const Eigen::Vector2d v(h(0, 2), h(1, 2));
  Eigen::Matrix2d jacobian;
  jacobian << h(0, 0) - h(2, 0) * h(0, 2), h(0, 1) - h(2, 1) * h(0, 2), h(1, 0) - h(2, 0) * h(1, 2),
      h(1, 1) - h(2, 1) * h(1, 2);

  // With the plane at rotation R and translation t, J = [I | -v] R[:, 0:2] / t.z. A rotation
  // R_v that turns the optical axis onto the ray through v makes [I | -v] R_v = [B | 0], so
  // with R = R_v R', J = B R'[0:2, 0:2] / t.z: the top-left block of the rotation R' is
  // A = B⁻¹ J up to the scale t.z, which makes its largest singular value 1.
  const Eigen::Vector3d ray = Eigen::Vector3d(v.x(), v.y(), 1.0).normalized();
  Eigen::Matrix3d to_ray = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(ray);
  if (axis.norm() > 1e-12) {
    to_ray =
        Eigen::AngleAxisd(std::atan2(axis.norm(), ray.z()), axis.normalized()).toRotationMatrix();
  }
  Eigen::Matrix<double, 2, 3> project_at_v;
  project_at_v << 1, 0, -v.x(), 0, 1, -v.y();
  const Eigen::Matrix2d b = (project_at_v * to_ray).leftCols<2>();
  if (!(std::abs(b.determinant()) > 1e-300)) return std::nullopt;
  const Eigen::Matrix2d a = b.inverse() * jacobian;
  // The largest singular value of a 2x2 matrix in closed form.
  const double frobenius2 = a.squaredNorm(), det = a.determinant();
  const double largest = std::sqrt(
      (frobenius2 + std::sqrt(std::max(0.0, frobenius2 * frobenius2 - 4 * det * det))) / 2);
  if (!(largest > 0) || !std::isfinite(largest)) return std::nullopt;
  const Eigen::Matrix2d block = a / largest;

  // The block's columns, completed to unit length by a third entry each and made orthogonal by
  // its sign: the two completions (±) are the two poses.
  const double first = std::sqrt(std::max(0.0, 1 - block.col(0).squaredNorm()));
  double second = std::sqrt(std::max(0.0, 1 - block.col(1).squaredNorm()));
  if (block.col(0).dot(block.col(1)) > 0) second = -second;
  std::array<Eigen::Isometry3d, 2> poses;
  for (int s = 0; s < 2; ++s) {
    const double sign = s == 0 ? 1.0 : -1.0;
    Eigen::Matrix3d turned;
    turned.col(0) << block(0, 0), block(1, 0), sign * first;
    turned.col(1) << block(0, 1), block(1, 1), sign * second;
    turned.col(2) = turned.col(0).cross(turned.col(1));
    // Noise can leave the completed columns off unit length (a clamped entry): the nearest
    // rotation.
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(to_ray * turned,
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
    if (rotation.determinant() < 0) {
      Eigen::Matrix3d u = svd.matrixU();
      u.col(2) = -u.col(2);
      rotation = u * svd.matrixV().transpose();
    }
    poses[s] = Eigen::Isometry3d::Identity();
    poses[s].linear() = rotation;
    poses[s].translation() = translation_for(poses[s].linear(), plane, rays);
  }
  return poses;
}

}  // namespace mocap::pose
