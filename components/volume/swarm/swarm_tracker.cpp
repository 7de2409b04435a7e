#include "volume/swarm/swarm_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "common/min_cost_assignment/min_cost_assignment.hpp"
#include "volume/rigid_bodies/rigid_body_identification.hpp"

namespace mocap::volume {
namespace {

// A robot is found upright (tilted less than this) where the markers found allow it turned: a
// swarm starts on the ground or hovering.
constexpr double kMostTiltAtStart_rad = 0.7854;  // 45 degrees
// A robot not looked for by its track costs this many times its search radius squared when it
// is left without what was found: any find within the radius is taken before none.
constexpr double kUnfoundCostFactor = 4;
// The most instances of a layout looked for around one robot: two identical robots side by
// side, and a third.
constexpr int kMostInstancesPerSearch = 3;
// A marker measured this many times less precisely than the median of its robot's is left
// out: a blob merged with another in one camera's image is triangulated millimetres off, which
// a fit of three markers would turn into degrees.
constexpr double kPoorMarkerFactor = 5;
// A tracked robot's gate reaches this many sigmas of the position its motion model's
// acceleration noise allows since its last measurement.
constexpr double kGateSigmas = 3;

// Cloud markers by grid cell, for the markers near a point without looking at all of them.
class PointGrid {
 public:
  PointGrid(const std::vector<CloudMarker>& cloud, double cell_m)
      : cloud_(&cloud), cell_m_(cell_m) {
    cells_.reserve(cloud.size());
    for (size_t i = 0; i < cloud.size(); ++i) {
      cells_.emplace_back(key(cell_of(cloud[i].position)), static_cast<int>(i));
    }
    std::sort(cells_.begin(), cells_.end());
  }

  // Calls visit(index, squared distance) for each marker within `radius_m` of `at`.
  template <class Visit>
  void near(const Eigen::Vector3d& at, double radius_m, Visit visit) const {
    const Eigen::Vector3<int64_t> cell = cell_of(at);
    const auto span = static_cast<int64_t>(std::ceil(radius_m / cell_m_));
    const double limit = radius_m * radius_m;
    for (int64_t z = cell.z() - span; z <= cell.z() + span; ++z) {
      for (int64_t y = cell.y() - span; y <= cell.y() + span; ++y) {
        const int64_t first = key({cell.x() - span, y, z}), last = key({cell.x() + span, y, z});
        for (auto it = std::lower_bound(cells_.begin(), cells_.end(), std::make_pair(first, -1));
             it != cells_.end() && it->first <= last; ++it) {
          const double squared = ((*cloud_)[it->second].position - at).squaredNorm();
          if (squared <= limit) visit(it->second, squared);
        }
      }
    }
  }

 private:
  static constexpr int64_t kSpan = int64_t{1} << 20;
  Eigen::Vector3<int64_t> cell_of(const Eigen::Vector3d& point) const {
    Eigen::Vector3<int64_t> cell;
    for (int i = 0; i < 3; ++i) {
      cell[i] = static_cast<int64_t>(
                    std::clamp(std::floor(point[i] / cell_m_), -kSpan / 4.0, kSpan / 4.0)) +
                kSpan / 2;
    }
    return cell;
  }
  static int64_t key(const Eigen::Vector3<int64_t>& cell) {
    return (cell.z() * kSpan + cell.y()) * kSpan + cell.x();
  }

  const std::vector<CloudMarker>* cloud_;
  double cell_m_;
  std::vector<std::pair<int64_t, int>> cells_;  // (cell key, marker), sorted
};

// A marker's sigma (metres): the mean of its covariance's axes.
double sigma_of(const CloudMarker& marker) { return std::sqrt(marker.covariance.trace() / 3); }

// The relabellings of the markers `subset` of `layout` that a rotation maps onto themselves,
// within `tolerance_m` (the fit's RMS), the identity among them: three markers of a nearly
// isosceles triangle have two, the second turned half a turn about the triangle's axis. Each
// relabelling says, per marker of `subset`, the marker of `subset` it is taken for. Searches
// the relabellings that keep every distance within twice the tolerance.
std::vector<std::vector<size_t>> relabellings(const std::vector<Eigen::Vector3d>& layout,
                                              const std::vector<int>& subset, double tolerance_m) {
  const size_t k = subset.size();
  std::vector<std::vector<size_t>> found;
  std::vector<size_t> image(k);
  std::vector<char> taken(k, 0);
  const auto at = [&](size_t i) { return layout[static_cast<size_t>(subset[i])]; };
  const std::function<void(size_t)> extend = [&](size_t i) {
    if (i == k) {
      std::vector<Eigen::Vector3d> from, to;
      for (size_t j = 0; j < k; ++j) {
        from.push_back(at(j));
        to.push_back(at(image[j]));
      }
      if (best_fit_rms(from, to) <= tolerance_m) found.push_back(image);
      return;
    }
    for (size_t c = 0; c < k; ++c) {
      if (taken[c]) continue;
      bool keeps = true;
      for (size_t j = 0; j < i && keeps; ++j) {
        keeps = std::abs((at(i) - at(j)).norm() - (at(c) - at(image[j])).norm()) <= 2 * tolerance_m;
      }
      if (!keeps) continue;
      taken[c] = 1;
      image[i] = c;
      extend(i + 1);
      taken[c] = 0;
    }
  };
  if (k >= 3) extend(0);
  return found;
}

}  // namespace

std::optional<std::string> SwarmTrackerOptions::problem() const {
  if (!(gate_m > 0)) return fmt::format("gate_m: {} is not above 0", gate_m);
  if (!(layout_tolerance_m > 0))
    return fmt::format("layout_tolerance_m: {} is not above 0", layout_tolerance_m);
  if (!(max_fit_sigmas > 0))
    return fmt::format("max_fit_sigmas: {} is not above 0", max_fit_sigmas);
  if (min_markers < 3) return fmt::format("min_markers: {} is below 3", min_markers);
  if (!(start_radius_m > 0))
    return fmt::format("start_radius_m: {} is not above 0", start_radius_m);
  if (!(start_speed_mps > 0))
    return fmt::format("start_speed_mps: {} is not above 0", start_speed_mps);
  if (!(lost_after_s >= 0)) return fmt::format("lost_after_s: {} is below 0", lost_after_s);
  if (!(max_search_radius_m >= start_radius_m)) {
    return fmt::format("max_search_radius_m: {} is below start_radius_m ({})", max_search_radius_m,
                       start_radius_m);
  }
  if (auto problem = motion.problem()) return "motion." + *problem;
  return std::nullopt;
}

SwarmTracker::SwarmTracker(SwarmDatabase swarm, SwarmTrackerOptions options)
    : swarm_(std::move(swarm)), options_(options), robots_(swarm_.robots.size()) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("SwarmTrackerOptions::" + *problem);
  }
  for (size_t r = 0; r < robots_.size(); ++r) {
    if (swarm_.robots[r].layout >= swarm_.layouts.size()) {
      throw std::invalid_argument("robot '" + swarm_.robots[r].name + "' has no layout");
    }
    robots_[r].anchor = swarm_.robots[r].initial_position;
  }
}

bool SwarmTracker::reseed(const std::string& name, const Eigen::Vector3d& position) {
  for (size_t r = 0; r < robots_.size(); ++r) {
    if (swarm_.robots[r].name != name) continue;
    Robot& robot = robots_[r];
    robot.forget();
    robot.missed_since_ns.reset();
    robot.anchor = position;
    robot.lost_since_ns.reset();
    return true;
  }
  return false;
}

std::optional<SwarmTracker::Found> SwarmTracker::upright_fit(
    size_t layout, const std::vector<int>& markers, const std::vector<CloudMarker>& cloud) {
  std::vector<int> subset;
  for (size_t k = 0; k < markers.size(); ++k) {
    if (markers[k] >= 0) subset.push_back(static_cast<int>(k));
  }
  auto key = std::make_pair(layout, subset);
  auto known = relabellings_.find(key);
  if (known == relabellings_.end()) {
    known = relabellings_
                .emplace(std::move(key), relabellings(swarm_.layouts[layout].markers, subset,
                                                      options_.layout_tolerance_m))
                .first;
  }
  if (known->second.size() <= 1) return fit(layout, markers, cloud);
  // Each relabelling's pose: the cloud marker taken for subset[j] is taken for subset[p[j]].
  const double upright = std::cos(kMostTiltAtStart_rad);
  std::optional<Found> chosen;
  int upright_count = 0;
  for (const std::vector<size_t>& p : known->second) {
    std::vector<int> relabelled(markers.size(), -1);
    for (size_t j = 0; j < subset.size(); ++j) {
      relabelled[static_cast<size_t>(subset[p[j]])] = markers[static_cast<size_t>(subset[j])];
    }
    std::optional<Found> found = fit(layout, std::move(relabelled), cloud);
    if (!found || found->world_from_body.linear()(2, 2) < upright) continue;
    ++upright_count;
    chosen = std::move(found);
  }
  if (upright_count != 1) return std::nullopt;
  return chosen;
}

SwarmTracker::Search SwarmTracker::search(const Robot& robot, size_t layout,
                                          int64_t stamp_ns) const {
  if (!robot.lost_since_ns) return {robot.anchor, options_.start_radius_m, true};
  const double top_speed = swarm_.layouts[layout].top_speed_mps;
  // The radius grows until it reaches its cap; the centre moves on with the robot's last
  // velocity as long.
  const double lost_s =
      std::min(static_cast<double>(stamp_ns - *robot.lost_since_ns) * 1e-9,
               (options_.max_search_radius_m - options_.start_radius_m) / top_speed);
  return {robot.anchor + robot.lost_velocity * lost_s, options_.start_radius_m + top_speed * lost_s,
          false};
}

std::optional<SwarmTracker::Found> SwarmTracker::fit(size_t layout, std::vector<int> markers,
                                                     const std::vector<CloudMarker>& cloud) const {
  const std::vector<Eigen::Vector3d>& model = swarm_.layouts[layout].markers;
  Found found;
  if (model.size() == 1) {
    if (markers[0] < 0) return std::nullopt;
    const CloudMarker& marker = cloud[markers[0]];
    found.world_from_body.translation() = marker.position - model[0];
    found.covariance.topLeftCorner<3, 3>() = marker.covariance;
    found.covariance.bottomRightCorner<3, 3>() =
        Eigen::Matrix3d::Identity() * kUnknownOrientationVariance;
    found.markers = std::move(markers);
    return found;
  }
  const int needed = std::min(options_.min_markers, static_cast<int>(model.size()));
  {
    std::vector<double> sigmas;
    for (int m : markers) {
      if (m >= 0) sigmas.push_back(sigma_of(cloud[m]));
    }
    if (sigmas.empty()) return std::nullopt;
    std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
    const double median = sigmas[sigmas.size() / 2];
    for (int& m : markers) {
      if (m >= 0 && sigma_of(cloud[m]) > kPoorMarkerFactor * median) m = -1;
    }
  }
  // The layout fitted to the markers given, and the furthest off of them in its own sigmas.
  auto fitted = [&](const std::vector<int>& given, Eigen::Isometry3d& pose, double& rms_m) {
    std::vector<Eigen::Vector3d> from, to;
    for (size_t k = 0; k < given.size(); ++k) {
      if (given[k] < 0) continue;
      from.push_back(model[k]);
      to.push_back(cloud[given[k]].position);
    }
    if (static_cast<int>(from.size()) < needed) return std::numeric_limits<double>::infinity();
    rms_m = best_fit_rms(from, to, &pose);
    double worst = 0;
    for (size_t k = 0; k < given.size(); ++k) {
      if (given[k] < 0) continue;
      const CloudMarker& marker = cloud[given[k]];
      worst = std::max(worst, (pose * model[k] - marker.position).norm() / sigma_of(marker));
    }
    return worst;
  };
  double worst = fitted(markers, found.world_from_body, found.rms_m);
  // One marker that is not the robot's bends a fit of four so that another may look the worst:
  // the marker whose leaving out fits the rest best goes, one at a time.
  while (std::isfinite(worst) && worst > options_.max_fit_sigmas) {
    size_t best = markers.size();
    double best_worst = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < markers.size(); ++k) {
      if (markers[k] < 0) continue;
      std::vector<int> fewer = markers;
      fewer[k] = -1;
      Eigen::Isometry3d pose;
      double rms_m = 0;
      const double without = fitted(fewer, pose, rms_m);
      if (without < best_worst) {
        best_worst = without;
        best = k;
      }
    }
    if (best == markers.size()) return std::nullopt;
    markers[best] = -1;
    worst = fitted(markers, found.world_from_body, found.rms_m);
  }
  if (!std::isfinite(worst)) return std::nullopt;
  {
    std::vector<Eigen::Vector3d> to;
    std::vector<double> variances;
    for (int m : markers) {
      if (m < 0) continue;
      to.push_back(cloud[m].position);
      variances.push_back(cloud[m].covariance.trace() / 3);
    }
    // The markers' own variances: the position is their mean's, the orientation's information
    // their spread about the centre (a rigid body's inertia), in the world frame.
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& point : to) centre += point;
    centre /= static_cast<double>(to.size());
    Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
    double variance = 0;
    for (size_t i = 0; i < to.size(); ++i) {
      variance += variances[i];
      const Eigen::Vector3d arm = to[i] - centre;
      spread += arm.squaredNorm() * Eigen::Matrix3d::Identity() - arm * arm.transpose();
    }
    variance /= static_cast<double>(to.size());
    found.covariance.setZero();
    found.covariance.topLeftCorner<3, 3>() =
        Eigen::Matrix3d::Identity() * variance / static_cast<double>(to.size());
    found.covariance.bottomRightCorner<3, 3>() = variance * spread.inverse();
  }
  found.markers = std::move(markers);
  return found;
}

std::vector<SwarmRobotPose> SwarmTracker::track(int64_t stamp_ns,
                                                const std::vector<CloudMarker>& cloud,
                                                const std::vector<char>& claimed) {
  if (!claimed.empty() && claimed.size() != cloud.size()) {
    throw std::invalid_argument("SwarmTracker::track: `claimed` needs one entry per marker");
  }
  counts_ = {};
  std::vector<char> used = claimed.empty() ? std::vector<char>(cloud.size(), 0) : claimed;
  std::vector<std::optional<SwarmRobotPose>> poses(robots_.size());

  // 1. Tracked robots, all at once.
  const PointGrid grid(cloud, options_.gate_m);
  std::vector<AllowedPair> allowed;
  std::vector<double> unassigned;
  std::vector<size_t> rows;  // each tracked robot's markers, robot by robot: the robot
  const int64_t lost_after_ns = std::llround(options_.lost_after_s * 1e9);
  for (size_t r = 0; r < robots_.size(); ++r) {
    Robot& robot = robots_[r];
    if (!robot.tracked()) continue;
    if (robot.missed_since_ns && stamp_ns - *robot.missed_since_ns > lost_after_ns) {
      robot.anchor = robot.body ? robot.body->state().camera_from_body.translation()
                                : robot.point->state().position;
      robot.lost_velocity =
          robot.body ? robot.body->state().linear_velocity : robot.point->state().velocity;
      robot.lost_since_ns = robot.stamp_ns;
      robot.missed_since_ns.reset();
      robot.forget();
      continue;
    }
    Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
    if (robot.body) {
      start = robot.body->predicted_pose(stamp_ns);
    } else {
      start.translation() = robot.point->predicted_position(stamp_ns);
    }
    // The position's variance a white-noise acceleration of density q adds over dt: q dt³ / 3.
    const double dt_s = static_cast<double>(stamp_ns - robot.stamp_ns) * 1e-9;
    const double gate_m = std::max(
        options_.gate_m, kGateSigmas * std::sqrt(options_.motion.linear_acceleration_density *
                                                 dt_s * dt_s * dt_s / 3));
    for (const Eigen::Vector3d& marker : swarm_.layouts[swarm_.robots[r].layout].markers) {
      const int row = static_cast<int>(rows.size());
      grid.near(start * marker, gate_m, [&](int m, double squared) {
        if (!used[m]) allowed.push_back({row, m, squared});
      });
      rows.push_back(r);
      unassigned.push_back(gate_m * gate_m);
    }
  }
  const std::vector<int> assigned = min_cost_assignment(
      static_cast<int>(rows.size()), static_cast<int>(cloud.size()), allowed, unassigned);
  for (size_t first = 0; first < rows.size();) {
    const size_t r = rows[first];
    const size_t count = swarm_.layouts[swarm_.robots[r].layout].markers.size();
    std::vector<int> markers(assigned.begin() + static_cast<long>(first),
                             assigned.begin() + static_cast<long>(first + count));
    first += count;
    if (auto found = fit(swarm_.robots[r].layout, std::move(markers), cloud)) {
      for (int m : found->markers) {
        if (m >= 0) used[m] = 1;
      }
      poses[r] = posed(r, stamp_ns, *found, false);
      ++counts_.tracked;
    } else if (!robots_[r].missed_since_ns) {
      robots_[r].missed_since_ns = stamp_ns;
    }
  }

  // 2. Robots to find, among the markers no robot took: layouts of several markers first.
  for (const bool several : {true, false}) {
    std::vector<size_t> searching;
    for (size_t r = 0; r < robots_.size(); ++r) {
      const bool has_several = swarm_.layouts[swarm_.robots[r].layout].markers.size() > 1;
      if (!robots_[r].tracked() && has_several == several) searching.push_back(r);
    }
    if (searching.empty()) continue;
    std::vector<Found> finds;
    std::vector<size_t> find_layouts;
    allowed.clear();
    unassigned.clear();
    std::vector<Search> searches;
    for (size_t r : searching)
      searches.push_back(search(robots_[r], swarm_.robots[r].layout, stamp_ns));
    for (size_t row = 0; row < searching.size(); ++row) {
      const size_t r = searching[row];
      const size_t layout = swarm_.robots[r].layout;
      const Search& where = searches[row];
      const double radius = where.radius_m;
      unassigned.push_back(kUnfoundCostFactor * radius * radius);
      std::vector<int> candidates;
      for (size_t m = 0; m < cloud.size(); ++m) {
        const CloudMarker& marker = cloud[m];
        if (used[m] || (marker.position - where.centre).norm() > radius) continue;
        if (where.at_rest && marker.velocity_known &&
            marker.velocity.norm() > options_.start_speed_mps) {
          continue;
        }
        candidates.push_back(static_cast<int>(m));
      }
      std::vector<Found> around;
      if (!several) {
        for (int m : candidates) around.push_back(*fit(layout, {m}, cloud));
      } else {
        RigidBodyDatabase one{
            {RigidBody{swarm_.layouts[layout].name, swarm_.layouts[layout].markers}}};
        const RigidBodyIdentificationOptions identification{options_.layout_tolerance_m,
                                                            options_.min_markers};
        // The instances nearest the centre first: the layout looked for among the nearest
        // markers, twice as many each time, until one is found (a search grown over a grid of
        // robots finds the robot itself before its neighbours).
        std::sort(candidates.begin(), candidates.end(), [&](int a, int b) {
          return (cloud[a].position - where.centre).squaredNorm() <
                 (cloud[b].position - where.centre).squaredNorm();
        });
        const size_t first_window = swarm_.layouts[layout].markers.size() + 2;
        for (int instance = 0; instance < kMostInstancesPerSearch; ++instance) {
          std::vector<IdentifiedBody> identified;
          for (size_t window = std::min(first_window, candidates.size());;
               window = std::min(2 * window, candidates.size())) {
            std::vector<Eigen::Vector3d> positions;
            for (size_t k = 0; k < window; ++k) positions.push_back(cloud[candidates[k]].position);
            identified = identify_rigid_bodies(one, positions, identification);
            if (!identified.empty() || window == candidates.size()) break;
          }
          if (identified.empty()) break;
          std::vector<int> markers;
          for (int measured : identified[0].measured) {
            markers.push_back(measured < 0 ? -1 : candidates[measured]);
          }
          std::vector<int> rest;
          for (int m : candidates) {
            if (std::find(markers.begin(), markers.end(), m) == markers.end()) rest.push_back(m);
          }
          candidates = std::move(rest);
          if (auto found = upright_fit(layout, markers, cloud)) around.push_back(*found);
        }
      }
      for (Found& found : around) {
        const double off = (found.world_from_body.translation() - where.centre).norm();
        if (off > radius) continue;
        // One find seen from two robots' searches is one column.
        auto same = std::find_if(finds.begin(), finds.end(), [&](const Found& other) {
          return other.markers == found.markers;
        });
        const int column = static_cast<int>(same - finds.begin());
        if (same == finds.end()) {
          finds.push_back(std::move(found));
          find_layouts.push_back(layout);
        }
        allowed.push_back({static_cast<int>(row), column, off * off});
      }
    }
    // A find goes only to the robot of its layout looked for nearest to it, among all whose
    // search reaches it, those that could not take it included (a start's markers not at
    // rest): a lost robot whose search has grown over a neighbour not found this frame does not
    // take the neighbour for itself.
    std::vector<int> nearest(finds.size(), -1);
    for (size_t column = 0; column < finds.size(); ++column) {
      const Eigen::Vector3d at = finds[column].world_from_body.translation();
      double best = std::numeric_limits<double>::infinity();
      for (size_t row = 0; row < searching.size(); ++row) {
        const double off = (at - searches[row].centre).norm();
        if (swarm_.robots[searching[row]].layout == find_layouts[column] &&
            off <= searches[row].radius_m && off < best) {
          best = off;
          nearest[column] = static_cast<int>(row);
        }
      }
    }
    std::erase_if(allowed, [&](const AllowedPair& pair) {
      return nearest[static_cast<size_t>(pair.column)] != pair.row;
    });
    const std::vector<int> given = min_cost_assignment(
        static_cast<int>(searching.size()), static_cast<int>(finds.size()), allowed, unassigned);
    for (size_t row = 0; row < searching.size(); ++row) {
      if (given[row] < 0) continue;
      const Found& found = finds[given[row]];
      // Two finds may share a marker (the same markers in two orders): the first given keeps it.
      if (std::any_of(found.markers.begin(), found.markers.end(),
                      [&](int m) { return m >= 0 && used[m]; })) {
        continue;
      }
      for (int m : found.markers) {
        if (m >= 0) used[m] = 1;
      }
      poses[searching[row]] = posed(searching[row], stamp_ns, found, true);
      ++counts_.found;
    }
  }

  std::vector<SwarmRobotPose> result;
  for (auto& pose : poses) {
    if (pose) result.push_back(std::move(*pose));
  }
  counts_.searching = static_cast<int>(robots_.size() - result.size());
  return result;
}

SwarmRobotPose SwarmTracker::posed(size_t r, int64_t stamp_ns, const Found& found, bool afresh) {
  Robot& robot = robots_[r];
  const bool several = swarm_.layouts[swarm_.robots[r].layout].markers.size() > 1;
  SwarmRobotPose pose;
  pose.robot = r;
  pose.orientation_known = several;
  pose.markers = found.markers;
  for (int m : found.markers) pose.markers_used += m >= 0 ? 1 : 0;
  pose.fit_rms_m = found.rms_m;
  pose.found_afresh = afresh;
  if (afresh) robot.lost_since_ns.reset();
  robot.missed_since_ns.reset();
  robot.stamp_ns = stamp_ns;
  if (several) {
    if (afresh) {
      robot.body.emplace(found.world_from_body, found.covariance, stamp_ns, options_.motion);
    } else {
      robot.body->correct(stamp_ns, found.world_from_body, found.covariance);
    }
    const tracking::BodyState& state = robot.body->state();
    pose.world_from_body = state.camera_from_body;
    pose.covariance = state.pose_covariance();
    pose.linear_velocity = state.linear_velocity;
    pose.angular_velocity = state.angular_velocity;
    pose.velocity_covariance = state.velocity_covariance();
  } else {
    const Eigen::Matrix3d covariance = found.covariance.topLeftCorner<3, 3>();
    const Eigen::Vector3d measured = found.world_from_body.translation();
    if (afresh) {
      robot.point.emplace(measured, covariance, stamp_ns, options_.motion);
    } else {
      robot.point->correct(stamp_ns, measured, covariance);
    }
    const tracking::PointState& state = robot.point->state();
    pose.world_from_body.translation() = state.position;
    pose.covariance.topLeftCorner<3, 3>() = state.covariance.topLeftCorner<3, 3>();
    pose.covariance.bottomRightCorner<3, 3>() =
        Eigen::Matrix3d::Identity() * kUnknownOrientationVariance;
    pose.linear_velocity = state.velocity;
    pose.velocity_covariance.topLeftCorner<3, 3>() = state.covariance.bottomRightCorner<3, 3>();
    pose.velocity_covariance.bottomRightCorner<3, 3>() =
        Eigen::Matrix3d::Identity() * kUnknownOrientationVariance;
  }
  pose.velocity_known = !afresh;
  return pose;
}

}  // namespace mocap::volume
