// A volume's cameras, frame by frame, to one pose per rigid body: what the fusion component
// runs, without middleware (the libraries of this folder's siblings, tied together).
//
// Each frame, every tracked body is looked for first where its track predicts it: each camera's
// detections near the predicted markers (views_near), the pose fused over them. Bodies not
// tracked are then identified among the markers triangulated from the detections left over,
// and fused the same way, which starts their tracks. A track the cameras lose is kept for
// `lost_after_s` and looked for at its prediction, then dropped. A body that only one camera
// sees keeps its track (the single-camera pose, `cameras_used` 1) but cannot start one:
// identification needs markers in 3D.
//
// The cameras' residuals are watched: a camera whose views disagree with the others' fused
// pose (its extrinsics have moved: bumped) is left out of fusion when the others agree without
// it, and reported as drifted when its average residual stays above `drift_px`.
//
//   VolumeTracker tracker(cameras, bodies);
//   std::vector<TrackedBodyPose> poses = tracker.track(stamp_ns, detections);
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

#include "volume/marker_cloud/marker_cloud.hpp"
#include "volume/pose_fusion/pose_fusion.hpp"
#include "volume/rigid_bodies/rigid_body_database.hpp"
#include "volume/rigid_bodies/rigid_body_identification.hpp"
#include "volume/triangulation/triangulation.hpp"

namespace mocap::volume {

struct VolumeCamera {
  std::string name;
  std::shared_ptr<const calibration::CameraModel> model;
  Eigen::Isometry3d camera_from_world = Eigen::Isometry3d::Identity();
  std::string frame_id;  // of its images: its optical frame
};

struct VolumeTrackerOptions {
  MarkerTriangulationOptions triangulation;
  RigidBodyIdentificationOptions identification;
  // A pose rests on six points at least: four or five (one camera seeing a corner of a board,
  // two cameras two markers each) fix six unknowns with nothing left over to check them, and on
  // the demo's images such fits stood centimetres off with residuals as small as any.
  MultiCameraPoseOptions fusion = {.min_points = 6};
  // How far a camera's detection may be from where the predicted pose puts a marker (pixels).
  double match_radius_px = 8;
  // A track not fused for this long is dropped; the body must then be identified again.
  double lost_after_s = 0.5;
  // A camera whose average residual (each view's median pixel error) against the others' fused
  // poses exceeds this (pixels) has moved.
  double drift_px = 2.0;

  // Why these options cannot be used, naming the field (nested ones by their path:
  // "fusion.min_points: ..."); nullopt when they can. The tracker's constructor throws
  // std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// One frame's detections of one camera.
struct CameraFrame {
  bool received = false;  // false: no message from this camera for this capture time
  int64_t stamp_ns = 0;   // its capture time (may differ a little from the frame's)
  std::vector<Eigen::Vector2d> pixels;
  // Each pixel's 1-sigma error (Fiducial.uncertainty), index by index; empty: all alike.
  std::vector<double> pixel_sigma_px;
};

struct TrackedBodyPose {
  std::string name;
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // From the track's last two poses; known from a track's second frame on.
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // world frame, m/s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world frame, rad/s
  bool velocity_known = false;
  // Over (vx, vy, vz, wx, wy, wz), from the poses' covariance over the velocity's time span.
  Eigen::Matrix<double, 6, 6> velocity_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double reprojection_rms_px = 0;
  double normalized_rms = 0;  // MultiCameraPose::normalized_rms
  int cameras_used = 0;       // 1: the single-camera pose
  int points_used = 0;
};

struct CameraHealth {
  double average_error_px = 0;  // its views' median errors against the fused poses, averaged
  int64_t views = 0;            // views that went into the average
  int64_t left_out = 0;         // fusions that left it out because the others disagreed with it
  bool drifted = false;         // average above drift_px: left out of fusion
};

class VolumeTracker {
 public:
  // Throws std::invalid_argument for no cameras, a camera without a model, or bad options.
  VolumeTracker(std::vector<VolumeCamera> cameras, RigidBodyDatabase bodies,
                VolumeTrackerOptions options = {});

  // One capture time's detections, one entry per camera in the constructor's order. Returns
  // the bodies posed in this frame, in database order.
  std::vector<TrackedBodyPose> track(int64_t stamp_ns, const std::vector<CameraFrame>& frame);

  const std::vector<VolumeCamera>& cameras() const { return cameras_; }
  const RigidBodyDatabase& bodies() const { return bodies_; }
  const std::vector<CameraHealth>& camera_health() const { return health_; }
  // Bodies identified from triangulated markers (tracks started), over the tracker's life.
  int64_t identifications() const { return identifications_; }
  // Fits set aside as unusually poor (residuals more than five times what the track, or the
  // volume, usually has): from a track's prediction, the body then fitted from its last pose or
  // identified afresh; from identification, the body left unposed. Over the tracker's life.
  int64_t unusual_fits() const { return unusual_fits_; }

 private:
  struct Track {
    Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
    int64_t stamp_ns = 0;
    Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
    bool velocity_known = false;
    Eigen::Matrix<double, 6, 6> velocity_covariance = Eigen::Matrix<double, 6, 6>::Zero();
    std::deque<std::pair<int64_t, Eigen::Isometry3d>> history;  // recent poses by stamp
    // The normalized RMS its fits usually have (a running average); 0 until the first.
    double usual_normalized_rms = 0;
    int cameras_used = 0;  // of its last pose
  };

  struct Fused {
    MultiCameraPose pose;
    std::vector<std::vector<Eigen::Vector2d>> used;  // per camera, the detections it rests on
  };
  // The body's pose fused over the cameras' detections within `radius_px` of where `start`
  // puts its markers, with a disagreeing camera left out when the others agree without it:
  // one whose points make the fit fail, or one whose points raise the fit's residuals well
  // above `usual_normalized_rms` (what the body's fits usually have) where the others' alone
  // are as usual. Of two cameras that disagree, `fused_prediction` (where a track that several
  // cameras fused puts the body now; null for none) may tell which is off: see suspect_of_two.
  std::optional<Fused> fuse(size_t body, const Eigen::Isometry3d& start,
                            const std::vector<CameraDetections>& detections, double radius_px,
                            double usual_normalized_rms,
                            const Eigen::Isometry3d* fused_prediction = nullptr);
  // The pose fitted to `views` from `start`; where it fails, fitted again without the points
  // far off it (a marker an occluder cut in half, its centre moved, or one merged with a
  // neighbour's: without them the others may agree), `views` then left without them.
  MultiCameraPose fit_without_outliers(std::vector<CameraView>& views,
                                       const Eigen::Isometry3d& start) const;
  // Of the two views with points (each agrees with itself), the camera to leave out: the one
  // whose residuals say it is on its way to being called drifted while the other's do not;
  // else, given a `fused_prediction`, the one whose points lie beyond drift_px of where it puts
  // them while the other's lie within the fusion's RMS limit, its error then recorded as a
  // residual. views.size() when neither stands out.
  size_t suspect_of_two(const std::vector<CameraView>& views,
                        const Eigen::Isometry3d* fused_prediction);
  // Leaves the points furthest off out of `views`, one by one (a few at most), and refits
  // `fused`, when that brings the fit's residuals back to the usual; false (nothing changed)
  // otherwise.
  bool without_worst_points(std::vector<CameraView>& views, MultiCameraPose& fused,
                            double usual_normalized_rms) const;
  // The view whose points disagree with the others' (disagreeing above), `fused` refitted
  // without it; nullopt when leaving no one view out brings the residuals back to the usual.
  // Of two views each fits alone: a `suspect` (below views.size()) is the only one looked at.
  std::optional<size_t> disagreeing_view(const std::vector<CameraView>& views,
                                         MultiCameraPose& fused, double usual_normalized_rms,
                                         size_t suspect) const;
  // A marker merged with a neighbour's, half hidden by another board, or another body's taken
  // for one of this body's moves its pixel by a pixel or more where the rest agree within a
  // tenth: a few such points stay under the RMS limit yet tilt the pose. The points far above
  // the fit's typical error are left out of `views` and `fused` fitted again without them.
  void trim_strays(std::vector<CameraView>& views, MultiCameraPose& fused) const;
  // A fit whose residuals are far beyond what `usual_normalized_rms` and the detections'
  // sigmas explain: not a pose of the body (its points are something else).
  static bool unusually_poor(const Fused& fit, double usual_normalized_rms);
  // Removes the detections `used` from `detections`: one detection belongs to one body.
  static void take(const std::vector<std::vector<Eigen::Vector2d>>& used,
                   std::vector<CameraDetections>& detections);
  void record_residual(size_t camera, double error_px);
  TrackedBodyPose update_track(size_t body, int64_t stamp_ns, const MultiCameraPose& fused);

  std::vector<VolumeCamera> cameras_;
  RigidBodyDatabase bodies_;
  VolumeTrackerOptions options_;
  std::vector<std::optional<Track>> tracks_;  // per body
  std::vector<CameraHealth> health_;
  int64_t identifications_ = 0;
  int64_t unusual_fits_ = 0;
  double usual_normalized_rms_ = 0;  // of every body's fits, a running average
};

// A cloud marker's body: the index of a posed body in the list given, and which of its markers.
struct MarkerOwner {
  int body = -1;  // -1: unlabeled
  int marker = 0;
};

// A body's markers where its pose puts them (world frame).
struct PlacedBody {
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
  const std::vector<Eigen::Vector3d>* markers = nullptr;  // in the body's frame
};

// Each cloud marker's owner: every placed marker claims the nearest cloud marker within
// `radius_m` that no one claimed first (bodies in the order given); unlabeled otherwise.
std::vector<MarkerOwner> owners_of(const std::vector<CloudMarker>& cloud,
                                   const std::vector<PlacedBody>& bodies, double radius_m);

}  // namespace mocap::volume
