// How well the robot follows, from the simulation's ground truth (issue figures for the
// follower demo): how far off the camera's optical axis the object is, how far the base keeps
// from it once the object stands still, and how long the base takes to stop when the track is
// lost. Middleware-free; the follower_monitor plugin feeds it.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mocap::evaluation {

struct FollowEvaluationOptions {
  // The object counts as walking above this speed, as standing below it; the speed is
  // measured over speed_window_s, so that a pose of the camera paired with the wrong frame
  // does not look like a step.
  double walking_speed_mps = 0.1;
  double speed_window_s = 0.5;
  // Standing this long: the follower has had time to settle, distances count as steady.
  double settle_s = 4.0;

  // Why these options cannot be used, naming the field ("settle_s: -1 is below 0"); nullopt
  // when they can. FollowEvaluator's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct FollowFigures {
  // Angle between the optical axis and the object, per camera frame in which the object is
  // trackable (facing the camera); and the subset while it walks.
  std::vector<double> pointing_error_deg;
  std::vector<double> pointing_error_walking_deg;
  // Horizontal distance from the base to the object, per frame in steady state.
  std::vector<double> steady_distance_m;
  // Per loss of track: from the last pose received to the first zero velocity command.
  std::vector<double> stop_latency_s;
};

class FollowEvaluator {
 public:
  explicit FollowEvaluator(FollowEvaluationOptions options = {});

  // A ground-truth frame: the object in the camera frame, the camera in the world, whether
  // the object can be tracked in it.
  void add_truth(int64_t stamp_ns, const Eigen::Vector3d& object_in_camera,
                 const Eigen::Isometry3d& world_from_camera, bool trackable);
  // The base's position in the world (x, y).
  void add_base(const Eigen::Vector2d& position) { base_ = position; }
  // A pose of the object arrived (receive time).
  void add_pose(int64_t received_ns) { last_pose_ns_ = received_ns; }
  // A velocity command arrived (receive time).
  void add_velocity_command(int64_t received_ns, double linear, double angular);

  const FollowFigures& figures() const { return figures_; }
  // The object's speed over the ground at the last truth frame.
  double object_speed_mps() const { return speed_mps_; }
  const FollowEvaluationOptions& options() const { return options_; }

 private:
  FollowEvaluationOptions options_;
  FollowFigures figures_;
  std::optional<Eigen::Vector2d> base_;
  std::optional<int64_t> last_pose_ns_;
  bool moving_ = false;  // the last command was not a stop
  // Object motion: its recent positions (stamp, x y), oldest first.
  std::deque<std::pair<int64_t, Eigen::Vector2d>> recent_;
  double speed_mps_ = 0;
  std::optional<int64_t> standing_since_ns_;
};

// Median, 95th percentile and maximum (NaN for no values).
struct Spread {
  double median, p95, max;
};
Spread spread(std::vector<double> values);

}  // namespace mocap::evaluation
