// What the turret does, without servos or middleware: keep the tracked object on the optical
// axis (seed 000 §5.11.3), and when the track is lost, hold still, then optionally search.
//
//   TurretFollower follower(turret);
//   follower.observe(image_stamp_ns, object_in_camera, angles_at_image);  // per pose
//   TurretCommand command = follower.update(now_ns, present_angles);      // per control cycle
//
// The object is kept in the base frame: where it was seen, through the angles the turret had
// at that moment (joint_history.hpp). Each cycle aims the camera at it from the present angles,
// at where it has moved since its image: its velocity in the base frame is the least-squares
// slope of its recent positions there, so a walking person is led, not trailed. (The velocity
// the tracker reports is in the camera frame, which turns with the turret: it holds the
// turret's own turning, which the base frame does not.)
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "follower/turret_kinematics/turret_model.hpp"

namespace mocap::turret {

struct TurretFollowerOptions {
  // Servo speed limits. The seed ran its heavy Tango turret at 0.1 and 0.05 rad/s (§5.11.3)
  // and found them too slow to follow a walking person (§7.5); these suit a light camera.
  double pan_speed_rps = 1.5;
  double tilt_speed_rps = 1.0;
  // No pose for this long: the track is lost.
  double lost_after_s = 0.3;
  // A moving object is aimed at where its velocity has taken it since its image, at most this
  // far ahead; 0 aims at where it was seen.
  double max_lead_s = 0.2;
  // Its velocity is measured over the positions of this last stretch of time (at least three
  // of them, a tenth of a second apart or more).
  double velocity_window_s = 0.25;
  // After losing the track: hold still this long, then search (when `search` is on).
  double hold_s = 2.0;
  // Searching sweeps the pan joint between its limits at search_speed_rps, tilt level.
  bool search = false;
  double search_speed_rps = 0.3;

  // Why these options cannot be used, naming the field ("pan_speed_rps: 0 is not above 0"):
  // speeds, lost_after_s and velocity_window_s must be positive, max_lead_s and hold_s not
  // negative; nullopt when they can. TurretFollower's constructor throws std::invalid_argument
  // with it.
  std::optional<std::string> problem() const;
};

enum class TurretMode {
  Idle,       // no object seen yet: hold where it is
  Tracking,   // aiming at the object
  Holding,    // track lost: holding still
  Searching,  // track lost for hold_s: sweeping
};
const char* to_string(TurretMode mode);  // "idle", "tracking", "holding", "searching"

struct TurretCommand {
  TurretMode mode = TurretMode::Idle;
  JointAngles goal;   // where the joints should go
  JointAngles speed;  // how fast, rad/s (positive)
  // Tracking: the angle between the optical axis at the present angles and the object, as
  // last seen (0 otherwise).
  double pointing_error_rad = 0;
  // Tracking: the object is beyond the joints' limits; `goal` is the nearest reachable.
  bool out_of_reach = false;
};

class TurretFollower {
 public:
  // Throws std::invalid_argument for options that cannot be used (problem()).
  explicit TurretFollower(TurretModel turret, TurretFollowerOptions options = {});

  // The object seen at `stamp_ns` at `in_camera` (camera frame, metres), when the joints were
  // at `angles`.
  void observe(int64_t stamp_ns, const Eigen::Vector3d& in_camera, const JointAngles& angles);

  // How the object moves in the base frame (m/s), once measured.
  const std::optional<Eigen::Vector3d>& velocity_in_base() const { return velocity_in_base_; }

  // The command for now, the joints being at `present`.
  TurretCommand update(int64_t now_ns, const JointAngles& present);

  // Where the object was last seen, base frame; nothing before the first observation.
  const std::optional<Eigen::Vector3d>& object_in_base() const { return object_in_base_; }
  const TurretModel& turret() const { return turret_; }
  const TurretFollowerOptions& options() const { return options_; }

 private:
  TurretModel turret_;
  TurretFollowerOptions options_;
  std::optional<Eigen::Vector3d> object_in_base_;
  std::optional<Eigen::Vector3d> velocity_in_base_;
  std::deque<std::pair<int64_t, Eigen::Vector3d>> recent_;  // (stamp, base position)
  int64_t last_seen_ns_ = 0;
  std::optional<JointAngles> held_;  // where the joints stopped when the track was lost
  double search_direction_ = 1;
};

}  // namespace mocap::turret
