// A swarm flying through a volume, with each robot's true pose at any time: the scenes the
// swarm tracker is measured on. A robot follows legs one after the other (a straight flight,
// a circle, a wander about a point); its heading turns at a steady rate and it tilts a little,
// as a quadrotor does when it flies.
//
// The builders make the scenes of the swarm issue: a take-off from a grid, a formation flight,
// pairs crossing a few centimetres apart, two robots exchanging places, and random flight that
// keeps a minimum separation.
//
//   SwarmScene scene = takeoff_grid(layout, 10, 5, 0.3, 1.0, 2.0);
//   Eigen::Isometry3d truth = scene.pose(robot, time_s);
//   std::vector<Eigen::Vector3d> markers = scene.markers(time_s);  // every robot's, in order
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/centroid_camera/occluding_sphere.hpp"

namespace mocap::synthetic {

// One part of a robot's flight, from `start_s` to `end_s` (scene seconds).
struct SwarmLeg {
  enum class Kind {
    Line,    // from `from` to `to`, easing in and out (minimum jerk), bowed sideways by `bow_m`
    Circle,  // about `from` (its centre), `radius_m`, at `rate_rad_s`, from angle `phase_rad`
    Wander,  // about `from`, within `radius_m` on each axis: a few sines of `rate_rad_s` and up
  };
  Kind kind = Kind::Line;
  double start_s = 0;
  double end_s = 1;
  Eigen::Vector3d from = Eigen::Vector3d::Zero();
  Eigen::Vector3d to = Eigen::Vector3d::Zero();
  double bow_m = 0;  // Line: to the left of the flight, at its middle
  double radius_m = 0;
  double rate_rad_s = 0;
  double phase_rad = 0;
};

struct SwarmSceneRobot {
  std::string name;
  std::vector<Eigen::Vector3d> markers;  // in the robot's frame, metres
  std::string layout;                    // the markers' name, where a file gave one
  std::vector<SwarmLeg> legs;            // in time order; before the first, at its start
  double yaw_rad = 0;                    // heading at time 0
  double yaw_rate_rad_s = 0;
  double tilt_rad = 0;  // roll and pitch swing up to this
};

struct SwarmScene {
  std::vector<SwarmSceneRobot> robots;
  // Standing in the volume (a pillar's stretch, a person, a ladder): what lies behind one is
  // hidden from a camera, as behind a robot.
  std::vector<OccludingSphere> occluders;
  double duration_s = 0;
  // Seconds every robot stays where its flight starts before the flights begin (the flights'
  // time 0 is then `hold_s`), as a swarm waits on the ground while its tracker comes up and
  // finds each robot at its initial position.
  double hold_s = 0;

  // The robot's pose at `time_s`: its origin where its legs put it.
  Eigen::Isometry3d pose(size_t robot, double time_s) const;
  // Every robot's markers in the world at `time_s`, robot after robot.
  std::vector<Eigen::Vector3d> markers(double time_s) const;
  // The scene's robots and then `other`'s (renamed when a name is taken), over the longer
  // duration; both scenes' occluders.
  SwarmScene with(const SwarmScene& other) const;
  // The same flights and occluders moved by `offset` (world frame, metres).
  SwarmScene shifted(const Eigen::Vector3d& offset) const;
};

// A robot's layout: the four markers of a quadrotor's marker deck, about 3 cm apart (no
// rotation maps them onto each other), or one marker.
std::vector<Eigen::Vector3d> marker_deck_layout();
std::vector<Eigen::Vector3d> single_marker_layout();

// `rows` x `columns` robots on the floor `spacing_m` apart, centred on (0, 0), all rising
// after half a second to `height_m` over `climb_s`, then hovering (wandering a few
// centimetres) until `duration_s`.
SwarmScene takeoff_grid(const std::vector<Eigen::Vector3d>& layout, int rows, int columns,
                        double spacing_m, double height_m, double climb_s, double duration_s,
                        const std::string& prefix = "robot_");
// `count` robots on a circle of `radius_m` at `height_m`, the circle turning at `rate_rad_s`.
SwarmScene formation_circle(const std::vector<Eigen::Vector3d>& layout, int count, double radius_m,
                            double height_m, double rate_rad_s, double duration_s,
                            const std::string& prefix = "robot_");
// `pairs` pairs of robots flying at each other along parallel lines `separation_m` apart
// (centre to centre), passing at `cross_at_s` at `speed_mps`, back and forth until
// `duration_s`; the pairs `pair_spacing_m` apart.
SwarmScene crossing_pairs(const std::vector<Eigen::Vector3d>& layout, int pairs,
                          double separation_m, double speed_mps, double pair_spacing_m,
                          double height_m, double duration_s, const std::string& prefix = "robot_");
// Two robots `distance_m` apart exchanging places over `over_s` every `period_s`, passing
// `separation_m` apart (centre to centre) at the middle.
SwarmScene place_exchange(const std::vector<Eigen::Vector3d>& layout, const Eigen::Vector3d& centre,
                          double distance_m, double separation_m, double over_s, double period_s,
                          double duration_s, const std::string& prefix = "robot_");
// `count` robots wandering at random (seeded) within `extent_m` x `extent_m` at `height_m`,
// each within a cell of its own so that no two come closer than `min_separation_m`.
SwarmScene random_flight(const std::vector<Eigen::Vector3d>& layout, int count, double extent_m,
                         double height_m, double min_separation_m, double duration_s, uint64_t seed,
                         const std::string& prefix = "robot_");

}  // namespace mocap::synthetic
