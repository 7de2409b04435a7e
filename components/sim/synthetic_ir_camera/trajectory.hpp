// Where a constellation is over time: the scripted motions of the synthetic camera's scenes.
//
// Every pose is the constellation frame expressed in the camera frame (p_camera = pose *
// p_constellation), the transform the pose estimator estimates. Camera frame: x right, y down,
// z forward (metres). Constellation frame (config/constellations.yaml): origin at the board's
// centre, x along the long side, y along the short side, z out of the board on the side the
// markers face.
//
// Orientations are given as roll, pitch, yaw in degrees relative to the *facing* orientation:
// the board upright in front of the camera, fronto-parallel, markers towards the camera, i.e.
// board x = camera x (right), board y = -camera y (up), board z = -camera z (towards the
// camera). rpy_deg = [0, 0, 0] is that orientation; a board turned 90 degrees or more from it
// shows its back and none of its markers. The angles turn about the board's own axes, like an
// aircraft whose nose is the board's z axis:
//   - yaw about board y (up): positive turns the marker side towards the camera's right (+x);
//   - pitch about board x (right): positive tilts the marker side down (towards camera +y);
//   - roll about board z (towards the camera): positive turns the board counter-clockwise as
//     the camera sees it.
// Composition: R = R_facing * Ry(yaw) * Rx(pitch) * Rz(roll).
#pragma once

#include <string_view>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mocap::synthetic {

// The orientation described above, as a rotation from the constellation to the camera frame.
Eigen::Matrix3d facing_orientation(const Eigen::Vector3d& rpy_deg = Eigen::Vector3d::Zero());

// One pose, forever.
struct StaticTrajectory {
  Eigen::Vector3d position{0, 0, 1.5};  // camera frame, metres
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
};

struct Keyframe {
  double time_s = 0;
  Eigen::Vector3d position{0, 0, 1.5};
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
};

// Positions interpolated linearly and orientations by slerp (shortest arc) between keyframes
// in increasing time. Before the first keyframe and after the last (without `loop`) the pose
// holds; with `loop` the motion repeats with period last.time_s - first.time_s.
struct KeyframeTrajectory {
  std::vector<Keyframe> keyframes;  // at least one, times strictly increasing
  bool loop = false;
};

// The board's centre runs round a circle, keeping its orientation (rpy_deg relative to
// facing). The angle starts at `phase_deg` and grows by 360 degrees per `period_s`.
struct OrbitTrajectory {
  enum class Plane {
    Frontal,     // circle at constant depth, counter-clockwise as the camera sees it
    Horizontal,  // circle in the camera's x-z plane: the board comes closer and goes away
  };
  Eigen::Vector3d centre{0, 0, 2};  // camera frame, metres
  double radius_m = 0.5;
  double period_s = 10;
  double phase_deg = 0;  // 0 = on the +x side of the centre
  Plane plane = Plane::Frontal;
  // Tilts the circle's plane about the camera's x axis (the board keeps its orientation):
  // positive moves the upper part of a frontal circle away from the camera.
  double tilt_deg = 0;
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
};

// Back and forth on the segment from `from` to `to` at constant speed, starting at `from`,
// while the yaw swings sinusoidally by ±yaw_swing_deg around rpy_deg's yaw (starting at the
// centre of the swing, increasing).
struct WalkTrajectory {
  Eigen::Vector3d from{-0.5, 0, 2};
  Eigen::Vector3d to{0.5, 0, 2};
  double speed_mps = 0.3;
  double yaw_swing_deg = 0;
  double swing_period_s = 0;  // 0 = one swing per round trip
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
};

// Fixed position, turning about `axis` (in the board's frame at rest, i.e. after rpy_deg) at
// `rate_deg_s`: axis [0, 0, 1] spins the board in its plane, [0, 1, 0] turns it about its
// vertical axis so that it shows its back half of the time.
struct SpinTrajectory {
  Eigen::Vector3d position{0, 0, 1.5};
  Eigen::Vector3d axis{0, 0, 1};  // need not be normalised; not zero
  double rate_deg_s = 30;
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
};

using Trajectory = std::variant<StaticTrajectory, KeyframeTrajectory, OrbitTrajectory,
                                WalkTrajectory, SpinTrajectory>;

// The pose at scene time `time_s` (seconds; any value, also negative). load_scene checks
// trajectories; one built in code with no keyframes, a period or speed that is not positive,
// or a zero axis throws std::invalid_argument. Keyframe times must increase.
Eigen::Isometry3d pose_at(const Trajectory& trajectory, double time_s);

// "static", "keyframes", "orbit", "walk", "spin": the `type` of the scene file.
std::string_view type_name(const Trajectory& trajectory);

}  // namespace mocap::synthetic
