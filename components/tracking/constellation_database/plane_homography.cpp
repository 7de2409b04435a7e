#include "tracking/constellation_database/plane_homography.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace mocap::constellations {
namespace {

// Moves the centroid to the origin and scales the mean distance to √2 (Hartley), so the
// linear system is well conditioned in pixels and in metres alike.
std::optional<Eigen::Matrix3d> normalisation(std::span<const Eigen::Vector2d> points) {
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

std::optional<Eigen::Matrix3d> fit_homography(std::span<const Eigen::Vector2d> from,
                                              std::span<const Eigen::Vector2d> to) {
  if (from.size() < 4 || from.size() != to.size()) return std::nullopt;
  auto tf = normalisation(from);
  auto tt = normalisation(to);
  if (!tf || !tt) return std::nullopt;
  // Points on one line leave no unique plane mapping: the smaller spread of either set,
  // against the larger, tells.
  auto flat = [](std::span<const Eigen::Vector2d> points, const Eigen::Matrix3d& t) {
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
  // identifier fits many hypotheses per frame. Each pair gives the rows
  //   r1 = [0, -a, b.y p],  r2 = [a, 0, -b.x p]   (a = (p, 1), p = the normalised `from`),
  // so AᵀA and Aᵀb come from a handful of sums instead of two 8x8 outer products a pair.
  Eigen::Matrix3d sum_aa = Eigen::Matrix3d::Zero();
  Eigen::Matrix2d sum_pp = Eigen::Matrix2d::Zero();  // weighted by |b|²
  Eigen::Matrix<double, 3, 2> sum_bx_ap = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix<double, 3, 2> sum_by_ap = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Vector3d sum_bx_a = Eigen::Vector3d::Zero(), sum_by_a = Eigen::Vector3d::Zero();
  Eigen::Vector2d sum_bb_p = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector2d p = tf->topLeftCorner<2, 2>() * from[i] + tf->topRightCorner<2, 1>();
    const Eigen::Vector2d b = tt->topLeftCorner<2, 2>() * to[i] + tt->topRightCorner<2, 1>();
    const Eigen::Vector3d a(p.x(), p.y(), 1.0);
    const double bb = b.squaredNorm();
    sum_aa.noalias() += a * a.transpose();
    sum_pp.noalias() += bb * p * p.transpose();
    sum_bx_ap.noalias() += b.x() * a * p.transpose();
    sum_by_ap.noalias() += b.y() * a * p.transpose();
    sum_bx_a += b.x() * a;
    sum_by_a += b.y() * a;
    sum_bb_p += bb * p;
  }
  Eigen::Matrix<double, 8, 8> ata = Eigen::Matrix<double, 8, 8>::Zero();
  ata.block<3, 3>(0, 0) = sum_aa;
  ata.block<3, 3>(3, 3) = sum_aa;
  ata.block<2, 2>(6, 6) = sum_pp;
  ata.block<3, 2>(0, 6) = -sum_bx_ap;
  ata.block<3, 2>(3, 6) = -sum_by_ap;
  ata.block<2, 3>(6, 0) = -sum_bx_ap.transpose();
  ata.block<2, 3>(6, 3) = -sum_by_ap.transpose();
  Eigen::Matrix<double, 8, 1> atb;
  atb << sum_bx_a, sum_by_a, -sum_bb_p;
  const Eigen::LDLT<Eigen::Matrix<double, 8, 8>, Eigen::Lower> solver(ata);
  if (solver.info() != Eigen::Success) return std::nullopt;
  const Eigen::Matrix<double, 8, 1> h = solver.solve(atb);
  Eigen::Matrix3d hn;
  hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1;
  Eigen::Matrix3d result = tt->inverse() * hn * *tf;
  if (!result.allFinite() || std::abs(result(2, 2)) < 1e-300) return std::nullopt;
  return result / result(2, 2);
}

}  // namespace mocap::constellations
