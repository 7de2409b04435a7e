#include "plane_homography.hpp"

#include <cmath>

#include <Eigen/Cholesky>
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
  // Points on one line leave no unique plane mapping: the smaller spread of either set,
  // against the larger, tells.
  auto flat = [](const std::vector<Eigen::Vector2d>& points, const Eigen::Matrix3d& t) {
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const auto& p : points) {
      const Eigen::Vector2d q = t.topLeftCorner<2, 2>() * p + t.topRightCorner<2, 1>();
      scatter += q * q.transpose();
    }
    const double trace = scatter.trace(), det = scatter.determinant();
    return !(det > 1e-9 * trace * trace);
  };
  if (flat(from, *tf) || flat(to, *tt)) return std::nullopt;
  // The DLT with h33 = 1, in least squares by the normal equations (8x8). Normalised, the
  // centroid of `from` is the origin and maps to a finite point, so h33 is not zero; this is
  // an order of magnitude faster than the 9x9 eigenproblem of the homogeneous form, and the
  // identifier fits many hypotheses per frame.
  Eigen::Matrix<double, 8, 8> ata = Eigen::Matrix<double, 8, 8>::Zero();
  Eigen::Matrix<double, 8, 1> atb = Eigen::Matrix<double, 8, 1>::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector2d a = tf->topLeftCorner<2, 2>() * from[i] + tf->topRightCorner<2, 1>();
    const Eigen::Vector2d b = tt->topLeftCorner<2, 2>() * to[i] + tt->topRightCorner<2, 1>();
    Eigen::Matrix<double, 8, 1> r1, r2;
    r1 << 0, 0, 0, -a.x(), -a.y(), -1, b.y() * a.x(), b.y() * a.y();
    r2 << a.x(), a.y(), 1, 0, 0, 0, -b.x() * a.x(), -b.x() * a.y();
    ata.noalias() += r1 * r1.transpose() + r2 * r2.transpose();
    atb.noalias() += -b.y() * r1 + b.x() * r2;
  }
  const Eigen::LDLT<Eigen::Matrix<double, 8, 8>> solver(ata);
  if (solver.info() != Eigen::Success) return std::nullopt;
  const Eigen::Matrix<double, 8, 1> h = solver.solve(atb);
  Eigen::Matrix3d hn;
  hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1;
  Eigen::Matrix3d result = tt->inverse() * hn * *tf;
  if (!result.allFinite() || std::abs(result(2, 2)) < 1e-300) return std::nullopt;
  return result / result(2, 2);
}

}  // namespace mocap::constellations
