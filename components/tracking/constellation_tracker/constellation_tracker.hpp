// Follows constellations from frame to frame: the tracking stage of the pipeline, from one
// camera's fiducials to each board's identity, pose and velocity.
//
//   ConstellationTracker tracker(database, camera);
//   for each frame:
//     for (const TrackedConstellation& board : tracker.update(capture_stamp_ns, fiducial_pixels))
//       use(board.pose, board.motion.linear_velocity, ...);
//
// A board found in a frame is remembered. In the next frame its pose is predicted at the
// frame's capture time (body_motion.hpp), its markers are projected through the camera model,
// and the detected fiducials are associated with them for every tracked board at once
// (marker_association.hpp). Any four or more associated markers, in any arrangement, give the
// pose, refined through the camera model and believed only when every marker it puts in plain
// view is either found or could be hidden (marker_visibility.hpp); otherwise the board is
// dropped, not guessed. Boards not tracked are searched among the fiducials no tracked board
// claimed, by full identification (constellation_identifier.hpp), which also finds a board
// from one whole line and its loose markers; a board it finds starts a track once its pose is
// verified the same way.
//
// The tracker's state depends only on the frames it is given, in order: the same frames give
// the same answers, byte for byte, live or replayed from a bag.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <mocap/calibration/camera_model.hpp>

#include "tracking/body_motion/body_motion.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "tracking/constellation_identifier/constellation_identifier.hpp"
#include "tracking/constellation_tracker/marker_association.hpp"
#include "tracking/constellation_tracker/marker_visibility.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"

namespace mocap::tracking {

// One detected fiducial: where it is (pixels, with the lens's distortion) and how big it looks
// (the blob's area, Fiducial.size; 0 when unknown).
struct ImageFiducial {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double size = 0;
};

struct TrackerOptions {
  // Full identification of boards not tracked. Its focal_length_px is the camera's.
  constellations::IdentifierOptions identification;
  // Poses of boards found by identification; tracked boards use the same bound on the
  // reprojection error, with pose.min_points replaced by min_tracked_markers.
  pose::PlanarPoseOptions pose;
  BodyMotionOptions motion;
  VisibilityOptions visibility;
  // A detected fiducial's position error, px (1 sigma), added to each predicted marker's own
  // uncertainty: the detector's centroid error and what a motion model misses in one frame.
  double fiducial_sigma_px = 1.0;
  // Squared Mahalanobis distance beyond which a fiducial cannot be a predicted marker
  // (marker_association.hpp).
  double association_gate = 16.0;
  // A tracked board's measured pose further than this from its prediction (squared
  // Mahalanobis distance over the pose's 6 degrees of freedom, prediction and measurement
  // uncertainties together) is a jump no motion explains: markers taken for others. The track
  // is dropped and the board identified afresh.
  double max_motion_surprise = 40.0;
  // Fewest associated markers for a tracked board's pose: four fix a plane's pose.
  int min_tracked_markers = 4;
  // A tracked board its prediction loses (a camera on a turret that starts or stops turning
  // moves the whole picture by tens of pixels between frames, which no motion of the board
  // foretells) is looked for again shifted: the one image shift, within this radius, that puts
  // at least relock_min_markers of its markers on free fiducials. Its velocity starts afresh;
  // the track goes on.
  double relock_radius_px = 120.0;
  int relock_min_markers = 6;
  // After the fit, an associated marker further than this from its reprojection is taken out
  // and the pose fitted again without it (a distractor next to a hidden marker).
  double max_marker_error_px = 2.5;
  // A missing marker imaged this close to a fiducial of another board, or to one no board
  // claimed, has merged with it or sits under it: it counts as hidden.
  double merge_distance_px = 4.0;
  // Markers in view and missing must lie in one straight band (one occluder) with no marker
  // found in it, but for this many: a glare or a fingertip elsewhere.
  int spare_missing_markers = 1;
  // A fiducial no board claimed, this close to the segment between two neighbouring markers of
  // a board's line (and not at either), contradicts the board's pose: boards of one size
  // differ by where their sides' markers are.
  double side_tolerance_px = 1.5;
  // A tracked marker whose fiducial looks smaller than this share of what its depth and angle
  // lead to expect, against the board's other markers, is cut by an occluder's edge (its
  // centroid is off): it counts as seen but is left out of the pose. Larger than the inverse
  // share, it has merged with another blob. Needs sizes; 0 turns it off.
  double min_size_ratio = 0.5;

  // Why these options cannot be used, naming the field (nested ones by their path:
  // "pose.min_points: 3; ..."); nullopt when they can. ConstellationTracker's constructor
  // throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// How a pose was found.
enum class PoseSource {
  Tracked,      // associated with the markers predicted from the previous frames
  Identified,   // full identification: two or more whole lines
  FromOneLine,  // full identification: one whole line and loose markers
};
const char* to_string(PoseSource source);  // "tracked", "identified", "one line"

struct TrackedConstellation {
  // Which fiducial is which marker (indices into the frame's fiducials), and the whole lines
  // with their measured cross-ratios: what the seed's Constellation message carries.
  constellations::IdentifiedConstellation identified;
  PoseSource source = PoseSource::Tracked;
  // This frame's pose, measured from its markers alone, with its covariance.
  pose::PlanarPose pose;
  // The track's filtered state at the frame's stamp: the velocities and their covariance. A
  // board seen for the first time has zero velocity and the filter's initial uncertainty.
  BodyState motion;
  uint64_t track_id = 0;   // new for each track; a board lost and found again gets a new one
  int frames_tracked = 0;  // frames of this track so far, this one included
};

// What became of one frame, for logs and benchmarks.
struct TrackerStats {
  int tracked = 0;                      // boards followed from the previous frame
  int relocked = 0;                     //   of them, found again by an image shift
  int identified = 0;                   // boards found by full identification
  int from_one_line = 0;                //   of them, from one line and loose markers
  int lost = 0;                         // tracked boards not found again (too few markers)
  int rejected = 0;                     // boards whose pose could not be verified
  std::vector<std::string> rejections;  // "name: why", for the rejected and the lost
  bool identification_ran = false;      // some boards were not tracked
};

class ConstellationTracker {
 public:
  // Keeps a reference to `database`, which must outlive the tracker. Throws
  // std::invalid_argument for a null camera or options that cannot be used.
  ConstellationTracker(const constellations::ConstellationDatabase& database,
                       std::shared_ptr<const calibration::CameraModel> camera,
                       TrackerOptions options = {});

  // One frame: the fiducials as detected (non-finite ones are ignored), captured at
  // `stamp_ns`. Stamps should increase; a frame older than the last one starts every track
  // afresh. Returns the boards found, in database order; their image points index `fiducials`.
  std::vector<TrackedConstellation> update(int64_t stamp_ns,
                                           const std::vector<ImageFiducial>& fiducials,
                                           TrackerStats* stats = nullptr);

  // Forgets every track.
  void reset() { tracks_.clear(); }

  const TrackerOptions& options() const { return options_; }

 private:
  struct Track {
    const constellations::ConstellationModel* model;
    BodyMotionFilter motion;
    uint64_t id;
    int frames;
  };
  struct Candidate;  // a pose found this frame, before its verification

  void follow_tracks(int64_t stamp_ns, const std::vector<ImageFiducial>& fiducials,
                     std::vector<Candidate>& candidates, TrackerStats& stats);
  // Every tracked board's markers where the camera should see them with the boards at
  // `predicted` (per track), with their uncertainty, and the (track, marker) of each; markers
  // out of view or behind another tracked board are left out.
  void predict_markers(const std::vector<BodyState>& predicted,
                       std::vector<PredictedMarker>& markers,
                       std::vector<std::pair<int, int>>& track_marker) const;
  // The markers of track t found again by the picture's shift (relock) on fiducials no other
  // track holds (`track_of_fiducial`), and the pose they give; false when there are none.
  bool find_shifted(size_t t, const BodyState& predicted, const std::vector<int>& track_of_fiducial,
                    pose::PlanarPose& pose, std::vector<int>& image_of) const;
  // The pose of track t from the fiducials associated with its markers (`image_of`, a marker
  // left out when its fit shows it is not the marker's), refined from the prediction.
  void fit_associated(size_t t, const BodyState& predicted,
                      const std::vector<ImageFiducial>& detected, std::vector<int>& image_of,
                      pose::PlanarPose& pose) const;
  // The markers of a tracked board predicted at `pose` (in view, at `images`), found again on
  // fiducials not `taken` by an image shift; the fiducial of each marker, or nothing.
  std::optional<std::vector<int>> relock(const constellations::ConstellationModel& model,
                                         const std::vector<MarkerImage>& images,
                                         const std::vector<Eigen::Vector2d>& fiducials,
                                         const std::vector<bool>& taken) const;
  // Per marker: whether its fiducial looks whole (not cut by an occluder, not merged) by its
  // size, judged at `pose`.
  std::vector<bool> whole_markers(const constellations::ConstellationModel& model,
                                  const Eigen::Isometry3d& pose, const std::vector<int>& image_of,
                                  const std::vector<ImageFiducial>& detected) const;
  void identify_others(const std::vector<Eigen::Vector2d>& fiducials,
                       const std::vector<bool>& claimed, std::vector<Candidate>& candidates,
                       TrackerStats& stats);
  // Why the candidate's pose is not believed; empty when it is.
  std::string verify(const Candidate& candidate, const std::vector<Candidate>& others,
                     const std::vector<Eigen::Vector2d>& fiducials,
                     const std::vector<int>& owner) const;

  const constellations::ConstellationDatabase& database_;
  std::shared_ptr<const calibration::CameraModel> camera_;
  TrackerOptions options_;
  constellations::ConstellationIdentifier identifier_;
  std::vector<Track> tracks_;
  uint64_t next_track_id_ = 1;
  int64_t last_stamp_ns_ = 0;
  std::vector<Eigen::Vector2d> pixels_;  // the frame's fiducials' pixels
  std::vector<Eigen::Vector2d> ideal_;   // per fiducial: f·(x/z, y/z), NaN when claimed
};

}  // namespace mocap::tracking
