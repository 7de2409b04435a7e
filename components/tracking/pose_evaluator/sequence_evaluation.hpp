// Scores a tracker over a sequence of frames against the synthetic camera's truth: what the
// frames where things go wrong show (a board half hidden, leaving the picture, crossing
// another). Per board, an *episode* is a run of frames in which it can be tracked (in front,
// facing the camera, at least half its markers visible and at least four); the figures are
// per episode and per frame in them. Middleware-free; tracking_accuracy_bench and the tracker's
// tests feed it.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace mocap::evaluation {

struct SequenceTruth {
  std::string name;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // camera frame
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  bool facing_camera = false;
  int visible_markers = 0;
  int markers = 0;
};

struct SequenceEstimate {
  std::string name;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // Velocities when the estimator gives them and its track is settled (enough frames).
  std::optional<Eigen::Vector3d> linear_velocity, angular_velocity;
};

struct SequenceOptions {
  // An estimate within both bounds of the truth of its name is right; within them of another
  // board's truth it is an identity swap; near none, a false identification.
  double position_bound_m = 0.05;
  double orientation_bound_deg = 5.0;

  // Why these options cannot be used, naming the field ("position_bound_m: 0 is not above 0");
  // nullopt when they can. SequenceEvaluator's constructor throws std::invalid_argument with
  // it.
  std::optional<std::string> problem() const;
};

struct SequenceScore {
  int episodes = 0;                   // runs of trackable frames, all boards
  int acquired = 0;                   // episodes in which the board was found at least once
  int frames_after_acquisition = 0;   // trackable frames from an episode's first find on
  int tracked_after_acquisition = 0;  //   of them, with the board found
  int trackable_frames = 0;
  int tracked_frames = 0;  // trackable frames with the board found
  int identity_swaps = 0;
  int false_identifications = 0;
  std::vector<double> position_error_mm, orientation_error_deg;  // right estimates, trackable
  std::vector<double> velocity_error_mps, angular_velocity_error_dps;
  std::vector<double> acquisition_delay_s;  // per acquired episode: from its start to the find

  double acquired_percent() const;
  double tracked_after_acquisition_percent() const;
  double tracked_percent() const;
};

class SequenceEvaluator {
 public:
  explicit SequenceEvaluator(SequenceOptions options = {});

  // One frame at scene time `time_s` (increasing).
  void add_frame(double time_s, const std::vector<SequenceTruth>& truth,
                 const std::vector<SequenceEstimate>& estimates);

  const SequenceScore& score() const { return score_; }

  static bool trackable(const SequenceTruth& truth);

 private:
  struct Episode {
    double start_s = 0;
    bool acquired = false;
  };
  SequenceOptions options_;
  SequenceScore score_;
  std::map<std::string, Episode> open_;  // boards in an episode now
};

}  // namespace mocap::evaluation
