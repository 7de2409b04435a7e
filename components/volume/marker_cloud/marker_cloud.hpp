// A volume's markers in 3D, frame after frame, without identities: the marker cloud. Each
// marker is a track with a persistent id, found first where its track predicts it; the rest are
// matched across cameras by their rays. Built for a hundred markers and more (a swarm), where
// trying every pair of detections of every pair of cameras each frame would not keep up.
//
// Each frame, in order:
//  1. Predicted tracks. Each track's position, moved on by its velocity to the frame's time, is
//     projected into every camera; the detection nearest that projection within `gate_px` is
//     its observation in that camera, unless the detection is the nearest of two tracks' (two
//     markers merged into one blob there: the detection is left out, and counted). A track
//     observed by two cameras or more is triangulated (Gauss-Newton on the pixel errors, from
//     the prediction), observations further than `tolerance_px` off left out.
//  2. New markers. The detections no track took, a blob two tracks claim aside (it is theirs,
//     merged), are matched across cameras: each pair of cameras proposes a marker for two
//     detections whose rays pass within `tolerance_px` of each other; a proposal gathers the
//     other cameras' free detections it projects onto, and is triangulated from them all. Proposals
//     seen by `min_cameras_to_start` cameras or more, the most cameras first, then the lowest
//     error, become markers; one that lies where a track not observed this frame is predicted
//     continues that track.
//  3. What is left: a detection no marker explains (seen by one camera only, or a blob of
//     several markers) is counted, never triangulated.
// A track not observed for `lost_after_s` is dropped.
//
//   MarkerCloudTracker cloud;
//   std::vector<CloudMarker> markers = cloud.track(stamp_ns, detections);
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "volume/triangulation/triangulation.hpp"

namespace mocap::volume {

struct MarkerCloudOptions {
  // How far a detection may be from a track's predicted projection (pixels).
  double gate_px = 3.0;
  // How far a marker may reproject from a detection that sees it (pixels); also how close two
  // rays must pass (in pixels, in either camera) to propose a marker.
  double tolerance_px = 1.0;
  // Fewest cameras that start a marker: two cameras' rays meet by chance among a hundred
  // markers' detections, three seldom. A tracked marker continues with two.
  int min_cameras_to_start = 3;
  // A track not observed for this long is dropped (seconds).
  double lost_after_s = 0.1;

  // Why these options cannot be used, naming the field ("gate_px: 0 is not above 0"); nullopt
  // when they can. MarkerCloudTracker's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// The most cameras a cloud marker's `cameras` bits can name.
inline constexpr int kMaxCloudCameras = 32;

struct CloudMarker {
  uint32_t id = 0;                                     // its track's, the same from frame to frame
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame, metres
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of the position, from the pixels' sigmas
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();    // m/s; zero on a track's first frame
  bool velocity_known = false;                           // from a track's second frame on
  double rms_px = 0;                                     // reprojection error over its cameras
  uint32_t cameras = 0;                                  // bit c: camera c saw it
  // (camera, detection) pairs: the camera's index and the index of its pixel.
  std::vector<std::pair<int, int>> observations;
};

// What happened to one frame's detections and tracks.
struct MarkerCloudCounts {
  int tracked = 0;      // markers found where their tracks predicted them
  int started = 0;      // new tracks
  int continued = 0;    // tracks not observed where predicted, found again by their rays
  int coasting = 0;     // tracks not observed this frame, kept
  int dropped = 0;      // tracks given up this frame
  int merged = 0;       // detections left out as the nearest of two tracks (merged blobs)
  int unexplained = 0;  // detections no marker explains
};

class MarkerCloudTracker {
 public:
  // Throws std::invalid_argument for bad options.
  explicit MarkerCloudTracker(MarkerCloudOptions options = {});

  // One capture time's detections of every camera (fixed: the same cameras in the same order,
  // at most kMaxCloudCameras) to this frame's markers: tracked ones first, in no particular
  // order. Stamps must not go back.
  std::vector<CloudMarker> track(int64_t stamp_ns, const std::vector<CameraDetections>& cameras);

  // The last frame's counts.
  const MarkerCloudCounts& counts() const { return counts_; }
  // Every frame's counts added up.
  const MarkerCloudCounts& totals() const { return totals_; }
  size_t tracks() const { return tracks_.size(); }

 private:
  struct Track {
    uint32_t id = 0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    int64_t stamp_ns = 0;  // when last observed
    bool velocity_known = false;
  };
  void update(Track& track, int64_t stamp_ns, const Eigen::Vector3d& position);

  MarkerCloudOptions options_;
  std::vector<Track> tracks_;
  uint32_t next_id_ = 0;
  MarkerCloudCounts counts_, totals_;
};

}  // namespace mocap::volume
