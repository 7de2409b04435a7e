#include "volume/rigid_bodies/rigid_body_identification.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include <Eigen/SVD>

namespace mocap::volume {
namespace {

// Steps one body's search may take. Missing markers may be anywhere, so the search is
// exponential in the worst case (many markers of look-alike distances: ghosts of a bad
// triangulation, other bodies' markers): bounded, it gives the best assignment found so far
// rather than hold the frame, and a tracker finds the body in a later frame.
constexpr long kMaxSearchSteps = 200'000;

// Depth-first over the body's markers: each one placed on a free measured marker whose
// distances to those placed before match, or left missing.
class AssignmentSearch {
 public:
  AssignmentSearch(const RigidBody& body, const std::vector<Eigen::Vector3d>& markers,
                   const std::vector<bool>& taken, const RigidBodyIdentificationOptions& options)
      : body_(body),
        markers_(markers),
        taken_(taken),
        options_(options),
        assignment_(body.markers.size(), -1) {}

  // The best assignment found, if any reaches min_markers.
  bool run(IdentifiedBody& out) {
    extend(0, 0);
    if (best_found_ < options_.min_markers) return false;
    out.name = body_.name;
    out.measured = best_assignment_;
    out.markers_found = best_found_;
    out.rms_m = best_rms_;
    out.world_from_body = best_fit_;
    return true;
  }

 private:
  bool compatible(size_t k, int candidate) const {
    for (size_t j = 0; j < k; ++j) {
      if (assignment_[j] < 0) continue;
      if (assignment_[j] == candidate) return false;
      const double expected = (body_.markers[k] - body_.markers[j]).norm();
      const double measured = (markers_[candidate] - markers_[assignment_[j]]).norm();
      if (std::abs(expected - measured) > options_.tolerance) return false;
    }
    return true;
  }

  void extend(size_t k, int found) {
    if (++steps_ > kMaxSearchSteps) return;
    const int left = static_cast<int>(body_.markers.size() - k);
    if (found + left < std::max(best_found_, options_.min_markers)) return;
    if (left == 0) {
      evaluate(found);
      return;
    }
    for (int m = 0; m < static_cast<int>(markers_.size()); ++m) {
      if (taken_[m] || !compatible(k, m)) continue;
      assignment_[k] = m;
      extend(k + 1, found + 1);
      assignment_[k] = -1;
    }
    extend(k + 1, found);  // body marker k missing
  }

  // Distances alone do not tell a body from its mirror image: the fit does.
  void evaluate(int found) {
    std::vector<Eigen::Vector3d> from, to;
    for (size_t k = 0; k < assignment_.size(); ++k) {
      if (assignment_[k] < 0) continue;
      from.push_back(body_.markers[k]);
      to.push_back(markers_[assignment_[k]]);
    }
    Eigen::Isometry3d fit;
    const double rms = best_fit_rms(from, to, &fit);
    if (rms > options_.tolerance) return;
    if (found > best_found_ || rms < best_rms_) {
      best_found_ = found;
      best_rms_ = rms;
      best_assignment_ = assignment_;
      best_fit_ = fit;
    }
  }

  const RigidBody& body_;
  const std::vector<Eigen::Vector3d>& markers_;
  const std::vector<bool>& taken_;
  const RigidBodyIdentificationOptions& options_;
  std::vector<int> assignment_;
  long steps_ = 0;
  int best_found_ = 0;
  double best_rms_ = std::numeric_limits<double>::infinity();
  std::vector<int> best_assignment_;
  Eigen::Isometry3d best_fit_ = Eigen::Isometry3d::Identity();
};

}  // namespace

Eigen::Isometry3d best_fit_transform(const std::vector<Eigen::Vector3d>& from,
                                     const std::vector<Eigen::Vector3d>& to) {
  if (from.size() != to.size() || from.size() < 3) {
    throw std::invalid_argument("best_fit_transform needs three or more point pairs");
  }
  const double n = static_cast<double>(from.size());
  Eigen::Vector3d from_centre = Eigen::Vector3d::Zero(), to_centre = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    from_centre += from[i] / n;
    to_centre += to[i] / n;
  }
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    covariance += (to[i] - to_centre) * (from[i] - from_centre).transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d correction = Eigen::Matrix3d::Identity();
  // A rotation, not a reflection.
  correction(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.linear() = svd.matrixU() * correction * svd.matrixV().transpose();
  transform.translation() = to_centre - transform.linear() * from_centre;
  return transform;
}

double best_fit_rms(const std::vector<Eigen::Vector3d>& from,
                    const std::vector<Eigen::Vector3d>& to, Eigen::Isometry3d* fit) {
  const Eigen::Isometry3d transform = best_fit_transform(from, to);
  double sum = 0;
  for (size_t i = 0; i < from.size(); ++i) sum += (transform * from[i] - to[i]).squaredNorm();
  if (fit != nullptr) *fit = transform;
  return std::sqrt(sum / static_cast<double>(from.size()));
}

std::optional<std::string> RigidBodyIdentificationOptions::problem() const {
  if (!(tolerance > 0)) return fmt::format("tolerance: {} m is not above 0", tolerance);
  if (min_markers < 3) {
    return fmt::format("min_markers: {}; three markers at least fix a body", min_markers);
  }
  return std::nullopt;
}

std::vector<IdentifiedBody> identify_rigid_bodies(const RigidBodyDatabase& database,
                                                  const std::vector<Eigen::Vector3d>& markers,
                                                  const RigidBodyIdentificationOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("RigidBodyIdentificationOptions::" + *problem);
  }
  // Larger bodies first: a smaller one must not take markers of a larger one.
  std::vector<size_t> order(database.bodies.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return database.bodies[a].markers.size() > database.bodies[b].markers.size();
  });
  std::vector<bool> taken(markers.size(), false);
  std::vector<std::pair<size_t, IdentifiedBody>> found;
  for (size_t index : order) {
    IdentifiedBody body;
    if (!AssignmentSearch(database.bodies[index], markers, taken, options).run(body)) continue;
    for (int m : body.measured) {
      if (m >= 0) taken[m] = true;
    }
    found.emplace_back(index, std::move(body));
  }
  std::sort(found.begin(), found.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<IdentifiedBody> out;
  for (auto& [index, body] : found) out.push_back(std::move(body));
  return out;
}

}  // namespace mocap::volume
