// Compares estimated poses with the synthetic camera's ground truth, frame by frame: the
// accuracy figures of the tracking pipeline (docs/targets.md).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace mocap::evaluation {

struct EvaluationOptions {
  // A ground-truth object counts as trackable when at least this many of its markers are
  // visible (three sides of a 12-marker board).
  int min_visible_markers = 10;
  // An estimate further than this from the truth, or of an object not in view, is a false
  // identification rather than an inaccurate pose.
  double false_position_error_m = 0.05;
  double false_orientation_error_deg = 5.0;
  // Frames whose estimate has not arrived after this many newer truth frames count as lost.
  size_t max_pending_frames = 200;

  // Why these options cannot be used, naming the field ("max_pending_frames: 0; ..."); nullopt
  // when they can. PoseEvaluator's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct ObjectPose {
  std::string name;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  int visible_markers = 0;  // truth only
  // False for an estimate whose orientation is unknown (a robot of one marker): its position
  // alone is judged.
  bool orientation_known = true;
  // Linear (m/s) and angular (rad/s) velocity in the camera frame, when known: always for the
  // truth, for an estimate once its track has measured them.
  std::optional<Eigen::Vector3d> linear_velocity, angular_velocity;
};

// One estimate counted as a false identification, kept so it can be told: which object, when,
// and how far from the truth (NaN errors: the object is not in the truth at all).
struct FalseIdentification {
  int64_t stamp_ns = 0;
  std::string name;
  double position_error_m = 0;
  double orientation_error_deg = 0;
};

// Totals over a run or a window of it.
struct EvaluationSummary {
  uint64_t frames = 0;       // truth frames evaluated
  uint64_t frames_lost = 0;  // truth frames no estimate array arrived for
  uint64_t expected = 0;     // trackable objects in those frames
  uint64_t tracked = 0;      // of them, estimated within the false-identification bounds
  // Frames whose estimate was made without the data of a camera that should have given it (late
  // past the fusion's wait, or lost on the way): on a busy machine, a scheduler's doing rather
  // than the tracker's. Their trackable objects and how many of them were tracked, also counted
  // in `expected` and `tracked`.
  uint64_t incomplete_frames = 0;
  uint64_t expected_in_incomplete = 0;
  uint64_t tracked_in_incomplete = 0;
  uint64_t false_identifications = 0;
  std::vector<FalseIdentification> false_identification_details;  // one per count above
  // Estimates nearer another object's true position than their own: one object reported as
  // another (identical robots of a swarm swapped).
  uint64_t identity_swaps = 0;
  uint64_t objects = 0;                   // the most objects in one truth frame (a swarm's robots)
  std::vector<double> position_errors_m;  // one per tracked object
  std::vector<double> orientation_errors_deg;  // one per tracked object
  // Per tracked object with a measured velocity: |v - v_true| m/s, |w - w_true| deg/s.
  std::vector<double> velocity_errors_mps, angular_velocity_errors_dps;

  double tracked_percent() const;
  // Over the frames made with every camera's data: what the tracking does with what it is given.
  double tracked_percent_in_complete_frames() const;
  // Quantile q in [0, 1] of a list (NaN when empty).
  static double quantile(std::vector<double> values, double q);
};

// Pairs truth and estimates by their stamp (both carry the image's), in any arrival order.
class PoseEvaluator {
 public:
  explicit PoseEvaluator(EvaluationOptions options = {});

  void add_truth(int64_t stamp_ns, std::vector<ObjectPose> objects);
  // `incomplete`: made without the data of a camera that should have given it.
  void add_estimate(int64_t stamp_ns, std::vector<ObjectPose> objects, bool incomplete = false);

  const EvaluationSummary& total() const { return total_; }
  // What was evaluated since the last call.
  EvaluationSummary take_window();

 private:
  struct Estimate {
    std::vector<ObjectPose> objects;
    bool incomplete = false;
  };
  void evaluate(int64_t stamp_ns, const std::vector<ObjectPose>& truth, const Estimate& estimate);
  void expire();

  EvaluationOptions options_;
  std::map<int64_t, std::vector<ObjectPose>> pending_truth_;
  std::map<int64_t, Estimate> pending_estimates_;
  EvaluationSummary total_;
  EvaluationSummary window_;
};

}  // namespace mocap::evaluation
