// Exponential smoothing of each constellation's pose: no middleware, unit-testable.
#pragma once

#include <map>
#include <string>

#include <Eigen/Geometry>

namespace pose_filter {

struct PoseSmootherOptions {
  // Weight of a new sample, 0 (ignore it) .. 1 (no smoothing).
  double position_smoothing = 0.5;
  double orientation_smoothing = 0.5;
  // A track unseen this long starts again from its next sample.
  double restart_after_s = 0.5;
};

struct SmoothedPose {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  unsigned samples = 0;    // since the track (re)started
  bool restarted = false;  // this sample started the track
};

class PoseSmoother {
 public:
  explicit PoseSmoother(PoseSmootherOptions options = {}) : options_(options) {}

  // Adds `name`'s pose measured at `time_s` and returns the smoothed pose.
  SmoothedPose update(const std::string& name, double time_s, const Eigen::Isometry3d& pose);

  const PoseSmootherOptions& options() const { return options_; }

 private:
  struct Track {
    Eigen::Vector3d position;
    Eigen::Quaterniond orientation;
    double last_time_s = 0;
    unsigned samples = 0;
  };
  PoseSmootherOptions options_;
  std::map<std::string, Track, std::less<>> tracks_;
};

}  // namespace pose_filter
