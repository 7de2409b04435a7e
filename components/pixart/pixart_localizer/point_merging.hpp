// Step 2b of the localizer: one point per LED, however many cameras see it.
//
// Where the cameras' fields overlap, one LED is seen by two (or four) cameras at about the
// same instant, and the views put it a few millimetres apart (calibration and pixel
// rounding; seed 002 Figure 0.7 shows four such points). Points of different cameras are
// merged, by their average, when they are closer than `merge_distance_m` and their samples
// were taken within `merge_window_s` of each other:
//
//   1. Only views taken within `stale_after_s` of the newest view take part: a camera whose
//      last sample is older has stopped reporting, and what it saw then is no longer there.
//   2. Candidate pairs (different cameras, close in space and time) are taken closest
//      first; two groups join when they share no camera (one camera never sees an LED twice,
//      so two points of one camera are two LEDs) and every pair across them is a candidate.
//      Complete linkage keeps a chain of nearby LEDs from collapsing into one point.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pixart/pixart_localizer/camera_views.hpp"

namespace mocap::pixart::localization {

struct MergeOptions {
  // Points of two cameras closer than this are one LED. Well under the smallest LED spacing
  // of a robot, well over the disagreement of two calibrated cameras.
  double merge_distance_m = 0.02;
  // ... if their samples were taken within this of each other (a robot at 1 m/s moves 5 mm).
  double merge_window_s = 0.005;
  // Views older than this, relative to the newest view, take no part (the sensors sample at
  // about 270 Hz, every 3.7 ms).
  double stale_after_s = 0.02;

  // Why these options cannot be used, naming the field ("merge_distance_m: 0 is not above
  // 0"); nullopt when they can. merge_views throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// The cameras that saw a point: bit i for the rig's camera i (rigs have at most 64 cameras).
using CameraSet = uint64_t;
inline constexpr size_t kMaxCameras = 64;

struct MergedPoint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // world x, y on the LED plane
  int views = 1;                                       // cameras that saw it
  CameraSet cameras = 0;
};

struct MergedPoints {
  std::vector<MergedPoint> points;
  int64_t stamp_ns = 0;  // the newest view's: the time the points describe
  int cameras = 0;       // views that took part (fresh enough), with or without points
};

// The LEDs seen at the newest view's time. Views not yet received take no part; views beyond
// the first kMaxCameras are ignored.
MergedPoints merge_views(const std::vector<CameraView>& views, const MergeOptions& options = {});

}  // namespace mocap::pixart::localization
