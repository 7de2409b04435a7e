// Finding rigid bodies among a volume's triangulated markers by the distances between their
// markers, and each body's pose from the markers found (rigid_body_database.hpp).
//
// For each body, largest first: every pair of markers whose distance matches one of the body's
// pairs starts a search that adds the body's other markers one by one, each a marker whose
// distances to those already placed all match within the tolerance; a body marker may be
// missing (occluded) as long as `min_markers` are found. The assignment with the most markers,
// then the lowest RMS after the best-fit rigid transform, wins, and its markers are taken: one
// marker belongs to one body.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "volume/rigid_bodies/rigid_body_database.hpp"

namespace mocap::volume {

struct RigidBodyIdentificationOptions {
  // How far a measured inter-marker distance may be from the body's (metres): a few times the
  // triangulation's error.
  double tolerance = 0.004;
  // Fewest of a body's markers that identify it (at least 3, which fix a pose).
  int min_markers = 3;
  // Why these options cannot be used, naming the field ("tolerance_px: 0 is not above 0");
  // nullopt when they can. The functions that take them throw std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct IdentifiedBody {
  std::string name;
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
  // For each of the body's markers, the index of the measured marker it is, or -1 (missing).
  std::vector<int> measured;
  int markers_found = 0;
  double rms_m = 0;  // of the markers found, after the fit
};

// The bodies of `database` found among `markers` (world frame, metres), in database order.
std::vector<IdentifiedBody> identify_rigid_bodies(
    const RigidBodyDatabase& database, const std::vector<Eigen::Vector3d>& markers,
    const RigidBodyIdentificationOptions& options = {});

// The rigid transform (no scale) that best maps `from` onto `to`, point by point, in the least
// squares sense (Kabsch): to ≈ T * from. At least three points not on one line.
Eigen::Isometry3d best_fit_transform(const std::vector<Eigen::Vector3d>& from,
                                     const std::vector<Eigen::Vector3d>& to);
// The RMS distance (metres) between `to` and `from` moved by best_fit_transform, which it
// stores in `fit` when given.
double best_fit_rms(const std::vector<Eigen::Vector3d>& from,
                    const std::vector<Eigen::Vector3d>& to, Eigen::Isometry3d* fit = nullptr);

}  // namespace mocap::volume
