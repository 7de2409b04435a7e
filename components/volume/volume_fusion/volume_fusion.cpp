#include "volume/volume_fusion/volume_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace mocap::volume {
namespace {

// How quickly a camera's average residual follows its latest views, and how many views it
// takes before the average can call the camera drifted.
constexpr double kResidualSmoothing = 0.02;
constexpr int64_t kViewsBeforeDriftCall = 50;
// A camera whose average residual has passed this fraction of drift_px, its partner's staying
// below half of that, is the one left out when the two alone see a body and disagree.
constexpr double kSuspectFraction = 0.25;
// Views of fewer points say little of a camera: one marker taken for another is half of two.
constexpr size_t kMinPointsForResidual = 3;
// The residual of a camera is measured with detections up to this many times the matching
// radius away: a bumped camera's markers land beyond the radius that pairs them for fusion.
constexpr double kResidualRadiusFactor = 3;
// A track only one camera found is looked for again this many times the matching radius wide.
constexpr double kRetryRadiusFactor = 3;
// A point this many times the fusion's RMS limit off the pose is left out, and the pose fitted
// again without it.
constexpr double kOutlierFactor = 2;
// In a pose that holds, a point further off than this many times the points' median error,
// each in units of its pixel's sigma, and than kStrayFloorSigmas, is a stray: left out, and
// the pose fitted again. In sigmas, not pixels: a neighbour's marker taken for one of the
// body's lies 0.1 to 0.3 px off where the body's own lie 0.02 to 0.05 px off, which a floor in
// pixels kept, and two cameras' fit then stood 6 to 15 mm off.
constexpr double kStrayFactor = 5;
constexpr double kStrayFloorSigmas = 3;
// The sigma of a pixel whose detections state none, for the tests above.
constexpr double kUnstatedSigmaPx = 0.1;
// A fit is set aside as unusually poor when its residuals (in sigmas: normalized RMS) exceed
// this many times what the body's track usually has (its running average), or, for a body not
// tracked, what the volume's fits usually have. On the demo's rendered images sound fits lie at
// 0.75 to 1.5 (3 at most), fits from a neighbour's markers centimetres off at 16 to 48: such a
// fit is not handed out; the body is looked for afresh, or left unposed.
constexpr double kUsualRmsSmoothing = 0.1;
constexpr double kUnusualRmsFactor = 5;
// A fit whose residuals exceed this many times the usual is looked at camera by camera and
// point by point: where leaving one camera's points out, or its few worst points, brings the
// rest back to the usual, those points were not the body's markers (one far-off point pulls a
// whole fit, so that its median error hides it from trim_strays). Whichever keeps more points:
// a camera's one or two points bending the others' fit leave the others' points the furthest
// off, where one far-off point in a camera that sees the body well is the one to leave out. A
// camera that sees one or two of a body's markers, one of them a blob merged with a neighbour's,
// bends the depth the camera that sees the whole body fixes poorly: 10 to 15 mm off on the demo's
// images, with residuals 3 to 4 times the usual.
constexpr double kElevatedRmsFactor = 2;
// At most this many of a fit's worst points are left out, one by one, to bring it back to the
// usual: markers cut by an occluder's edge in one camera come several at a time.
constexpr int kMostWorstPoints = 3;
// A camera's points disagree with the others' when they add this many sigmas (squared, per
// residual, in units of the usual) to the fit's chi-square: 3, where agreeing points add about
// 1. Points cut by an occluder's edge raise a fit's residuals too, in every camera, and by
// less: leaving a camera out for them left a single camera's poorer depth.
constexpr double kDisagreeingSigmas = 3;
// A track's velocity is measured over its poses of this long (seconds).
constexpr double kVelocityWindow_s = 0.05;

// What a fit's normalized RMS is compared with: what the fits usually have, or, before any, the
// 1 that detections whose sigmas are right give. Relative, so that cameras erring more (or
// less) than their sigmas say are judged by their own usual.
double expected_rms(double usual_normalized_rms) {
  return usual_normalized_rms > 0 ? usual_normalized_rms : 1.0;
}

int cameras_seeing(const std::vector<CameraView>& views) {
  return static_cast<int>(std::count_if(views.begin(), views.end(),
                                        [](const CameraView& v) { return !v.pixels.empty(); }));
}

int points_in(const std::vector<CameraView>& views) {
  int points = 0;
  for (const CameraView& view : views) points += static_cast<int>(view.pixels.size());
  return points;
}

// The distance (pixels) between each of the view's pixels and where the pose projects its
// point; infinite for a point that does not project.
std::vector<double> point_errors_px(const CameraView& view,
                                    const Eigen::Isometry3d& world_from_body) {
  std::vector<double> errors;
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    const Eigen::Vector3d in_camera =
        view.camera_from_world * world_from_body * view.body_points[i];
    const auto pixel = in_camera.z() > 0 ? view.camera->project(in_camera) : std::nullopt;
    errors.push_back(pixel ? (*pixel - view.pixels[i]).norm()
                           : std::numeric_limits<double>::infinity());
  }
  return errors;
}

// The median of point_errors_px: a moved camera has all of its points off, where a marker
// merged with a neighbour's, or taken for it, is one; NaN for a view without points.
double view_median_error_px(const CameraView& view, const Eigen::Isometry3d& world_from_body) {
  std::vector<double> errors = point_errors_px(view, world_from_body);
  if (errors.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

// point_errors_px, each in units of its pixel's sigma.
std::vector<double> point_errors_sigmas(const CameraView& view,
                                        const Eigen::Isometry3d& world_from_body) {
  std::vector<double> errors = point_errors_px(view, world_from_body);
  for (size_t i = 0; i < errors.size(); ++i) errors[i] /= view.pixel_sigma_px[i];
  return errors;
}

// A view with no points left: the camera is left out of the fit. Its pixels' sigmas go with
// them, so the lists stay index by index.
void empty_view(CameraView& view) {
  view.body_points.clear();
  view.pixels.clear();
  view.pixel_sigma_px.clear();
}

enum class Units { Pixels, Sigmas };

// The views without their points further than `limit` (pixels, or each point's sigmas) from
// where the pose puts them.
std::vector<CameraView> without_outliers(const std::vector<CameraView>& views,
                                         const Eigen::Isometry3d& world_from_body, double limit,
                                         Units units) {
  std::vector<CameraView> kept;
  for (const CameraView& view : views) {
    const std::vector<double> errors = units == Units::Pixels
                                           ? point_errors_px(view, world_from_body)
                                           : point_errors_sigmas(view, world_from_body);
    CameraView close{view.camera, view.camera_from_world, {}, {}, {}};
    for (size_t i = 0; i < errors.size(); ++i) {
      if (errors[i] > limit) continue;
      close.body_points.push_back(view.body_points[i]);
      close.pixels.push_back(view.pixels[i]);
      close.pixel_sigma_px.push_back(view.pixel_sigma_px[i]);
    }
    kept.push_back(std::move(close));
  }
  return kept;
}

// `world_from_body` moved on by the velocities for `dt_s`.
Eigen::Isometry3d predicted(const Eigen::Isometry3d& world_from_body, const Eigen::Vector3d& v,
                            const Eigen::Vector3d& w, double dt_s) {
  Eigen::Isometry3d pose = world_from_body;
  pose.translation() += v * dt_s;
  const double angle = w.norm() * dt_s;
  if (angle > 0) {
    pose.linear() = Eigen::AngleAxisd(angle, w.normalized()).toRotationMatrix() * pose.linear();
  }
  return pose;
}

}  // namespace

std::optional<std::string> VolumeTrackerOptions::problem() const {
  if (auto problem = triangulation.problem()) return "triangulation." + *problem;
  if (auto problem = identification.problem()) return "identification." + *problem;
  if (auto problem = fusion.problem()) return "fusion." + *problem;
  if (!(match_radius_px > 0))
    return fmt::format("match_radius_px: {} is not above 0", match_radius_px);
  if (!(lost_after_s >= 0)) return fmt::format("lost_after_s: {} is below 0", lost_after_s);
  if (!(drift_px > 0)) return fmt::format("drift_px: {} is not above 0", drift_px);
  return std::nullopt;
}

VolumeTracker::VolumeTracker(std::vector<VolumeCamera> cameras, RigidBodyDatabase bodies,
                             VolumeTrackerOptions options)
    : cameras_(std::move(cameras)),
      bodies_(std::move(bodies)),
      options_(options),
      tracks_(bodies_.bodies.size()),
      health_(cameras_.size()) {
  if (cameras_.empty()) throw std::invalid_argument("a volume needs at least one camera");
  for (const VolumeCamera& camera : cameras_) {
    if (!camera.model) throw std::invalid_argument("camera '" + camera.name + "' has no model");
  }
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("VolumeTrackerOptions::" + *problem);
  }
}

std::vector<TrackedBodyPose> VolumeTracker::track(int64_t stamp_ns,
                                                  const std::vector<CameraFrame>& frame) {
  if (frame.size() != cameras_.size()) {
    throw std::invalid_argument("a frame needs one entry per camera");
  }
  for (const CameraFrame& camera : frame) {
    if (!camera.pixel_sigma_px.empty() && camera.pixel_sigma_px.size() != camera.pixels.size()) {
      throw std::invalid_argument("a camera's pixel_sigma_px needs one value per pixel, or none");
    }
  }
  std::vector<CameraDetections> detections;
  for (size_t c = 0; c < cameras_.size(); ++c) {
    CameraDetections camera{cameras_[c].model.get(), cameras_[c].camera_from_world, {}, {}};
    if (frame[c].received && !health_[c].drifted) {
      camera.pixels = frame[c].pixels;
      camera.pixel_sigma_px = frame[c].pixel_sigma_px;
      if (camera.pixel_sigma_px.empty())
        camera.pixel_sigma_px.assign(camera.pixels.size(), kUnstatedSigmaPx);
    }
    detections.push_back(std::move(camera));
  }
  // A camera stamped a little off the frame's time saw each body moved on by its velocity:
  // its extrinsics take the shift, per body.
  auto for_body = [&](const Track& track) {
    std::vector<CameraDetections> shifted = detections;
    if (!track.velocity_known) return shifted;
    for (size_t c = 0; c < shifted.size(); ++c) {
      const double dt_s = static_cast<double>(frame[c].stamp_ns - stamp_ns) * 1e-9;
      if (frame[c].received && dt_s != 0) {
        shifted[c].camera_from_world =
            shifted[c].camera_from_world * Eigen::Translation3d(track.linear_velocity * dt_s);
      }
    }
    return shifted;
  };

  std::vector<std::optional<TrackedBodyPose>> posed(bodies_.bodies.size());
  std::vector<std::optional<Fused>> single_camera(bodies_.bodies.size());
  // Tracked bodies first, where their tracks predict them.
  for (size_t b = 0; b < bodies_.bodies.size(); ++b) {
    std::optional<Track>& track = tracks_[b];
    if (!track) continue;
    const double dt_s = static_cast<double>(stamp_ns - track->stamp_ns) * 1e-9;
    if (dt_s > options_.lost_after_s) {
      track.reset();
      continue;
    }
    const Eigen::Isometry3d start = track->velocity_known
                                        ? predicted(track->world_from_body, track->linear_velocity,
                                                    track->angular_velocity, dt_s)
                                        : track->world_from_body;
    const std::vector<CameraDetections> cameras = for_body(*track);
    const double usual =
        track->usual_normalized_rms > 0 ? track->usual_normalized_rms : usual_normalized_rms_;
    std::optional<Fused> fused = fuse(b, start, cameras, options_.match_radius_px, usual,
                                      track->cameras_used >= 2 ? &start : nullptr);
    if (fused && fused->pose.cameras_used == 1) {
      // The other cameras' detections may lie beyond the radius from a prediction that one
      // camera's poor depth put off: from that camera's pose, a wider net, which the fusion's
      // RMS limit and the check of its residuals keep from taking wrong detections.
      std::optional<Fused> wider = fuse(b, fused->pose.world_from_body, cameras,
                                        kRetryRadiusFactor * options_.match_radius_px, usual);
      if (wider && wider->pose.cameras_used >= 2 && !unusually_poor(*wider, usual)) {
        fused = std::move(wider);
      }
    } else if (!fused) {
      // Posed by one camera last, the body passes into another's view where the prediction,
      // off in the first camera's depth, misses its markers: the same wider net. A body that
      // turned back is nearer its last pose than its prediction, which runs on.
      const double radius =
          (track->cameras_used == 1 ? kRetryRadiusFactor : 1.0) * options_.match_radius_px;
      if (track->cameras_used == 1) fused = fuse(b, start, cameras, radius, usual);
      if (!fused) fused = fuse(b, track->world_from_body, cameras, radius, usual);
    }
    // Markers taken for their neighbours, as when a body turns back and its prediction runs on,
    // or when one camera's poor depth puts the prediction off, give a fit under the RMS limit
    // yet centimetres off, far above the track's usual residuals.
    auto unusual = [&](const std::optional<Fused>& fit) {
      return fit && unusually_poor(*fit, usual);
    };
    if (unusual(fused)) {
      ++unusual_fits_;
      // A body that turned back is nearer its last pose than its prediction; failing that, it
      // is looked for afresh below, among the markers triangulated from every camera.
      std::optional<Fused> from_last =
          fuse(b, track->world_from_body, cameras, options_.match_radius_px, usual);
      if (!from_last || unusual(from_last)) continue;
      fused = std::move(from_last);
    }
    if (fused) {
      if (fused->pose.cameras_used >= 2) {
        take(fused->used, detections);  // what this body used is nobody else's
        posed[b] = update_track(b, stamp_ns, fused->pose);
      } else {
        single_camera[b] = std::move(*fused);
      }
    }
  }

  // The others, identified among the markers triangulated from what is left. A track that one
  // camera alone found may be found again from several: its depth from one camera is poor, and
  // a prediction off in depth misses the other cameras' detections, which would keep it at one.
  RigidBodyDatabase untracked;
  std::vector<size_t> untracked_index;
  for (size_t b = 0; b < bodies_.bodies.size(); ++b) {
    if (posed[b]) continue;
    untracked.bodies.push_back(bodies_.bodies[b]);
    untracked_index.push_back(b);
  }
  if (!untracked.bodies.empty()) {
    std::vector<Eigen::Vector3d> markers;
    for (const TriangulatedMarker& marker :
         triangulate_markers(detections, options_.triangulation)) {
      markers.push_back(marker.position);
    }
    for (const IdentifiedBody& found :
         identify_rigid_bodies(untracked, markers, options_.identification)) {
      const size_t b = untracked_index[static_cast<size_t>(
          std::find_if(untracked.bodies.begin(), untracked.bodies.end(),
                       [&](const RigidBody& body) { return body.name == found.name; }) -
          untracked.bodies.begin())];
      std::optional<Fused> fused = fuse(b, found.world_from_body, detections,
                                        options_.match_radius_px, usual_normalized_rms_);
      if (fused && unusually_poor(*fused, usual_normalized_rms_)) {
        ++unusual_fits_;
        continue;
      }
      if (fused) {
        ++identifications_;
        take(fused->used, detections);
        posed[b] = update_track(b, stamp_ns, fused->pose);
      }
    }
  }
  for (size_t b = 0; b < bodies_.bodies.size(); ++b) {
    if (posed[b] || !single_camera[b]) continue;
    take(single_camera[b]->used, detections);
    posed[b] = update_track(b, stamp_ns, single_camera[b]->pose);
  }

  std::vector<TrackedBodyPose> poses;
  for (auto& pose : posed) {
    if (pose) poses.push_back(std::move(*pose));
  }
  return poses;
}

std::optional<VolumeTracker::Fused> VolumeTracker::fuse(
    size_t body, const Eigen::Isometry3d& start, const std::vector<CameraDetections>& detections,
    double radius_px, double usual_normalized_rms, const Eigen::Isometry3d* fused_prediction) {
  const std::vector<Eigen::Vector3d>& markers = bodies_.bodies[body].markers;
  std::vector<CameraView> views = views_near(detections, markers, start, radius_px);
  if (points_in(views) < options_.fusion.min_points) return std::nullopt;
  MultiCameraPose fused = fit_without_outliers(views, start);
  std::optional<size_t> left_out;
  if (!fused.valid && cameras_seeing(views) >= 2) {
    // One camera that disagrees with the rest: the one whose removal lets them agree.
    size_t best = views.size();
    if (cameras_seeing(views) == 2) {
      best = suspect_of_two(views, fused_prediction);
    } else {
      const std::vector<double> without = rms_without_each_view_px(views, start, options_.fusion);
      for (size_t c = 0; c < without.size(); ++c) {
        if (!std::isnan(without[c]) && (best == views.size() || without[c] < without[best])) {
          best = c;
        }
      }
    }
    // Without it, the others' points far off are left out as the whole fit's were: a view may
    // hold a neighbour's marker that the fit pulled by the camera left out did not show.
    if (best < views.size()) {
      std::vector<CameraView> others = views;
      empty_view(others[best]);
      MultiCameraPose fit = fit_without_outliers(others, start);
      if (fit.valid) {
        left_out = best;
        ++health_[best].left_out;
        views = std::move(others);  // the left-out camera's detections stay for others
        fused = std::move(fit);
      }
    }
  }
  if (!fused.valid) return std::nullopt;
  const std::vector<CameraView> untrimmed = views;
  trim_strays(views, fused);
  if (!left_out && fused.normalized_rms > kElevatedRmsFactor * expected_rms(usual_normalized_rms)) {
    // A camera's points, or a few worst points: whichever keeps more of the fit's points.
    MultiCameraPose without_camera = fused, without_points = fused;
    std::vector<CameraView> fewer_points = views;
    const std::optional<size_t> other = disagreeing_view(
        views, without_camera, usual_normalized_rms,
        cameras_seeing(views) == 2 ? suspect_of_two(views, fused_prediction) : views.size());
    const bool points_out =
        without_worst_points(fewer_points, without_points, usual_normalized_rms);
    if (other && !(points_out && without_points.points_used > without_camera.points_used)) {
      left_out = *other;
      ++health_[*other].left_out;
      empty_view(views[*other]);
      fused = std::move(without_camera);
    } else if (points_out) {
      views = std::move(fewer_points);
      fused = std::move(without_points);
    }
  }

  // Each camera's residual where two other cameras or more hold the pose: a camera in the
  // fusion by its own points, strays included (a moved camera's points are all strays: its
  // residual must see them), one left out by its detections nearest to where the pose puts
  // the markers.
  if (fused.cameras_used >= 2) {
    for (size_t c = 0; c < views.size(); ++c) {
      const bool in_fusion = !views[c].pixels.empty();
      if (fused.cameras_used - (in_fusion ? 1 : 0) < 2) continue;
      std::optional<CameraView> wide;
      if (untrimmed[c].pixels.empty() && left_out == c) {
        wide = views_near({detections[c]}, markers, fused.world_from_body,
                          kResidualRadiusFactor * options_.match_radius_px)[0];
      }
      const CameraView* view = !untrimmed[c].pixels.empty() ? &untrimmed[c]
                               : wide                       ? &*wide
                                                            : nullptr;
      if (view == nullptr || view->pixels.size() < kMinPointsForResidual) continue;
      const double residual = view_median_error_px(*view, fused.world_from_body);
      if (!std::isnan(residual)) record_residual(c, residual);
    }
  }

  Fused result{fused, std::vector<std::vector<Eigen::Vector2d>>(views.size())};
  for (size_t c = 0; c < views.size(); ++c) result.used[c] = views[c].pixels;
  return result;
}

size_t VolumeTracker::suspect_of_two(const std::vector<CameraView>& views,
                                     const Eigen::Isometry3d* fused_prediction) {
  std::vector<size_t> seeing;
  for (size_t c = 0; c < views.size(); ++c) {
    if (!views[c].pixels.empty()) seeing.push_back(c);
  }
  const CameraHealth& a = health_[seeing[0]];
  const CameraHealth& b = health_[seeing[1]];
  const double suspicious = kSuspectFraction * options_.drift_px;
  if (a.average_error_px > suspicious && b.average_error_px < suspicious / 2) return seeing[0];
  if (b.average_error_px > suspicious && a.average_error_px < suspicious / 2) return seeing[1];
  if (fused_prediction == nullptr) return views.size();
  // Off where the track puts the body: its error goes into its residuals (the prediction rests
  // on other cameras' poses), so that it stays the suspect once the track goes on from the
  // other camera alone.
  const double error_a = view_median_error_px(views[seeing[0]], *fused_prediction);
  const double error_b = view_median_error_px(views[seeing[1]], *fused_prediction);
  const double on = options_.fusion.max_reprojection_rms_px;
  if (error_a > options_.drift_px && error_b <= on) {
    record_residual(seeing[0], error_a);
    return seeing[0];
  }
  if (error_b > options_.drift_px && error_a <= on) {
    record_residual(seeing[1], error_b);
    return seeing[1];
  }
  return views.size();
}

MultiCameraPose VolumeTracker::fit_without_outliers(std::vector<CameraView>& views,
                                                    const Eigen::Isometry3d& start) const {
  MultiCameraPose fused = estimate_multi_camera_pose(views, start, options_.fusion);
  if (fused.valid || !(fused.reprojection_rms_px > 0)) return fused;
  std::vector<CameraView> kept =
      without_outliers(views, fused.world_from_body,
                       kOutlierFactor * options_.fusion.max_reprojection_rms_px, Units::Pixels);
  const int points = points_in(kept);
  if (points < options_.fusion.min_points || points == points_in(views)) return fused;
  MultiCameraPose again = estimate_multi_camera_pose(kept, fused.world_from_body, options_.fusion);
  if (!again.valid) return fused;
  views = std::move(kept);
  return again;
}

bool VolumeTracker::without_worst_points(std::vector<CameraView>& views, MultiCameraPose& fused,
                                         double usual_normalized_rms) const {
  std::vector<CameraView> kept = views;
  MultiCameraPose fit = fused;
  for (int removed = 0; removed < kMostWorstPoints; ++removed) {
    size_t worst_view = 0, worst_point = 0;
    double worst = -1;
    for (size_t v = 0; v < kept.size(); ++v) {
      const std::vector<double> errors = point_errors_sigmas(kept[v], fit.world_from_body);
      for (size_t i = 0; i < errors.size(); ++i) {
        if (errors[i] > worst) {
          worst = errors[i];
          worst_view = v;
          worst_point = i;
        }
      }
    }
    if (worst < 0 || points_in(kept) <= options_.fusion.min_points) return false;
    CameraView& view = kept[worst_view];
    view.body_points.erase(view.body_points.begin() + static_cast<long>(worst_point));
    view.pixels.erase(view.pixels.begin() + static_cast<long>(worst_point));
    view.pixel_sigma_px.erase(view.pixel_sigma_px.begin() + static_cast<long>(worst_point));
    fit = estimate_multi_camera_pose(kept, fit.world_from_body, options_.fusion);
    if (!fit.valid) return false;
    if (fit.normalized_rms <= kElevatedRmsFactor * expected_rms(usual_normalized_rms)) {
      views = std::move(kept);
      fused = std::move(fit);
      return true;
    }
  }
  return false;
}

std::optional<size_t> VolumeTracker::disagreeing_view(const std::vector<CameraView>& views,
                                                      MultiCameraPose& fused,
                                                      double usual_normalized_rms,
                                                      size_t suspect) const {
  // What each view adds to the fit's chi-square, per residual of its own: about one for a view
  // that agrees with the others (in units of the usual), far more for one that does not.
  const double usual = expected_rms(usual_normalized_rms);
  const double chi_square = fused.normalized_rms * fused.normalized_rms * 2 * fused.points_used;
  std::optional<size_t> worst;
  MultiCameraPose worst_fit;
  double worst_added = kDisagreeingSigmas * kDisagreeingSigmas * usual * usual;
  for (size_t v = 0; v < views.size(); ++v) {
    if (views[v].pixels.empty() || (suspect < views.size() && v != suspect)) continue;
    std::vector<CameraView> others = views;
    empty_view(others[v]);
    if (points_in(others) < options_.fusion.min_points) continue;
    MultiCameraPose fit =
        estimate_multi_camera_pose(others, fused.world_from_body, options_.fusion);
    if (!fit.valid || fit.normalized_rms > kElevatedRmsFactor * usual) continue;
    const double added =
        (chi_square - fit.normalized_rms * fit.normalized_rms * 2 * fit.points_used) /
        (2 * static_cast<double>(views[v].pixels.size()));
    if (added > worst_added) {
      worst = v;
      worst_fit = std::move(fit);
      worst_added = added;
    }
  }
  if (worst) fused = std::move(worst_fit);
  return worst;
}

void VolumeTracker::trim_strays(std::vector<CameraView>& views, MultiCameraPose& fused) const {
  std::vector<double> errors;
  for (const CameraView& view : views) {
    const std::vector<double> view_errors = point_errors_sigmas(view, fused.world_from_body);
    errors.insert(errors.end(), view_errors.begin(), view_errors.end());
  }
  if (errors.empty()) return;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const double limit = std::max(kStrayFloorSigmas, kStrayFactor * errors[errors.size() / 2]);
  std::vector<CameraView> kept =
      without_outliers(views, fused.world_from_body, limit, Units::Sigmas);
  const int points = points_in(kept);
  if (points == points_in(views) || points < options_.fusion.min_points) return;
  MultiCameraPose again = estimate_multi_camera_pose(kept, fused.world_from_body, options_.fusion);
  if (!again.valid) return;
  views = std::move(kept);
  fused = std::move(again);
}

bool VolumeTracker::unusually_poor(const Fused& fit, double usual_normalized_rms) {
  return fit.pose.normalized_rms > kUnusualRmsFactor * expected_rms(usual_normalized_rms);
}

void VolumeTracker::take(const std::vector<std::vector<Eigen::Vector2d>>& used,
                         std::vector<CameraDetections>& detections) {
  for (size_t c = 0; c < used.size(); ++c) {
    std::vector<Eigen::Vector2d>& pixels = detections[c].pixels;
    std::vector<double>& sigmas = detections[c].pixel_sigma_px;
    for (const Eigen::Vector2d& pixel : used[c]) {
      auto it = std::find(pixels.begin(), pixels.end(), pixel);
      if (it == pixels.end()) continue;
      if (!sigmas.empty()) sigmas.erase(sigmas.begin() + (it - pixels.begin()));
      pixels.erase(it);
    }
  }
}

void VolumeTracker::record_residual(size_t camera, double error_px) {
  // Clipped, so that one wild view (a marker taken for another) does not make a camera drifted:
  // it takes several views in a row well above the threshold.
  error_px = std::min(error_px, 2 * options_.drift_px);
  CameraHealth& health = health_[camera];
  health.average_error_px = health.views == 0 ? error_px
                                              : (1 - kResidualSmoothing) * health.average_error_px +
                                                    kResidualSmoothing * error_px;
  ++health.views;
  if (health.views >= kViewsBeforeDriftCall && health.average_error_px > options_.drift_px) {
    health.drifted = true;
  }
}

TrackedBodyPose VolumeTracker::update_track(size_t body, int64_t stamp_ns,
                                            const MultiCameraPose& fused) {
  std::optional<Track>& track = tracks_[body];
  if (!track) track.emplace();
  Track& next = *track;
  next.world_from_body = fused.world_from_body;
  next.stamp_ns = stamp_ns;
  next.cameras_used = fused.cameras_used;
  auto follow = [&](double& usual) {
    usual = usual == 0
                ? fused.normalized_rms
                : (1 - kUsualRmsSmoothing) * usual + kUsualRmsSmoothing * fused.normalized_rms;
  };
  follow(next.usual_normalized_rms);
  follow(usual_normalized_rms_);
  next.history.emplace_back(stamp_ns, fused.world_from_body);
  while (next.history.size() > 2 &&
         static_cast<double>(stamp_ns - next.history[1].first) * 1e-9 >= kVelocityWindow_s) {
    next.history.pop_front();
  }
  // The velocity over the window's poses, oldest to newest: steadier than one frame's step.
  const auto& [oldest_ns, oldest] = next.history.front();
  if (stamp_ns > oldest_ns) {
    const double dt_s = static_cast<double>(stamp_ns - oldest_ns) * 1e-9;
    next.linear_velocity = (fused.world_from_body.translation() - oldest.translation()) / dt_s;
    const Eigen::AngleAxisd turn(fused.world_from_body.linear() * oldest.linear().transpose());
    next.angular_velocity = turn.axis() * turn.angle() / dt_s;
    next.velocity_known = true;
    // A difference of two poses over dt: twice a pose's variance over dt squared.
    next.velocity_covariance = 2 * fused.covariance / (dt_s * dt_s);
  }

  TrackedBodyPose pose;
  pose.name = bodies_.bodies[body].name;
  pose.world_from_body = fused.world_from_body;
  pose.covariance = fused.covariance;
  pose.linear_velocity = next.linear_velocity;
  pose.angular_velocity = next.angular_velocity;
  pose.velocity_known = next.velocity_known;
  pose.velocity_covariance = next.velocity_covariance;
  pose.reprojection_rms_px = fused.reprojection_rms_px;
  pose.normalized_rms = fused.normalized_rms;
  pose.cameras_used = fused.cameras_used;
  pose.points_used = fused.points_used;
  return pose;
}

std::vector<MarkerOwner> owners_of(const std::vector<CloudMarker>& cloud,
                                   const std::vector<PlacedBody>& bodies, double radius_m) {
  std::vector<MarkerOwner> owners(cloud.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    for (size_t k = 0; k < bodies[b].markers->size(); ++k) {
      const Eigen::Vector3d at = bodies[b].world_from_body * (*bodies[b].markers)[k];
      size_t nearest = cloud.size();
      double nearest_m = radius_m;
      for (size_t m = 0; m < cloud.size(); ++m) {
        const double off = (cloud[m].position - at).norm();
        if (owners[m].body < 0 && off <= nearest_m) {
          nearest = m;
          nearest_m = off;
        }
      }
      if (nearest < cloud.size()) owners[nearest] = {static_cast<int>(b), static_cast<int>(k)};
    }
  }
  return owners;
}

}  // namespace mocap::volume
