// The pan/tilt turret that carries the tracking camera on the mobile base (seed 000 §5.3.5,
// §5.11.2): a kinematic chain base -> pan joint -> tilt joint -> camera, read from YAML
// (config/turret.yaml documents the keys).
//
//   TurretModel turret = load_turret("config/turret.yaml");
//   Eigen::Isometry3d base_from_camera = turret.base_from_camera({pan, tilt});
//   JointAngles aim = turret.aim_at(base_from_camera * object_in_camera, {pan, tilt});
//
// Frames: the base is x forward, y left, z up (REP 103); the camera is an optical frame, x
// right, y down, z forward along the optical axis. A joint's frame sits at `origin` in its
// parent's frame when its angle is 0 and turns about `axis` (its own frame) by the angle, right
// handed. Angles are radians.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mocap::turret {

struct JointAngles {
  double pan = 0;
  double tilt = 0;
};

// How a servo's position maps onto its joint: joint angle = direction × (servo angle from
// zero_position). AX-12A positions are 0..1023 over 300 degrees.
struct ServoMapping {
  int zero_position = 512;
  int direction = 1;  // +1 or -1: servo mounted one way or the other
};

struct Joint {
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  // in the parent, at angle 0
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();           // unit, in the joint's frame
  double min_rad = -M_PI;
  double max_rad = M_PI;
  ServoMapping servo;

  // The joint's frame in its parent's at `angle`.
  Eigen::Isometry3d parent_from_joint(double angle) const;
};

// Why a turret file cannot be used: one line, "FILE:LINE: what is wrong".
class TurretError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where aim_at() points the camera.
struct Aim {
  JointAngles angles;
  // false: the target is outside the joints' limits; `angles` are the nearest within them.
  bool within_limits = true;
  // Angle between the optical axis at `angles` and the direction to the target.
  double residual_rad = 0;
};

class TurretModel {
 public:
  TurretModel() = default;
  TurretModel(Joint pan, Joint tilt, Eigen::Isometry3d tilt_from_camera, std::string source = {});

  // The camera (optical frame) in the base frame at `angles`.
  Eigen::Isometry3d base_from_camera(const JointAngles& angles) const;

  // The joint angles that put `target` (base frame) on the optical axis, in front of the
  // camera; the camera's offset from the joint axes is taken into account, so a near target
  // is centred too. Starts from `start` (the current angles: of the solutions, the one nearest
  // them). Targets within 1 cm of the tilt joint have no direction; the start is kept.
  Aim aim_at(const Eigen::Vector3d& target, const JointAngles& start = {}) const;

  // Angle between the optical axis at `angles` and the direction from the camera to `target`
  // (base frame): how far off centre the target is.
  double pointing_error(const JointAngles& angles, const Eigen::Vector3d& target) const;

  // `angles` moved into the joints' limits.
  JointAngles clamped(const JointAngles& angles) const;

  const Joint& pan() const { return pan_; }
  const Joint& tilt() const { return tilt_; }
  const Eigen::Isometry3d& tilt_from_camera() const { return tilt_from_camera_; }
  const std::string& source() const { return source_; }

 private:
  Joint pan_;
  Joint tilt_;
  Eigen::Isometry3d tilt_from_camera_ = Eigen::Isometry3d::Identity();
  std::string source_;
};

// Reads a turret file. Throws TurretError naming the file and line: unreadable file, bad YAML,
// unknown or missing keys, a zero axis, limits in the wrong order, a direction other than ±1.
TurretModel load_turret(const std::string& path);
TurretModel parse_turret(const std::string& text, const std::string& source);

}  // namespace mocap::turret
