#include <mocap/calibration/floor_frame.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace mocap::calibration {

Eigen::Isometry3d reference_from_world_of_board(const Eigen::Isometry3d& reference_from_board,
                                                const Eigen::Vector2d& mark) {
  Eigen::Isometry3d reference_from_floor_board = reference_from_board;
  const Eigen::Vector3d camera_in_board = reference_from_board.inverse().translation();
  if (camera_in_board.z() < 0) {
    reference_from_floor_board =
        reference_from_board * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  }
  return reference_from_floor_board *
         Eigen::Translation3d(-mark.x(), -mark.y(), 0);  // board_from_world
}

std::optional<Eigen::Isometry3d> reference_from_world_of_marks(
    const std::vector<Eigen::Vector3d>& centres, const std::vector<Eigen::Vector2d>& marks) {
  if (centres.size() != marks.size() || marks.size() < 3) return std::nullopt;
  const auto n = static_cast<double>(marks.size());
  Eigen::Vector3d centre_mean = Eigen::Vector3d::Zero(), mark_mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < marks.size(); ++i) {
    centre_mean += centres[i] / n;
    mark_mean += Eigen::Vector3d(marks[i].x(), marks[i].y(), 0) / n;
  }
  // Kabsch: the rotation world_from_reference maximising the centres' agreement with the marks.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Matrix2d mark_scatter = Eigen::Matrix2d::Zero();
  for (size_t i = 0; i < marks.size(); ++i) {
    const Eigen::Vector3d mark = Eigen::Vector3d(marks[i].x(), marks[i].y(), 0) - mark_mean;
    covariance += mark * (centres[i] - centre_mean).transpose();
    mark_scatter += mark.head<2>() * mark.head<2>().transpose();
  }
  // Marks in a line leave a turn about that line free: their narrower spread is nil.
  const Eigen::Vector2d spreads =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(mark_scatter).eigenvalues();  // ascending
  if (!(spreads(0) > 1e-6 * spreads(1))) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  sign(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Isometry3d world_from_reference = Eigen::Isometry3d::Identity();
  world_from_reference.linear() = svd.matrixU() * sign * svd.matrixV().transpose();
  world_from_reference.translation() = mark_mean - world_from_reference.linear() * centre_mean;
  // The reference camera looks at the floor from above.
  if (world_from_reference.translation().z() <= 0) return std::nullopt;
  return world_from_reference.inverse();
}

std::vector<Eigen::Isometry3d> cameras_in_world(
    const std::vector<Eigen::Isometry3d>& camera_from_reference,
    const Eigen::Isometry3d& reference_from_world) {
  std::vector<Eigen::Isometry3d> out;
  for (const Eigen::Isometry3d& camera : camera_from_reference) {
    out.push_back(camera * reference_from_world);
  }
  return out;
}

}  // namespace mocap::calibration
