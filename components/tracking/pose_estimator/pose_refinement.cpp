#include "tracking/pose_estimator/pose_refinement.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace mocap::pose {

Eigen::Isometry3d perturbed(const Eigen::Isometry3d& pose, const Vector6d& delta) {
  Eigen::Isometry3d result = pose;
  const double angle = delta.tail<3>().norm();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  if (angle > 0) rotation = Eigen::AngleAxisd(angle, delta.tail<3>() / angle).toRotationMatrix();
  result.linear() = rotation * pose.linear();
  result.translation() = pose.translation() + delta.head<3>();
  return result;
}

RefinedPose refine_pose(const PoseResiduals& residuals, const Eigen::Isometry3d& start,
                        int max_iterations) {
  RefinedPose out;
  Eigen::Isometry3d pose = start;
  std::optional<Eigen::VectorXd> current = residuals(pose);
  if (!current) return out;
  double cost = current->squaredNorm();
  double lambda = 1e-3;
  Eigen::MatrixXd jacobian(current->size(), 6);
  auto step_size = [&](int k, double scale) {
    return k < 3 ? scale * std::max(1.0, pose.translation().norm()) : scale;
  };
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    // Forward differences while iterating (half the projections); the information below
    // uses central ones.
    for (int k = 0; k < 6; ++k) {
      const double h = step_size(k, 1e-7);
      Vector6d step = Vector6d::Zero();
      step(k) = h;
      std::optional<Eigen::VectorXd> plus = residuals(perturbed(pose, step));
      if (!plus) return out;
      jacobian.col(k) = (*plus - *current) / h;
    }
    const Matrix6d jtj = jacobian.transpose() * jacobian;
    const Vector6d jtr = jacobian.transpose() * *current;
    bool improved = false;
    for (int attempt = 0; attempt < 8 && !improved; ++attempt) {
      Matrix6d damped = jtj;
      damped.diagonal() *= 1 + lambda;
      const Vector6d delta = -damped.ldlt().solve(jtr);
      const Eigen::Isometry3d candidate = perturbed(pose, delta);
      std::optional<Eigen::VectorXd> next = residuals(candidate);
      if (next && next->squaredNorm() < cost) {
        const bool converged = cost - next->squaredNorm() < 1e-8 * (1 + cost);
        pose = candidate;
        current = std::move(next);
        cost = current->squaredNorm();
        lambda = std::max(lambda / 10, 1e-9);
        improved = true;
        if (converged) iteration = max_iterations;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  for (int k = 0; k < 6; ++k) {
    const double h = step_size(k, 1e-6);
    Vector6d step = Vector6d::Zero();
    step(k) = h;
    std::optional<Eigen::VectorXd> plus = residuals(perturbed(pose, step));
    std::optional<Eigen::VectorXd> minus = residuals(perturbed(pose, -step));
    if (!plus || !minus) return out;
    jacobian.col(k) = (*plus - *minus) / (2 * h);
  }
  out.information = jacobian.transpose() * jacobian;
  out.pose = pose;
  out.squared_error = cost;
  out.valid = true;
  return out;
}

Matrix6d pose_covariance(const RefinedPose& refined, int residual_count, double min_variance) {
  const int dof = residual_count - 6;
  const double sigma2 = std::max(min_variance, dof > 0 ? refined.squared_error / dof : 0);
  Eigen::FullPivLU<Matrix6d> lu(refined.information);
  return lu.isInvertible() ? Matrix6d(sigma2 * lu.inverse()) : Matrix6d::Zero();
}

}  // namespace mocap::pose
