// The seed's two driving rules (seed 000 §5.11.4): the base goes to a goal 1.5 m in front of
// the tracked object and points at it.
//
//   Rule 1, near the goal: no translation, only rotation that points the base at the object.
//   Rule 2, elsewhere: drive toward the goal, forward, or backward when the goal is more than
//   90 degrees off the heading; speed and turn rate proportional to the distance and to the
//   heading error, each capped, so the base arcs toward the goal and slows down as it nears it.
//
//   DriveRules rules(options);
//   DriveCommand command = rules.command({object_position, object_facing});
//
// Everything is in the base frame on the floor plane: x forward, y left, angles
// counter-clockwise.
//
// The seed switched between the rules at one radius, so the base stopped anywhere within a
// quarter metre of the goal. DriveRules adds hysteresis: rule 2 drives on until the base is
// within `arrival_tolerance_m` of the goal, and rule 1 then holds while the goal stays within
// `goal_tolerance_m` (the seed's quarter metre), so a base that has arrived does not chase
// every small movement of the object, yet it ends up close to the goal.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "follower/drive_follower/velocity.hpp"

namespace mocap::drive {

struct DriveOptions {
  double goal_distance_m = 1.5;       // the goal is this far in front of the object
  double goal_tolerance_m = 0.25;     // rule 1 holds while the goal is this close
  double arrival_tolerance_m = 0.05;  // rule 2 drives until the goal is this close
  double linear_gain = 1.0;           // m/s per metre to the goal
  double angular_gain = 2.0;          // rad/s per radian of heading error
  double max_linear_mps = 0.6;
  double max_angular_rps = 1.5;

  // Why these options cannot be used, naming the field ("linear_gain: 0 is not above 0"):
  // distances, gains and limits must be positive, the arrival tolerance no larger than the goal
  // tolerance; nullopt when they can. DriveRules' constructor throws std::invalid_argument
  // with it.
  std::optional<std::string> problem() const;
};

// The tracked object on the floor plane, in the base frame.
struct ObjectInBase {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Vector2d facing = Eigen::Vector2d::UnitX();  // unit: the way its front looks
};

enum class DriveRule {
  Face,      // rule 1: at the goal, turning to point at the object
  Forward,   // rule 2, goal ahead
  Backward,  // rule 2, goal behind
};
std::string_view to_string(DriveRule rule);  // "face", "forward", "backward"

struct DriveCommand {
  double linear_mps = 0;
  double angular_rps = 0;
  DriveRule rule = DriveRule::Face;

  Velocity velocity() const { return {linear_mps, angular_rps}; }
};

// Where the base should be: `goal_distance_m` in front of the object.
Eigen::Vector2d goal_position(const ObjectInBase& object, const DriveOptions& options);

// Bearing of a point from the base's heading, in (-pi, pi]; 0 for the origin.
double bearing(const Eigen::Vector2d& point);

// The seed's rules without memory: rule 1 when the goal is within `face_within_m`.
DriveCommand drive_command(const ObjectInBase& object, const DriveOptions& options,
                           double face_within_m);

// The rules with hysteresis between the arrival and the goal tolerance (see above).
class DriveRules {
 public:
  explicit DriveRules(DriveOptions options = {});  // checks problem()

  DriveCommand command(const ObjectInBase& object);
  // True after the base arrived, until the goal moves beyond the goal tolerance.
  bool holding() const { return holding_; }
  // Forgets the arrival: after a lost track the base drives to the goal again.
  void reset() { holding_ = false; }
  const DriveOptions& options() const { return options_; }

 private:
  DriveOptions options_;
  bool holding_ = false;
};

}  // namespace mocap::drive
