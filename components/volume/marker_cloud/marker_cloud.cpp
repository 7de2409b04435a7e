#include "volume/marker_cloud/marker_cloud.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>
#include <Eigen/Cholesky>

namespace mocap::volume {
namespace {

// The sigma of a pixel whose camera states none (as the fusion assumes).
constexpr double kUnstatedSigmaPx = 0.1;
// A detection stated this many times less precise than its camera's median is a merged blob.
constexpr double kMergedSigmaFactor = 3;
// A detection two tracks reach goes to the nearer when it is this much nearer.
constexpr double kMuchNearer = 0.5;
// Gauss-Newton steps at most, and the step (metres) that ends them sooner: 10 um, after which
// the point is a few percent of that (the Jacobian's error) from the solution, against markers
// placed to a tenth of a millimetre. From a track's prediction, two passes.
constexpr int kMaxSteps = 5;
constexpr double kConvergedStep_m = 1e-5;

// What a frame computes once per camera.
struct CameraGeometry {
  const calibration::CameraModel* model = nullptr;
  Eigen::Isometry3d camera_from_world = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d world_from_camera = Eigen::Matrix3d::Identity();  // rotation
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();                 // in the world
  double focal_px = 1;
};

// One camera's detections by grid cell, for the detections near a pixel without looking at
// all of them: bucketed by row (a counting sort: a frame's grids cost no sort), each row's
// cells in no order.
class PixelGrid {
 public:
  PixelGrid(const std::vector<Eigen::Vector2d>& pixels, double cell_px)
      : pixels_(&pixels), cell_px_(cell_px) {
    if (pixels.empty()) return;
    std::vector<int64_t> rows(pixels.size());
    first_row_ = std::numeric_limits<int64_t>::max();
    int64_t last_row = std::numeric_limits<int64_t>::min();
    for (size_t i = 0; i < pixels.size(); ++i) {
      rows[i] = cell_of(pixels[i].y());
      first_row_ = std::min(first_row_, rows[i]);
      last_row = std::max(last_row, rows[i]);
    }
    row_starts_.assign(static_cast<size_t>(last_row - first_row_) + 2, 0);
    for (int64_t row : rows) ++row_starts_[static_cast<size_t>(row - first_row_) + 1];
    for (size_t r = 1; r < row_starts_.size(); ++r) row_starts_[r] += row_starts_[r - 1];
    cells_.resize(pixels.size());
    std::vector<int> filled(row_starts_.begin(), row_starts_.end() - 1);
    for (size_t i = 0; i < pixels.size(); ++i) {
      cells_[static_cast<size_t>(filled[static_cast<size_t>(rows[i] - first_row_)]++)] = {
          cell_of(pixels[i].x()), static_cast<int>(i)};
    }
  }

  // The detection nearest `at` within `radius_px` (at most the cell size) that `usable`
  // accepts, or -1.
  template <class Usable>
  int nearest(const Eigen::Vector2d& at, double radius_px, Usable usable) const {
    const int64_t cx = cell_of(at.x()), cy = cell_of(at.y());
    int best = -1;
    double best_squared = radius_px * radius_px;
    const int64_t rows = static_cast<int64_t>(row_starts_.size()) - 1;
    for (int64_t row = std::max(cy - 1 - first_row_, int64_t{0});
         row <= std::min(cy + 1 - first_row_, rows - 1); ++row) {
      const int end = row_starts_[static_cast<size_t>(row) + 1];
      for (int k = row_starts_[static_cast<size_t>(row)]; k < end; ++k) {
        const Cell& cell = cells_[static_cast<size_t>(k)];
        if (cell.column < cx - 1 || cell.column > cx + 1) continue;
        const double squared = ((*pixels_)[cell.detection] - at).squaredNorm();
        if (squared <= best_squared && usable(cell.detection)) {
          best = cell.detection;
          best_squared = squared;
        }
      }
    }
    return best;
  }

 private:
  struct Cell {
    int64_t column = 0;
    int detection = 0;
  };
  // Cells far outside any image (and a pixel that is not a number) are folded onto the edge
  // cells, which keeps the row index small; lookups compare true distances, so nothing is
  // found that is not near.
  static constexpr int64_t kSpan = 4096;
  int64_t cell_of(double pixel) const {
    // Shifted to be positive, where truncation is the floor (std::floor is a call here).
    const double shifted = pixel / cell_px_ + static_cast<double>(kSpan);
    if (!(shifted > 0)) return -kSpan;
    if (!(shifted < static_cast<double>(2 * kSpan))) return kSpan;
    return static_cast<int64_t>(shifted) - kSpan;
  }

  const std::vector<Eigen::Vector2d>* pixels_;
  double cell_px_;
  std::vector<Cell> cells_;  // by row
  int64_t first_row_ = 0;
  std::vector<int> row_starts_;  // row r's cells: [row_starts_[r], row_starts_[r + 1])
};

struct Observation {
  int camera = 0;
  int detection = 0;
};

struct Fit {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  std::vector<double> errors_px;  // per observation
  double rms_px = 0;
  bool valid = false;
};

// The point whose projections best fit the observations, in each pixel's sigmas, from `start`.
// The Jacobian is the pinhole's at the camera's focal length: the lens's distortion changes it
// by a few percent, which slows the steps a little but moves no solution (the errors
// themselves go through the camera's model). The errors and the covariance are those of the
// last point evaluated: the result itself when the steps run out, a step of less than
// kConvergedStep_m back when they converge (no pass over the cameras for a change in the
// errors far below a thousandth of a pixel). `start_pixels`, when given, are `start`'s
// projections in the observations' cameras, in their order: a track's prediction, projected
// already to find its detections.
Fit fit_point(const std::vector<CameraGeometry>& geometry,
              const std::vector<CameraDetections>& cameras,
              const std::vector<Observation>& observations, const Eigen::Vector3d& start,
              const Eigen::Vector2d* start_pixels = nullptr) {
  Fit fit;
  fit.position = start;
  fit.errors_px.resize(observations.size());
  Eigen::Matrix3d information;
  auto sigma_of = [&](const Observation& o) {
    const std::vector<double>& sigmas = cameras[o.camera].pixel_sigma_px;
    return sigmas.empty() ? kUnstatedSigmaPx : sigmas[o.detection];
  };
  for (int step = 0;; ++step) {
    information.setZero();
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    double squared = 0;
    for (size_t k = 0; k < observations.size(); ++k) {
      const Observation& o = observations[k];
      const CameraGeometry& camera = geometry[o.camera];
      const Eigen::Vector3d in_camera = camera.camera_from_world * fit.position;
      if (in_camera.z() <= 0) return fit;
      const std::optional<Eigen::Vector2d> pixel =
          step == 0 && start_pixels ? start_pixels[k] : camera.model->project(in_camera);
      if (!pixel) return fit;
      const Eigen::Vector2d error_px = *pixel - cameras[o.camera].pixels[o.detection];
      fit.errors_px[k] = error_px.norm();
      squared += error_px.squaredNorm();
      const double sigma = sigma_of(o);
      const double scale = camera.focal_px / (sigma * in_camera.z());
      Eigen::Matrix<double, 2, 3> jacobian;
      jacobian << scale, 0, -scale * in_camera.x() / in_camera.z(), 0, scale,
          -scale * in_camera.y() / in_camera.z();
      jacobian = jacobian * camera.camera_from_world.linear();
      information += jacobian.transpose() * jacobian;
      gradient += jacobian.transpose() * (error_px / sigma);
    }
    fit.rms_px = std::sqrt(squared / static_cast<double>(observations.size()));
    if (step == kMaxSteps) break;
    const Eigen::LDLT<Eigen::Matrix3d> solver(information);
    if (solver.info() != Eigen::Success || !solver.isPositive()) return fit;
    const Eigen::Vector3d step_m = -solver.solve(gradient);
    fit.position += step_m;
    if (step_m.norm() < kConvergedStep_m) break;
  }
  fit.covariance = information.inverse();
  fit.valid = true;
  return fit;
}

int cameras_in(const std::vector<Observation>& observations) {
  uint32_t bits = 0;
  for (const Observation& o : observations) bits |= 1u << o.camera;
  return std::popcount(bits);
}

// fit_point, the observations further than `tolerance_px` off left out one by one, worst first,
// while `min_cameras` remain; an invalid fit when fewer do. `start_pixels` as fit_point's.
Fit fit_consistent(const std::vector<CameraGeometry>& geometry,
                   const std::vector<CameraDetections>& cameras,
                   std::vector<Observation>& observations, const Eigen::Vector3d& start,
                   double tolerance_px, int min_cameras,
                   const Eigen::Vector2d* start_pixels = nullptr) {
  Fit fit;
  Eigen::Vector3d from = start;
  while (cameras_in(observations) >= min_cameras) {
    fit = fit_point(geometry, cameras, observations, from, start_pixels);
    start_pixels = nullptr;  // the next fit starts from this one's point
    if (!fit.valid) return fit;
    const auto worst = std::max_element(fit.errors_px.begin(), fit.errors_px.end());
    if (*worst <= tolerance_px) return fit;
    observations.erase(observations.begin() + (worst - fit.errors_px.begin()));
    from = fit.position;
  }
  return Fit{};
}

}  // namespace

std::optional<std::string> MarkerCloudOptions::problem() const {
  if (!(gate_px > 0)) return fmt::format("gate_px: {} is not above 0", gate_px);
  if (!(tolerance_px > 0)) return fmt::format("tolerance_px: {} is not above 0", tolerance_px);
  if (min_cameras_to_start < 2) {
    return fmt::format("min_cameras_to_start: {} is below 2", min_cameras_to_start);
  }
  if (!(lost_after_s >= 0)) return fmt::format("lost_after_s: {} is below 0", lost_after_s);
  return std::nullopt;
}

MarkerCloudTracker::MarkerCloudTracker(MarkerCloudOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("MarkerCloudOptions::" + *problem);
  }
}

void MarkerCloudTracker::update(Track& track, int64_t stamp_ns, const Eigen::Vector3d& position) {
  const double dt_s = static_cast<double>(stamp_ns - track.stamp_ns) * 1e-9;
  if (dt_s > 0) {
    track.velocity = (position - track.position) / dt_s;
    track.velocity_known = true;
  }
  track.position = position;
  track.stamp_ns = stamp_ns;
}

std::vector<CloudMarker> MarkerCloudTracker::track(int64_t stamp_ns,
                                                   const std::vector<CameraDetections>& cameras) {
  if (cameras.size() > static_cast<size_t>(kMaxCloudCameras)) {
    throw std::invalid_argument(fmt::format("a marker cloud takes at most {} cameras, not {}",
                                            kMaxCloudCameras, cameras.size()));
  }
  std::vector<CameraGeometry> geometry(cameras.size());
  std::vector<PixelGrid> grids;
  std::vector<std::vector<char>> taken(cameras.size());
  const double cell_px = std::max(options_.gate_px, 2 * options_.tolerance_px);
  for (size_t c = 0; c < cameras.size(); ++c) {
    const CameraDetections& camera = cameras[c];
    if (camera.camera == nullptr) throw std::invalid_argument("a camera without a model");
    if (!camera.pixel_sigma_px.empty() && camera.pixel_sigma_px.size() != camera.pixels.size()) {
      throw std::invalid_argument("a camera's pixel_sigma_px needs one value per pixel, or none");
    }
    geometry[c] = {
        camera.camera, camera.camera_from_world, camera.camera_from_world.linear().transpose(),
        camera.camera_from_world.inverse().translation(), camera.camera->focal_length_px()};
    grids.emplace_back(camera.pixels, cell_px);
    taken[c].assign(camera.pixels.size(), 0);
  }
  counts_ = {};
  std::vector<CloudMarker> markers;
  auto add_marker = [&](const Track& track, const Fit& fit,
                        const std::vector<Observation>& observations) {
    CloudMarker marker;
    marker.id = track.id;
    marker.position = fit.position;
    marker.covariance = fit.covariance;
    marker.velocity = track.velocity_known ? track.velocity : Eigen::Vector3d::Zero();
    marker.velocity_known = track.velocity_known;
    marker.rms_px = fit.rms_px;
    for (const Observation& o : observations) {
      marker.cameras |= 1u << o.camera;
      marker.observations.emplace_back(o.camera, o.detection);
      taken[o.camera][o.detection] = 1;
    }
    markers.push_back(std::move(marker));
  };

  // 1. Tracks where they are predicted. A detection two tracks reach goes to the nearer when it
  // is much the nearer (a marker's own track projects within a tenth of a pixel of it; a ghost
  // or a neighbour's, further); to neither when they are about as near (two markers merged
  // into one blob: its centre is neither's).
  const size_t camera_count = cameras.size();
  const double infinity = std::numeric_limits<double>::infinity();
  std::vector<int> nearest(tracks_.size() * camera_count, -1);
  struct Claims {
    std::vector<double> best_px, second_px;
    std::vector<int> best_track;
    bool held_by(size_t d, int track) const {
      return best_track[d] == track && best_px[d] <= kMuchNearer * second_px[d];
    }
    bool merged(size_t d) const {
      return second_px[d] < std::numeric_limits<double>::infinity() &&
             best_px[d] > kMuchNearer * second_px[d];
    }
  };
  std::vector<Claims> claims(camera_count);
  std::vector<Eigen::Vector3d> predictions(tracks_.size());
  std::vector<Eigen::Vector2d> projected(tracks_.size() * camera_count);  // where d is nearest
  for (size_t c = 0; c < camera_count; ++c) {
    claims[c].best_px.assign(cameras[c].pixels.size(), infinity);
    claims[c].second_px.assign(cameras[c].pixels.size(), infinity);
    claims[c].best_track.assign(cameras[c].pixels.size(), -1);
  }
  for (size_t t = 0; t < tracks_.size(); ++t) {
    const Track& track = tracks_[t];
    const double dt_s = static_cast<double>(stamp_ns - track.stamp_ns) * 1e-9;
    predictions[t] = track.position;
    if (track.velocity_known) predictions[t] += track.velocity * dt_s;
    for (size_t c = 0; c < camera_count; ++c) {
      const Eigen::Vector3d in_camera = geometry[c].camera_from_world * predictions[t];
      if (in_camera.z() <= 0) continue;
      const std::optional<Eigen::Vector2d> pixel = geometry[c].model->project(in_camera);
      if (!pixel) continue;
      const int d = grids[c].nearest(*pixel, options_.gate_px, [](int) { return true; });
      if (d < 0) continue;
      nearest[t * camera_count + c] = d;
      projected[t * camera_count + c] = *pixel;
      Claims& claim = claims[c];
      const double off = (cameras[c].pixels[d] - *pixel).norm();
      if (off < claim.best_px[d]) {
        claim.second_px[d] = claim.best_px[d];
        claim.best_px[d] = off;
        claim.best_track[d] = static_cast<int>(t);
      } else {
        claim.second_px[d] = std::min(claim.second_px[d], off);
      }
    }
  }
  for (size_t c = 0; c < camera_count; ++c) {
    for (size_t d = 0; d < cameras[c].pixels.size(); ++d) counts_.merged += claims[c].merged(d);
  }
  std::vector<double> median_sigma(camera_count, 0);  // of each camera's detections
  for (size_t c = 0; c < camera_count; ++c) {
    std::vector<double> sigmas = cameras[c].pixel_sigma_px;
    if (sigmas.empty()) continue;
    std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
    median_sigma[c] = sigmas[sigmas.size() / 2];
  }
  std::vector<char> observed(tracks_.size(), 0);
  std::vector<Observation> observations;
  std::vector<Eigen::Vector2d> predicted_pixels;
  for (size_t t = 0; t < tracks_.size(); ++t) {
    observations.clear();
    predicted_pixels.clear();
    for (size_t c = 0; c < camera_count; ++c) {
      const int d = nearest[t * camera_count + c];
      if (d >= 0 && claims[c].held_by(static_cast<size_t>(d), static_cast<int>(t))) {
        observations.push_back({static_cast<int>(c), d});
        predicted_pixels.push_back(projected[t * camera_count + c]);
      }
    }
    if (cameras_in(observations) < 2) continue;
    // Two cameras' rays meet wherever the second detection lies on the first's epipolar line,
    // and a blob merged with a neighbour's (stated with a wide sigma) lies millimetres off: a
    // third camera would refuse it, two cannot. A marker of two cameras, one of them such a
    // blob, waits for a better frame; its detections are its track's, not a new marker's.
    if (cameras_in(observations) == 2 &&
        std::any_of(observations.begin(), observations.end(), [&](const Observation& o) {
          const std::vector<double>& sigmas = cameras[o.camera].pixel_sigma_px;
          return !sigmas.empty() &&
                 sigmas[o.detection] > kMergedSigmaFactor * median_sigma[o.camera];
        })) {
      for (const Observation& o : observations) taken[o.camera][o.detection] = 1;
      continue;
    }
    const Fit fit = fit_consistent(geometry, cameras, observations, predictions[t],
                                   options_.tolerance_px, 2, predicted_pixels.data());
    if (!fit.valid) continue;
    update(tracks_[t], stamp_ns, fit.position);
    observed[t] = 1;
    add_marker(tracks_[t], fit, observations);
    ++counts_.tracked;
  }

  // 2. New markers from the free detections' rays. A blob two tracks claim is explained by
  // them: its centre, between two markers, would start a marker where there is none.
  for (size_t c = 0; c < camera_count; ++c) {
    for (size_t d = 0; d < cameras[c].pixels.size(); ++d) {
      if (claims[c].merged(d)) taken[c][d] = 1;
    }
  }
  std::vector<std::vector<Eigen::Vector3d>> rays(camera_count);  // world directions; zero: none
  for (size_t c = 0; c < camera_count; ++c) {
    rays[c].assign(cameras[c].pixels.size(), Eigen::Vector3d::Zero());
    for (size_t d = 0; d < cameras[c].pixels.size(); ++d) {
      if (taken[c][d]) continue;
      if (auto ray = geometry[c].model->unproject(cameras[c].pixels[d])) {
        rays[c][d] = (geometry[c].world_from_camera * *ray).normalized();
      }
    }
  }
  // Every pair of cameras' proposals, each with the other cameras' free detections near it;
  // one detection set (a marker proposed by several pairs) fitted once.
  struct Proposal {
    std::vector<Observation> observations;  // sorted by camera
    Eigen::Vector3d start = Eigen::Vector3d::Zero();
    Fit fit;
  };
  std::vector<Proposal> proposals;
  for (size_t a = 0; a < camera_count; ++a) {
    for (size_t b = a + 1; b < camera_count; ++b) {
      for (size_t i = 0; i < rays[a].size(); ++i) {
        if (taken[a][i] || rays[a][i].isZero()) continue;
        for (size_t j = 0; j < rays[b].size(); ++j) {
          if (taken[b][j] || rays[b][j].isZero()) continue;
          // The rays' closest points: centre_a + s ray_a and centre_b + u ray_b.
          const Eigen::Vector3d& ray_a = rays[a][i];
          const Eigen::Vector3d& ray_b = rays[b][j];
          const Eigen::Vector3d between = geometry[a].centre - geometry[b].centre;
          const double cosine = ray_a.dot(ray_b);
          const double denominator = 1 - cosine * cosine;
          if (denominator < 1e-12) continue;
          const double da = ray_a.dot(between), db = ray_b.dot(between);
          const double s = (cosine * db - da) / denominator;
          const double u = (db - cosine * da) / denominator;
          if (s <= 0 || u <= 0) continue;
          const Eigen::Vector3d on_a = geometry[a].centre + s * ray_a;
          const Eigen::Vector3d on_b = geometry[b].centre + u * ray_b;
          const double half_gap = (on_a - on_b).norm() / 2;
          if (std::max(geometry[a].focal_px * half_gap / s, geometry[b].focal_px * half_gap / u) >
              options_.tolerance_px) {
            continue;
          }
          Proposal proposal;
          proposal.start = (on_a + on_b) / 2;
          for (size_t c = 0; c < camera_count; ++c) {
            if (c == a || c == b) {
              proposal.observations.push_back(
                  {static_cast<int>(c), static_cast<int>(c == a ? i : j)});
              continue;
            }
            const Eigen::Vector3d in_camera = geometry[c].camera_from_world * proposal.start;
            if (in_camera.z() <= 0) continue;
            const std::optional<Eigen::Vector2d> pixel = geometry[c].model->project(in_camera);
            if (!pixel) continue;
            const int d = grids[c].nearest(*pixel, 2 * options_.tolerance_px,
                                           [&, c](int k) { return !taken[c][k]; });
            if (d >= 0) proposal.observations.push_back({static_cast<int>(c), d});
          }
          if (cameras_in(proposal.observations) >= options_.min_cameras_to_start) {
            proposals.push_back(std::move(proposal));
          }
        }
      }
    }
  }
  const auto same = [](const Proposal& x, const Proposal& y) {
    return std::equal(x.observations.begin(), x.observations.end(), y.observations.begin(),
                      y.observations.end(), [](const Observation& p, const Observation& q) {
                        return p.camera == q.camera && p.detection == q.detection;
                      });
  };
  std::sort(proposals.begin(), proposals.end(), [](const Proposal& x, const Proposal& y) {
    return std::lexicographical_compare(
        x.observations.begin(), x.observations.end(), y.observations.begin(), y.observations.end(),
        [](const Observation& p, const Observation& q) {
          return std::tie(p.camera, p.detection) < std::tie(q.camera, q.detection);
        });
  });
  proposals.erase(std::unique(proposals.begin(), proposals.end(), same), proposals.end());
  for (Proposal& proposal : proposals) {
    proposal.fit = fit_consistent(geometry, cameras, proposal.observations, proposal.start,
                                  options_.tolerance_px, options_.min_cameras_to_start);
  }
  std::erase_if(proposals, [](const Proposal& p) { return !p.fit.valid; });
  // The most cameras first: a marker seen by all beats the chance meeting of two of its
  // detections' rays with a third camera's stray detection.
  std::sort(proposals.begin(), proposals.end(), [](const Proposal& x, const Proposal& y) {
    if (x.observations.size() != y.observations.size()) {
      return x.observations.size() > y.observations.size();
    }
    return x.fit.rms_px < y.fit.rms_px;
  });
  for (Proposal& proposal : proposals) {
    std::vector<Observation>& observations = proposal.observations;
    const size_t before = observations.size();
    std::erase_if(observations,
                  [&](const Observation& o) { return taken[o.camera][o.detection] != 0; });
    // The fitted point finds the detections of cameras the proposal's first guess missed
    // (two cameras close together guess the depth poorly): left free, they would start a
    // second track of the same marker.
    uint32_t seen = 0;
    for (const Observation& o : observations) seen |= 1u << o.camera;
    for (size_t c = 0; c < camera_count; ++c) {
      if (seen & (1u << c)) continue;
      const Eigen::Vector3d in_camera = geometry[c].camera_from_world * proposal.fit.position;
      if (in_camera.z() <= 0) continue;
      const std::optional<Eigen::Vector2d> pixel = geometry[c].model->project(in_camera);
      if (!pixel) continue;
      const int d =
          grids[c].nearest(*pixel, options_.tolerance_px, [&, c](int k) { return !taken[c][k]; });
      if (d >= 0) observations.push_back({static_cast<int>(c), d});
    }
    if (observations.size() != before) {
      if (cameras_in(observations) < options_.min_cameras_to_start) continue;
      proposal.fit = fit_consistent(geometry, cameras, observations, proposal.fit.position,
                                    options_.tolerance_px, options_.min_cameras_to_start);
      if (!proposal.fit.valid) continue;
    }
    // Distances in the units of a pixel seen from the nearest camera that sees the marker.
    double nearest_camera_m = std::numeric_limits<double>::infinity();
    for (const Observation& o : observations) {
      nearest_camera_m =
          std::min(nearest_camera_m, (geometry[o.camera].centre - proposal.fit.position).norm() /
                                         geometry[o.camera].focal_px);
    }
    // A marker of this frame already there: these are detections of it its cameras did not
    // explain (a blob cut or merged), not a marker of their own.
    const double same_m = options_.tolerance_px * nearest_camera_m;
    if (std::any_of(markers.begin(), markers.end(), [&](const CloudMarker& marker) {
          return (marker.position - proposal.fit.position).norm() <= same_m;
        })) {
      continue;
    }
    // A track not observed this frame, predicted where this marker is (within the gate), is
    // this marker.
    size_t continued = observed.size();
    double best_m = options_.gate_px * nearest_camera_m;
    for (size_t t = 0; t < observed.size(); ++t) {
      if (observed[t]) continue;
      const double off = (predictions[t] - proposal.fit.position).norm();
      if (off <= best_m) {
        continued = t;
        best_m = off;
      }
    }
    if (continued < observed.size()) {
      observed[continued] = 1;
      update(tracks_[continued], stamp_ns, proposal.fit.position);
      add_marker(tracks_[continued], proposal.fit, observations);
      ++counts_.continued;
    } else {
      Track track;
      track.id = next_id_++;
      track.position = proposal.fit.position;
      track.stamp_ns = stamp_ns;
      tracks_.push_back(track);
      add_marker(track, proposal.fit, observations);
      ++counts_.started;
    }
  }

  // 3. What no marker explains, and tracks given up.
  for (size_t c = 0; c < camera_count; ++c) {
    for (size_t d = 0; d < taken[c].size(); ++d) {
      if (!taken[c][d]) ++counts_.unexplained;  // merged blobs were taken before step 2
    }
  }
  size_t kept = 0;
  for (size_t t = 0; t < tracks_.size(); ++t) {
    const bool is_new = t >= observed.size();
    if (!is_new && !observed[t]) {
      const double silent_s = static_cast<double>(stamp_ns - tracks_[t].stamp_ns) * 1e-9;
      if (silent_s > options_.lost_after_s) {
        ++counts_.dropped;
        continue;
      }
      ++counts_.coasting;
    }
    tracks_[kept++] = tracks_[t];
  }
  tracks_.resize(kept);

  totals_.tracked += counts_.tracked;
  totals_.started += counts_.started;
  totals_.continued += counts_.continued;
  totals_.coasting += counts_.coasting;
  totals_.dropped += counts_.dropped;
  totals_.merged += counts_.merged;
  totals_.unexplained += counts_.unexplained;
  return markers;
}

}  // namespace mocap::volume
