// A swarm's robots in the marker cloud (marker_cloud.hpp), frame after frame: identical
// bodies told apart by their tracks, and robots of one marker.
//
// Each frame:
//  1. Tracked robots. Every tracked robot's markers are predicted (the SE(3) constant-velocity
//     Kalman filter of body_motion.hpp; for a robot of one marker, its linear half), and all of
//     them are assigned to the cloud's markers at once, at the least total squared distance,
//     each within `gate_m` of its prediction (min_cost_assignment.hpp, per group of robots
//     whose gates overlap): robots that pass close by each other keep their own markers. The
//     gate widens with the time since the robot's last measurement as far as the motion
//     model's acceleration allows (three of its sigmas), so that a fusion stalled for a tenth
//     of a second (a busy machine) still finds each robot where its motion took it. A
//     robot of several markers is measured by the best rigid fit of its layout to the markers
//     it got (`min_markers` at least, none further off than `max_fit_sigmas` of its own
//     sigmas); a robot of one marker by its marker. The measurement corrects the robot's filter,
//     whose pose, velocities and covariances are what the robot's pose says.
//  2. Robots to find: those not found yet, near their initial positions (or where they were
//     re-seeded) within `start_radius_m`, among markers not known to move faster than
//     `start_speed_mps` (a robot flying past another's start is not taken for it), and those
//     lost (missed in the frames of `lost_after_s`), near where their last velocity carries
//     them from where they were last, within a radius that grows with their layout's top speed
//     and the time lost, up to `max_search_radius_m` (where the carrying stops too: a pair
//     that crossed while lost is not found swapped). Only markers no robot took this frame are
//     looked at: a lost robot never takes another's markers. Robots of several markers first
//     (their layout found among the markers by its distances, within `layout_tolerance_m`,
//     nearest where the robot is looked for first), then robots of one marker. A find goes
//     only to the robot of its layout looked for nearest to it, among all whose search reaches
//     it (those that could not take it too: a robot not yet at rest at its start is taken by
//     no one), and the robots are given what was found at the least total squared distance
//     from where each is looked for. A robot found starts a new filter.
//
//   SwarmTracker swarm(load_swarm("robots.yaml", SwarmTrackerOptions{}.layout_tolerance_m));
//   std::vector<SwarmRobotPose> poses = swarm.track(stamp_ns, cloud);
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tracking/body_motion/body_motion.hpp"
#include "volume/marker_cloud/marker_cloud.hpp"
#include "volume/swarm/swarm_database.hpp"

namespace mocap::volume {

struct SwarmTrackerOptions {
  // How far a marker may be from where a tracked robot's motion puts one of its markers
  // (metres). At 240 Hz a robot at 3 m/s moves 12.5 mm a frame, which the velocity predicts.
  double gate_m = 0.01;
  // How far a measured distance between two markers may be from the layout's when a robot is
  // searched for (metres), as in the rigid bodies' identification; also how close a layout may
  // come to mapping onto itself (swarm_database.hpp).
  double layout_tolerance_m = 0.002;
  // A marker further from where the robot's fitted layout puts it than this many of its own
  // sigmas (the cloud's covariance) is not the robot's: left out, and the layout fitted again.
  double max_fit_sigmas = 6;
  // Fewest of a layout's markers that pose a robot of several (at least 3).
  int min_markers = 3;
  // A robot not found yet is looked for this close to its initial (or re-seeded) position,
  double start_radius_m = 0.1;
  // among markers not known to move faster than this (m/s; a marker measured at 240 Hz to
  // 0.07 mm seems to move at about 0.03 m/s when still; in its first frame its speed is unknown).
  double start_speed_mps = 0.25;
  // A tracked robot missed in every frame for this long is lost (seconds). Only frames count:
  // across a stall of the fusion, the robot is looked for where its motion took it.
  double lost_after_s = 0.05;
  // The widest a lost robot is looked for (metres).
  double max_search_radius_m = 1.0;
  // How quickly a robot may change its speed and turn rate: the filter's white-noise
  // acceleration densities. At 240 Hz the cloud measures a marker to about 0.07 mm; a swarm's
  // robots change their speed by under a metre per second within a second. Measured on every
  // swarm scene (swarm_bench): a linear density of 0.15 m²/s³ gives the least position error
  // (median up to 0.098 mm; 0.3: up to 0.101 mm, from the noise it smooths less), the flights'
  // turns and take-offs included.
  tracking::BodyMotionOptions motion = {.linear_acceleration_density = 0.15,
                                        .angular_acceleration_density = 1.0};

  // Why these options cannot be used, naming the field ("gate_m: 0 is not above 0"); nullopt
  // when they can. SwarmTracker's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// The orientation variance (rad²) of a robot of one marker, whose orientation is unknown.
inline constexpr double kUnknownOrientationVariance = 1e9;

struct SwarmRobotPose {
  size_t robot = 0;  // index in the database's robots
  // A robot of one marker: its marker's position, the identity rotation.
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
  bool orientation_known = false;
  // Over (x, y, z, rx, ry, rz), the rotation's error a small world-frame angle applied on the
  // left; a robot of one marker has kUnknownOrientationVariance on the rotation's diagonal.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // The filter's; known from a track's second frame on.
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // world frame, m/s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world frame, rad/s
  bool velocity_known = false;
  // Over (vx, vy, vz, wx, wy, wz); a robot of one marker: kUnknownOrientationVariance for w.
  Eigen::Matrix<double, 6, 6> velocity_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // For each of its layout's markers, the index of the cloud marker it is, or -1.
  std::vector<int> markers;
  int markers_used = 0;
  double fit_rms_m = 0;       // of its layout fitted to its markers, before the filter
  bool found_afresh = false;  // not tracked in the frame before
};

// What became of the robots in one frame.
struct SwarmCounts {
  int tracked = 0;    // posed from their tracks
  int found = 0;      // found afresh (first time, re-seeded, or after being lost)
  int searching = 0;  // not posed: not found yet, lost, or coasting
};

class SwarmTracker {
 public:
  // Throws std::invalid_argument for bad options.
  explicit SwarmTracker(SwarmDatabase swarm, SwarmTrackerOptions options = {});

  // One frame's cloud to the robots posed in it, in database order. `claimed`, when not empty,
  // marks (index by index) cloud markers another tracker has taken: a body of its own.
  std::vector<SwarmRobotPose> track(int64_t stamp_ns, const std::vector<CloudMarker>& cloud,
                                    const std::vector<char>& claimed = {});

  // The robot was carried to `position`: it is looked for there, as at its start. False for a
  // name not in the swarm.
  bool reseed(const std::string& name, const Eigen::Vector3d& position);

  const SwarmDatabase& swarm() const { return swarm_; }
  const SwarmCounts& counts() const { return counts_; }

 private:
  struct Robot {
    // Tracked: one of the two filters (several markers: the pose; one marker: the position).
    std::optional<tracking::BodyMotionFilter> body;
    std::optional<tracking::PointMotionFilter> point;
    int64_t stamp_ns = 0;                    // of its last measurement
    std::optional<int64_t> missed_since_ns;  // the first frame it was missed in since
    bool tracked() const { return body || point; }
    void forget() {
      body.reset();
      point.reset();
    }
    // Where it is looked for while not tracked, and since when it is lost (nullopt: not lost
    // but not found yet, or re-seeded: the start radius); a lost robot's velocity then.
    Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
    std::optional<int64_t> lost_since_ns;
    Eigen::Vector3d lost_velocity = Eigen::Vector3d::Zero();
  };
  struct Found {
    std::vector<int> markers;  // per layout marker
    Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
    double rms_m = 0;
    Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  };

  // Where and how far a robot not tracked is looked for.
  struct Search {
    Eigen::Vector3d centre;
    double radius_m = 0;
    bool at_rest = false;  // among markers at rest only: a start or a re-seed
  };
  Search search(const Robot& robot, size_t layout, int64_t stamp_ns) const;
  // fit() of a robot found from scratch. Where a rotation maps the markers found (per layout
  // marker, -1: none) onto themselves relabelled (three markers of a nearly isosceles
  // triangle: the robot may be turned half a turn), the relabelling whose pose is upright,
  // if exactly one is; nullopt otherwise. The relabellings are kept per layout and markers.
  std::optional<Found> upright_fit(size_t layout, const std::vector<int>& markers,
                                   const std::vector<CloudMarker>& cloud);
  // The layout's pose from the cloud markers given per layout marker (-1: none), the worst
  // left out while it is beyond max_fit_sigmas, with the pose's covariance from the markers';
  // nullopt when too few remain.
  std::optional<Found> fit(size_t layout, std::vector<int> markers,
                           const std::vector<CloudMarker>& cloud) const;
  // The robot's filter started (afresh) or corrected with what was found.
  SwarmRobotPose posed(size_t robot, int64_t stamp_ns, const Found& found, bool afresh);

  SwarmDatabase swarm_;
  SwarmTrackerOptions options_;
  std::vector<Robot> robots_;
  SwarmCounts counts_;
  // (layout, its markers found) -> the relabellings a rotation makes of them, the identity too
  std::map<std::pair<size_t, std::vector<int>>, std::vector<std::vector<size_t>>> relabellings_;
};

}  // namespace mocap::volume
