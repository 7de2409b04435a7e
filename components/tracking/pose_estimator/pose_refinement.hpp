// Levenberg–Marquardt over a rigid pose, for any pixel residuals: one camera's view of a board
// (planar_pose.hpp) or every view of a body in a volume of cameras (pose_fusion.hpp).
// The Jacobian is numeric, as camera models are opaque.
#pragma once

#include <functional>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mocap::pose {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The residuals (pixels) at a pose, or nullopt when some point cannot be imaged there.
using PoseResiduals = std::function<std::optional<Eigen::VectorXd>(const Eigen::Isometry3d&)>;

// `pose` moved by `delta`: a translation (first three) and a rotation vector (last three),
// both in the frame the pose maps into, so that covariances over delta are in that frame.
Eigen::Isometry3d perturbed(const Eigen::Isometry3d& pose, const Vector6d& delta);

struct RefinedPose {
  bool valid = false;  // false: the residuals could not be evaluated along the way
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double squared_error = 0;                 // sum of squared residuals at `pose`
  Matrix6d information = Matrix6d::Zero();  // J^T J at `pose`, over perturbed()'s delta
};

RefinedPose refine_pose(const PoseResiduals& residuals, const Eigen::Isometry3d& start,
                        int max_iterations);

// The pose's covariance over perturbed()'s delta: the residuals' variance per coordinate (with
// the 6 pose parameters taken out of `residual_count`), at least `min_variance`, times the
// inverse information; zero when the information is singular. Residuals already divided by
// their sigmas take min_variance 1: the sigmas are a floor that lucky residuals do not lower.
Matrix6d pose_covariance(const RefinedPose& refined, int residual_count, double min_variance = 0);

}  // namespace mocap::pose
