#include "plane_homography.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace mocap::constellations {
namespace {

// Moves the centroid to the origin and scales the mean distance to √2 (Hartley), so the
// linear system is well conditioned in pixels and in metres alike.
std::optional<Eigen::Matrix3d> normalisation(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  double spread = 0;
  for (const auto& p : points) spread += (p - mean).norm();
  spread /= static_cast<double>(points.size());
  if (!(spread > 1e-12)) return std::nullopt;
  double s = std::sqrt(2.0) / spread;
  Eigen::Matrix3d t;
  t << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
  return t;
}

}  // namespace

std::optional<Eigen::Matrix3d> fit_homography(const std::vector<Eigen::Vector2d>& from,
                                              const std::vector<Eigen::Vector2d>& to) {
  if (from.size() < 4 || from.size() != to.size()) return std::nullopt;
  auto tf = normalisation(from);
  auto tt = normalisation(to);
  if (!tf || !tt) return std::nullopt;
  // Normal equations of the 2N x 9 DLT system: the eigenvector of the smallest eigenvalue.
  Eigen::Matrix<double, 9, 9> ata = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    Eigen::Vector3d a = *tf * Eigen::Vector3d(from[i].x(), from[i].y(), 1);
    Eigen::Vector3d b = *tt * Eigen::Vector3d(to[i].x(), to[i].y(), 1);
    Eigen::Matrix<double, 9, 1> r1, r2;
    r1 << 0, 0, 0, -a.x(), -a.y(), -1, b.y() * a.x(), b.y() * a.y(), b.y();
    r2 << a.x(), a.y(), 1, 0, 0, 0, -b.x() * a.x(), -b.x() * a.y(), -b.x();
    ata.noalias() += r1 * r1.transpose() + r2 * r2.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> solver(ata);
  // Collinear input leaves two (near-)zero eigenvalues: no unique plane mapping.
  const auto& values = solver.eigenvalues();
  if (!(values(1) > 1e-9 * values(8))) return std::nullopt;
  Eigen::Matrix<double, 9, 1> h = solver.eigenvectors().col(0);
  Eigen::Matrix3d hn;
  hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Eigen::Matrix3d result = tt->inverse() * hn * *tf;
  if (!result.allFinite() || std::abs(result(2, 2)) < 1e-300) return std::nullopt;
  return result / result(2, 2);
}

}  // namespace mocap::constellations
