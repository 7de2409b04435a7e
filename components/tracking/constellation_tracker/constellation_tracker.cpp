#include "tracking/constellation_tracker/constellation_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "tracking/constellation_database/cross_ratio.hpp"
#include "tracking/constellation_tracker/marker_association.hpp"

namespace mocap::tracking {
namespace {

using constellations::ConstellationModel;
using constellations::IdentifiedConstellation;
using constellations::IdentifiedLine;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// How a marker's image moves with a small change of the pose (translation, rotation vector in
// the camera frame, as PlanarPose::covariance): 2x6, by differences through the camera model.
std::optional<Eigen::Matrix<double, 2, 6>> image_jacobian(const calibration::CameraModel& camera,
                                                          const Eigen::Vector3d& position,
                                                          const Eigen::Vector3d& lever,
                                                          const Eigen::Vector2d& pixel) {
  // d(position)/d(pose) = [I, -[lever]x], lever = the marker's offset from the body's origin.
  Eigen::Matrix<double, 2, 3> projection;
  const double h = 1e-6 * std::max(1.0, position.norm());
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d moved = position;
    moved(k) += h;
    auto shifted = camera.project(moved);
    if (!shifted) return std::nullopt;
    projection.col(k) = (*shifted - pixel) / h;
  }
  Eigen::Matrix<double, 3, 6> motion;
  motion.leftCols<3>().setIdentity();
  motion.rightCols<3>() << 0, lever.z(), -lever.y(), -lever.z(), 0, lever.x(), lever.y(),
      -lever.x(), 0;
  return projection * motion;
}

// Whole lines among the identified markers, with their cross-ratios measured on the rays
// (without the lens's distortion, as identification measures them).
std::vector<IdentifiedLine> whole_lines(const calibration::CameraModel& camera,
                                        const ConstellationModel& model,
                                        const std::vector<int>& image_point_of,
                                        const std::vector<Eigen::Vector2d>& fiducials) {
  std::vector<IdentifiedLine> lines;
  for (size_t l = 0; l < model.lines.size(); ++l) {
    IdentifiedLine line;
    line.model_line = static_cast<int>(l);
    std::array<Eigen::Vector2d, 4> rays;
    bool whole = true;
    for (int k = 0; k < 4 && whole; ++k) {
      line.image_points[k] = image_point_of[model.lines[l].points[k]];
      auto ray = line.image_points[k] >= 0 ? camera.unproject(fiducials[line.image_points[k]])
                                           : std::nullopt;
      whole = ray.has_value();
      if (whole) rays[k] = ray->head<2>();
    }
    if (!whole) continue;
    line.cross_ratio = constellations::cross_ratio(rays[0], rays[1], rays[2], rays[3]);
    lines.push_back(line);
  }
  return lines;
}

// A measured pose's covariance as the motion filter takes it. It comes from the fit's own
// residuals; a floor of a tenth of a pixel keeps a lucky, nearly perfect fit from freezing the
// filter.
Matrix6d measurement_covariance(const pose::PlanarPose& pose) {
  constexpr double kFloorPx = 0.1;
  const double rms = std::max(pose.reprojection_rms_px, 1e-9);
  return rms < kFloorPx ? Matrix6d(pose.covariance * (kFloorPx * kFloorPx) / (rms * rms))
                        : pose.covariance;
}

// The model points and the pixels of an identification's markers, pair by pair.
std::vector<Eigen::Vector3d> marker_points(const IdentifiedConstellation& found) {
  std::vector<Eigen::Vector3d> points;
  for (size_t m = 0; m < found.image_point_of.size(); ++m) {
    if (found.image_point_of[m] >= 0) points.push_back(found.model->points[m]);
  }
  return points;
}

std::vector<Eigen::Vector2d> marker_pixels(const IdentifiedConstellation& found,
                                           const std::vector<Eigen::Vector2d>& fiducials) {
  std::vector<Eigen::Vector2d> pixels;
  for (int i : found.image_point_of) {
    if (i >= 0) pixels.push_back(fiducials[i]);
  }
  return pixels;
}

}  // namespace

const char* to_string(PoseSource source) {
  switch (source) {
    case PoseSource::Tracked:
      return "tracked";
    case PoseSource::Identified:
      return "identified";
    case PoseSource::FromOneLine:
      return "one line";
  }
  return "?";
}

struct ConstellationTracker::Candidate {
  const ConstellationModel* model = nullptr;
  PoseSource source = PoseSource::Tracked;
  int track = -1;  // index into tracks_; -1 for a board found by identification
  IdentifiedConstellation identified;
  pose::PlanarPose pose;
  std::vector<MarkerImage> images;  // every marker at the pose
  std::string rejection;            // why not believed; empty when it is
  bool relocked = false;            // found by an image shift: its motion starts afresh
};

std::optional<std::string> TrackerOptions::problem() const {
  if (auto problem = identification.problem()) return "identification." + *problem;
  if (auto problem = pose.problem()) return "pose." + *problem;
  if (auto problem = motion.problem()) return "motion." + *problem;
  if (auto problem = visibility.problem()) return "visibility." + *problem;
  // The association's covariances are inverted: each needs the fiducial's own share.
  if (!(fiducial_sigma_px > 0)) {
    return fmt::format("fiducial_sigma_px: {} is not above 0", fiducial_sigma_px);
  }
  if (!(association_gate > 0)) {
    return fmt::format("association_gate: {} is not above 0", association_gate);
  }
  if (!(max_motion_surprise > 0)) {
    return fmt::format("max_motion_surprise: {} is not above 0", max_motion_surprise);
  }
  // Both replace pose.min_points for their fits, which take four at least.
  if (min_tracked_markers < 4) {
    return fmt::format("min_tracked_markers: {}; four markers at least fix a plane's pose",
                       min_tracked_markers);
  }
  // Compared squared: a negative radius would pass for its opposite.
  if (!(relock_radius_px >= 0)) {
    return fmt::format("relock_radius_px: {} is below 0", relock_radius_px);
  }
  if (relock_min_markers < 4) {
    return fmt::format("relock_min_markers: {}; four markers at least fix a plane's pose",
                       relock_min_markers);
  }
  if (!(max_marker_error_px > 0)) {
    return fmt::format("max_marker_error_px: {} is not above 0", max_marker_error_px);
  }
  if (!(merge_distance_px >= 0)) {
    return fmt::format("merge_distance_px: {} is below 0", merge_distance_px);
  }
  if (spare_missing_markers < 0) {
    return fmt::format("spare_missing_markers: {} is below 0", spare_missing_markers);
  }
  if (!(side_tolerance_px >= 0)) {
    return fmt::format("side_tolerance_px: {} is below 0", side_tolerance_px);
  }
  // Above 1 no size would fit: at least min_size_ratio and at most its inverse of the median.
  if (!(min_size_ratio >= 0 && min_size_ratio <= 1)) {
    return fmt::format("min_size_ratio: {} is not in [0, 1]", min_size_ratio);
  }
  return std::nullopt;
}

ConstellationTracker::ConstellationTracker(const constellations::ConstellationDatabase& database,
                                           std::shared_ptr<const calibration::CameraModel> camera,
                                           TrackerOptions options)
    : database_(database),
      camera_(std::move(camera)),
      options_([&] {
        if (auto problem = options.problem()) {
          throw std::invalid_argument("TrackerOptions::" + *problem);
        }
        options.identification.focal_length_px = camera_ ? camera_->focal_length_px() : 0;
        return options;
      }()),
      identifier_(database, options_.identification) {
  if (!camera_) throw std::invalid_argument("ConstellationTracker: no camera model");
}

// One frame: follow the tracks (predict, associate; seed 000 §7.4.3) and verify them, identify
// the boards no track holds and verify those, then update the tracks. Kept whole (about 90
// lines) so that the order reads in one place; each step is a function of its own.
std::vector<TrackedConstellation> ConstellationTracker::update(
    int64_t stamp_ns, const std::vector<ImageFiducial>& detected, TrackerStats* stats_out) {
  pixels_.resize(detected.size());
  for (size_t i = 0; i < detected.size(); ++i) pixels_[i] = detected[i].pixel;
  const std::vector<Eigen::Vector2d>& fiducials = pixels_;
  TrackerStats local;
  TrackerStats& stats = stats_out ? *stats_out : local;
  stats = {};
  if (stamp_ns < last_stamp_ns_) tracks_.clear();
  last_stamp_ns_ = stamp_ns;

  std::vector<Candidate> candidates;
  follow_tracks(stamp_ns, detected, candidates, stats);

  // Who holds which fiducial; a board whose pose fails its check lets its go.
  std::vector<int> owner(fiducials.size(), -1);
  auto claim = [&](size_t c) {
    for (int i : candidates[c].identified.image_point_of) {
      if (i >= 0) owner[i] = static_cast<int>(c);
    }
  };
  // Candidates from `first` on claim their fiducials, then each is checked against all.
  auto verify_from = [&](size_t first) {
    for (size_t c = first; c < candidates.size(); ++c) claim(c);
    for (size_t c = first; c < candidates.size(); ++c) {
      Candidate& candidate = candidates[c];
      candidate.rejection = verify(candidate, candidates, fiducials, owner);
      if (candidate.rejection.empty()) continue;
      for (int& o : owner) {
        if (o == static_cast<int>(c)) o = -1;
      }
    }
  };
  verify_from(0);

  std::vector<bool> claimed(fiducials.size());
  for (size_t i = 0; i < fiducials.size(); ++i) claimed[i] = owner[i] >= 0;
  const size_t tracked_count = candidates.size();
  identify_others(fiducials, claimed, candidates, stats);
  verify_from(tracked_count);

  // The tracks go on with what was believed; the rest are dropped.
  std::vector<Track> next_tracks;
  std::vector<TrackedConstellation> result;
  for (Candidate& candidate : candidates) {
    if (!candidate.rejection.empty()) {
      ++stats.rejected;
      stats.rejections.push_back(candidate.model->name + ": " + candidate.rejection);
      continue;
    }
    const Matrix6d measured = measurement_covariance(candidate.pose);
    if (candidate.track >= 0) {
      Track track = std::move(tracks_[candidate.track]);
      if (candidate.relocked) {
        track.motion = BodyMotionFilter(candidate.pose.camera_from_object, measured, stamp_ns,
                                        options_.motion);
        ++stats.relocked;
      } else {
        track.motion.correct(stamp_ns, candidate.pose.camera_from_object, measured);
      }
      ++track.frames;
      next_tracks.push_back(std::move(track));
      ++stats.tracked;
    } else {
      next_tracks.push_back(
          {candidate.model,
           BodyMotionFilter(candidate.pose.camera_from_object, measured, stamp_ns, options_.motion),
           next_track_id_++, 1});
      ++stats.identified;
      stats.from_one_line += candidate.source == PoseSource::FromOneLine;
    }
    const Track& track = next_tracks.back();
    TrackedConstellation out;
    out.identified = std::move(candidate.identified);
    if (candidate.source == PoseSource::Tracked) {
      out.identified.lines =
          whole_lines(*camera_, *candidate.model, out.identified.image_point_of, fiducials);
    }
    out.source = candidate.source;
    out.pose = candidate.pose;
    out.motion = track.motion.state();
    out.track_id = track.id;
    out.frames_tracked = track.frames;
    result.push_back(std::move(out));
  }
  tracks_ = std::move(next_tracks);
  const auto& models = database_.constellations();
  std::sort(result.begin(), result.end(), [&](const auto& a, const auto& b) {
    return a.identified.model - models.data() < b.identified.model - models.data();
  });
  return result;
}

void ConstellationTracker::follow_tracks(int64_t stamp_ns,
                                         const std::vector<ImageFiducial>& detected,
                                         std::vector<Candidate>& candidates, TrackerStats& stats) {
  const std::vector<Eigen::Vector2d>& fiducials = pixels_;
  std::vector<BodyState> predicted(tracks_.size());
  for (size_t t = 0; t < tracks_.size(); ++t) {
    predicted[t] = tracks_[t].motion.predicted(stamp_ns);
  }
  // A track whose velocity is not measured yet (one frame old, or restarted) predicts loosely:
  // its pattern shifted by a marker's spacing can lie nearer the prediction than the true one.
  // Its gated association is therefore weighed against the picture's shift (relock), below.
  auto settled = [&](size_t t) { return tracks_[t].motion.corrections() > 1; };
  // Every tracked board's markers where the camera should see them now.
  std::vector<PredictedMarker> predictions;
  std::vector<std::pair<int, int>> predicted_marker;  // (track, marker) of each prediction
  predict_markers(predicted, predictions, predicted_marker);
  const std::vector<int> fiducial_of =
      associate_markers(predictions, fiducials, options_.association_gate);

  std::vector<std::vector<int>> image_point_of(tracks_.size());
  for (size_t t = 0; t < tracks_.size(); ++t) {
    image_point_of[t].assign(tracks_[t].model->points.size(), -1);
  }
  std::vector<int> track_of_fiducial(fiducials.size(), -1);
  for (size_t p = 0; p < predictions.size(); ++p) {
    image_point_of[predicted_marker[p].first][predicted_marker[p].second] = fiducial_of[p];
    if (fiducial_of[p] >= 0) track_of_fiducial[fiducial_of[p]] = predicted_marker[p].first;
  }

  for (size_t t = 0; t < tracks_.size(); ++t) {
    const ConstellationModel& model = *tracks_[t].model;
    std::vector<int>& image_of = image_point_of[t];
    Candidate candidate;
    candidate.model = &model;
    candidate.track = static_cast<int>(t);
    fit_associated(t, predicted[t], detected, image_of, candidate.pose);
    if (candidate.pose.valid &&
        tracks_[t].motion.surprise(stamp_ns, candidate.pose.camera_from_object,
                                   measurement_covariance(candidate.pose)) >
            options_.max_motion_surprise) {
      candidate.pose.valid = false;
      candidate.pose.rejection = "it moved further than its motion allows";
    }
    if (!candidate.pose.valid) {
      // Lost by its prediction: the picture may have moved as a whole.
      candidate.relocked =
          find_shifted(t, predicted[t], track_of_fiducial, candidate.pose, image_of) && settled(t);
    } else if (!settled(t)) {
      // A loose prediction: the shift's markers win when they are more, or as many and fit
      // better.
      pose::PlanarPose shifted;
      std::vector<int> shifted_image_of;
      if (find_shifted(t, predicted[t], track_of_fiducial, shifted, shifted_image_of) &&
          (shifted.points_used > candidate.pose.points_used ||
           (shifted.points_used == candidate.pose.points_used &&
            shifted.reprojection_rms_px < candidate.pose.reprojection_rms_px))) {
        candidate.pose = shifted;
        image_of = shifted_image_of;
      }
    }
    if (candidate.pose.valid) {
      for (int i : image_of) {
        if (i >= 0) track_of_fiducial[i] = static_cast<int>(t);
      }
    }
    if (!candidate.pose.valid) {
      ++stats.lost;
      stats.rejections.push_back(model.name + ": " + candidate.pose.rejection);
      continue;
    }
    candidate.identified.model = &model;
    candidate.identified.image_point_of = image_of;
    candidate.images =
        marker_images(*camera_, model, candidate.pose.camera_from_object, options_.visibility);
    candidates.push_back(std::move(candidate));
  }
}

void ConstellationTracker::predict_markers(const std::vector<BodyState>& predicted,
                                           std::vector<PredictedMarker>& markers,
                                           std::vector<std::pair<int, int>>& track_marker) const {
  const double fiducial_variance = options_.fiducial_sigma_px * options_.fiducial_sigma_px;
  for (size_t t = 0; t < tracks_.size(); ++t) {
    const Eigen::Isometry3d& pose = predicted[t].camera_from_body;
    const Matrix6d pose_covariance = predicted[t].pose_covariance();
    const ConstellationModel& model = *tracks_[t].model;
    const auto images = marker_images(*camera_, model, pose, options_.visibility);
    for (size_t m = 0; m < model.points.size(); ++m) {
      if (images[m].sight != MarkerSight::InView) continue;
      // A marker behind another tracked board is not looked for: boards are opaque.
      bool covered = false;
      for (size_t u = 0; u < tracks_.size() && !covered; ++u) {
        covered = u != t && behind_board(pose * model.points[m], *tracks_[u].model,
                                         predicted[u].camera_from_body);
      }
      if (covered) continue;
      const Eigen::Vector3d lever = pose.linear() * model.points[m];
      auto jacobian = image_jacobian(*camera_, pose * model.points[m], lever, images[m].pixel);
      if (!jacobian) continue;
      PredictedMarker marker;
      marker.pixel = images[m].pixel;
      marker.covariance = *jacobian * pose_covariance * jacobian->transpose() +
                          fiducial_variance * Eigen::Matrix2d::Identity();
      markers.push_back(marker);
      track_marker.emplace_back(static_cast<int>(t), static_cast<int>(m));
    }
  }
}

bool ConstellationTracker::find_shifted(size_t t, const BodyState& predicted,
                                        const std::vector<int>& track_of_fiducial,
                                        pose::PlanarPose& pose_out,
                                        std::vector<int>& image_of) const {
  const std::vector<Eigen::Vector2d>& fiducials = pixels_;
  std::vector<bool> taken(fiducials.size());
  for (size_t i = 0; i < fiducials.size(); ++i) {
    taken[i] = track_of_fiducial[i] >= 0 && track_of_fiducial[i] != static_cast<int>(t);
  }
  const ConstellationModel& model = *tracks_[t].model;
  const auto images =
      marker_images(*camera_, model, predicted.camera_from_body, options_.visibility);
  auto found = relock(model, images, fiducials, taken);
  if (!found) return false;
  pose::PlanarPoseOptions relock_options = options_.pose;
  relock_options.min_points = options_.relock_min_markers;
  IdentifiedConstellation shifted;
  shifted.model = &model;
  shifted.image_point_of = *found;
  pose::PlanarPose pose = pose::estimate_planar_pose(
      *camera_, marker_points(shifted), marker_pixels(shifted, fiducials), relock_options);
  if (!pose.valid) return false;
  pose_out = pose;
  image_of = *found;
  return true;
}

std::optional<std::vector<int>> ConstellationTracker::relock(
    const ConstellationModel& model, const std::vector<MarkerImage>& images,
    const std::vector<Eigen::Vector2d>& fiducials, const std::vector<bool>& taken) const {
  // Every (marker, free fiducial) pair within reach names a shift; the shift most markers agree
  // on (within the association's tolerance) is the picture's movement.
  constexpr double kAgreementPx = 2.5;
  struct Shift {
    Eigen::Vector2d offset;
    int marker, fiducial;
  };
  std::vector<Shift> shifts;
  const double reach2 = options_.relock_radius_px * options_.relock_radius_px;
  for (size_t m = 0; m < images.size(); ++m) {
    if (images[m].sight != MarkerSight::InView) continue;
    for (size_t i = 0; i < fiducials.size(); ++i) {
      if (taken[i] || !fiducials[i].allFinite()) continue;
      const Eigen::Vector2d offset = fiducials[i] - images[m].pixel;
      if (offset.squaredNorm() <= reach2) {
        shifts.push_back({offset, static_cast<int>(m), static_cast<int>(i)});
      }
    }
  }
  std::optional<Eigen::Vector2d> best;
  int best_support = options_.relock_min_markers - 1;
  std::vector<bool> marker_counted(images.size());
  for (const Shift& candidate : shifts) {
    std::fill(marker_counted.begin(), marker_counted.end(), false);
    int support = 0;
    for (const Shift& other : shifts) {
      if (marker_counted[other.marker] ||
          (other.offset - candidate.offset).squaredNorm() > kAgreementPx * kAgreementPx) {
        continue;
      }
      marker_counted[other.marker] = true;
      ++support;
    }
    if (support > best_support) {
      best_support = support;
      best = candidate.offset;
    }
  }
  if (!best) return std::nullopt;
  // Each marker, shifted, takes the nearest free fiducial within the tolerance.
  std::vector<int> image_of(model.points.size(), -1);
  std::vector<bool> used = taken;
  int found = 0;
  for (size_t m = 0; m < images.size(); ++m) {
    if (images[m].sight != MarkerSight::InView) continue;
    const Eigen::Vector2d at = images[m].pixel + *best;
    int nearest = -1;
    double nearest_distance = kAgreementPx;
    for (size_t i = 0; i < fiducials.size(); ++i) {
      if (used[i] || !fiducials[i].allFinite()) continue;
      const double distance = (fiducials[i] - at).norm();
      if (distance <= nearest_distance) {
        nearest = static_cast<int>(i);
        nearest_distance = distance;
      }
    }
    if (nearest < 0) continue;
    image_of[m] = nearest;
    used[nearest] = true;
    ++found;
  }
  if (found < options_.relock_min_markers) return std::nullopt;
  return image_of;
}

std::vector<bool> ConstellationTracker::whole_markers(
    const ConstellationModel& model, const Eigen::Isometry3d& pose,
    const std::vector<int>& image_of, const std::vector<ImageFiducial>& detected) const {
  std::vector<bool> whole(model.points.size(), true);
  if (!(options_.min_size_ratio > 0)) return whole;
  // Each size against what the marker's depth and angle lead to expect: a flat disc's image
  // shrinks with the square of its distance and with the cosine of its angle to the ray.
  const Eigen::Vector3d normal = pose.linear().col(2);
  std::vector<double> ratio(model.points.size(), 0);
  std::vector<double> ratios;
  for (size_t m = 0; m < model.points.size(); ++m) {
    if (image_of[m] < 0 || !(detected[image_of[m]].size > 0)) continue;
    const Eigen::Vector3d position = pose * model.points[m];
    const double distance = position.norm();
    const double cosine = std::max(0.1, normal.dot(-position) / distance);
    ratio[m] = detected[image_of[m]].size * distance * distance / cosine;
    ratios.push_back(ratio[m]);
  }
  if (ratios.size() < 3) return whole;
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  const double median = ratios[ratios.size() / 2];
  for (size_t m = 0; m < model.points.size(); ++m) {
    if (ratio[m] > 0) {
      whole[m] = ratio[m] >= options_.min_size_ratio * median &&
                 ratio[m] * options_.min_size_ratio <= median;
    }
  }
  return whole;
}

void ConstellationTracker::fit_associated(size_t t, const BodyState& predicted,
                                          const std::vector<ImageFiducial>& detected,
                                          std::vector<int>& image_of,
                                          pose::PlanarPose& pose) const {
  const ConstellationModel& model = *tracks_[t].model;
  const std::vector<Eigen::Vector2d>& fiducials = pixels_;
  const std::vector<bool> in_fit =
      whole_markers(model, predicted.camera_from_body, image_of, detected);
  pose::PlanarPoseOptions options = options_.pose;
  options.min_points = options_.min_tracked_markers;
  // Fit, then take out the worst marker while one is further than the bound from its
  // reprojection (a distractor taken for a hidden marker), and fit again.
  while (true) {
    std::vector<Eigen::Vector3d> object;
    std::vector<Eigen::Vector2d> image;
    std::vector<int> marker_of_pair;
    for (size_t m = 0; m < image_of.size(); ++m) {
      if (image_of[m] < 0 || !in_fit[m]) continue;
      object.push_back(model.points[m]);
      image.push_back(fiducials[image_of[m]]);
      marker_of_pair.push_back(static_cast<int>(m));
    }
    if (static_cast<int>(object.size()) < options_.min_tracked_markers) {
      pose = {};
      pose.rejection = fmt::format("{} markers associated, {} needed", object.size(),
                                   options_.min_tracked_markers);
      return;
    }
    pose = pose::refine_planar_pose(*camera_, predicted.camera_from_body, object, image, options);
    if (pose.points_used != static_cast<int>(object.size())) return;
    int worst = -1;
    double worst_error = options_.max_marker_error_px;
    for (size_t k = 0; k < object.size(); ++k) {
      auto at = camera_->project(pose.camera_from_object * object[k]);
      const double error = at ? (*at - image[k]).norm() : std::numeric_limits<double>::infinity();
      if (error > worst_error) {
        worst_error = error;
        worst = marker_of_pair[k];
      }
    }
    if (worst < 0) return;
    image_of[worst] = -1;
  }
}

void ConstellationTracker::identify_others(const std::vector<Eigen::Vector2d>& fiducials,
                                           const std::vector<bool>& claimed,
                                           std::vector<Candidate>& candidates,
                                           TrackerStats& stats) {
  const auto& models = database_.constellations();
  std::vector<bool> known(models.size(), false);
  for (const Candidate& candidate : candidates) {
    if (candidate.rejection.empty()) known[candidate.model - models.data()] = true;
  }
  if (std::all_of(known.begin(), known.end(), [](bool k) { return k; })) return;
  stats.identification_ran = true;
  // Lines are straight only without lens distortion: the identifier sees ideal pixels.
  const double focal = camera_->focal_length_px();
  ideal_.resize(fiducials.size());
  for (size_t i = 0; i < fiducials.size(); ++i) {
    ideal_[i] = Eigen::Vector2d::Constant(kNaN);
    if (claimed[i] || !fiducials[i].allFinite()) continue;
    if (auto ray = camera_->unproject(fiducials[i])) ideal_[i] = focal * ray->head<2>();
  }
  std::vector<IdentifiedConstellation> found_boards = identifier_.identify(ideal_);
  // Fiducials taken: by tracks, or by a board identified here.
  std::vector<bool> used = claimed;
  for (const IdentifiedConstellation& found : found_boards) {
    for (int i : found.image_point_of) {
      if (i >= 0) used[i] = true;
    }
  }
  for (IdentifiedConstellation& found : found_boards) {
    if (known[found.model - models.data()]) continue;
    Candidate candidate;
    candidate.model = found.model;
    candidate.source = found.from_one_line ? PoseSource::FromOneLine : PoseSource::Identified;
    candidate.pose = pose::estimate_planar_pose(*camera_, marker_points(found),
                                                marker_pixels(found, fiducials), options_.pose);
    if (!candidate.pose.valid) {
      ++stats.rejected;
      stats.rejections.push_back(candidate.model->name + ": " + candidate.pose.rejection);
      continue;
    }
    // The pose from the identified markers places the others: those that land on a free
    // fiducial join, and the pose is fitted again with them.
    bool completed = false;
    const auto images = marker_images(*camera_, *found.model, candidate.pose.camera_from_object,
                                      options_.visibility);
    for (size_t m = 0; m < images.size(); ++m) {
      if (found.image_point_of[m] >= 0 || images[m].sight != MarkerSight::InView) continue;
      int nearest = -1;
      double nearest_distance = options_.max_marker_error_px;
      for (size_t i = 0; i < fiducials.size(); ++i) {
        if (used[i] || !fiducials[i].allFinite()) continue;
        const double distance = (fiducials[i] - images[m].pixel).norm();
        if (distance <= nearest_distance) {
          nearest = static_cast<int>(i);
          nearest_distance = distance;
        }
      }
      if (nearest < 0) continue;
      found.image_point_of[m] = nearest;
      used[nearest] = true;
      completed = true;
    }
    if (completed) {
      pose::PlanarPose refined = pose::refine_planar_pose(
          *camera_, candidate.pose.camera_from_object, marker_points(found),
          marker_pixels(found, fiducials), options_.pose);
      if (refined.valid) candidate.pose = refined;
    }
    candidate.identified = std::move(found);
    candidate.images = marker_images(*camera_, *candidate.model, candidate.pose.camera_from_object,
                                     options_.visibility);
    candidates.push_back(std::move(candidate));
  }
}

std::string ConstellationTracker::verify(const Candidate& candidate,
                                         const std::vector<Candidate>& others,
                                         const std::vector<Eigen::Vector2d>& fiducials,
                                         const std::vector<int>& owner) const {
  const ConstellationModel& model = *candidate.model;
  const Eigen::Isometry3d& pose = candidate.pose.camera_from_object;
  const int self = static_cast<int>(&candidate - others.data());
  std::vector<Eigen::Vector2d> seen, unexplained;
  for (size_t m = 0; m < model.points.size(); ++m) {
    const MarkerImage& image = candidate.images[m];
    const int fiducial = candidate.identified.image_point_of[m];
    if (fiducial >= 0) {
      // A marker found where the pose turns it away from the camera: the pose is wrong.
      if (image.sight == MarkerSight::BehindCamera ||
          (pose.linear().col(2).dot(-(pose * model.points[m])) < 0)) {
        return "the pose turns found markers away from the camera";
      }
      seen.push_back(fiducials[fiducial]);
      continue;
    }
    if (image.sight != MarkerSight::InView) continue;
    // Merged with, or under, a fiducial that is not this board's.
    bool hidden = false;
    for (size_t i = 0; i < fiducials.size() && !hidden; ++i) {
      hidden = owner[i] != self && fiducials[i].allFinite() &&
               (fiducials[i] - image.pixel).norm() <= options_.merge_distance_px;
    }
    // Behind another board believed this frame.
    for (size_t o = 0; o < others.size() && !hidden; ++o) {
      const Candidate& other = others[o];
      if (static_cast<int>(o) == self || !other.rejection.empty()) continue;
      hidden = behind_board(pose * model.points[m], *other.model, other.pose.camera_from_object);
    }
    if (!hidden) unexplained.push_back(image.pixel);
  }
  if (!one_band_covers(unexplained, seen, options_.spare_missing_markers)) {
    return fmt::format("{} of its markers are missing in plain view ({} found)", unexplained.size(),
                       seen.size());
  }
  // Fiducials on its sides where it has no marker: a board found by one line could be another
  // board of the same size hinged on a side of the same line type, whose markers lie there.
  // One could be a stray light; two are the other board's.
  if (candidate.source != PoseSource::FromOneLine) return {};
  int on_sides = 0;
  for (const auto& line : model.lines) {
    for (int k = 0; k < 3; ++k) {
      const MarkerImage& a = candidate.images[line.points[k]];
      const MarkerImage& b = candidate.images[line.points[k + 1]];
      if (a.sight == MarkerSight::BehindCamera || b.sight == MarkerSight::BehindCamera) continue;
      const Eigen::Vector2d along = b.pixel - a.pixel;
      const double length = along.norm();
      if (length < 2 * options_.merge_distance_px) continue;
      for (size_t i = 0; i < fiducials.size(); ++i) {
        if (owner[i] >= 0 || !fiducials[i].allFinite()) continue;
        const Eigen::Vector2d offset = fiducials[i] - a.pixel;
        const double u = offset.dot(along) / length;
        if (u < options_.merge_distance_px || u > length - options_.merge_distance_px) continue;
        if (std::abs(offset.x() * along.y() - offset.y() * along.x()) / length <=
            options_.side_tolerance_px) {
          ++on_sides;
        }
      }
    }
  }
  if (on_sides >= 2)
    return fmt::format("{} fiducials lie on its sides where it has no marker", on_sides);
  return {};
}

}  // namespace mocap::tracking
