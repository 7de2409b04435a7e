// A swarm's robots: many of one marker layout (identical quadrotors) or of a single marker,
// told apart by their tracks from where each starts, as crazyswarm's `crazyflies.yaml` places
// its robots. A YAML file lists the layouts and the robots:
//
//   layouts:
//     - name: marker_deck                 # four markers about 3 cm apart
//       markers: [[0, 0.02, 0], [0.015, -0.01, 0], [-0.015, -0.012, 0.005], [0, 0, 0.02]]
//       top_speed_mps: 3                  # how fast a lost robot may have gone (default 3)
//     - name: single
//       markers: [[0, 0, 0]]              # one marker: a position, no orientation
//   robots:
//     - {name: cf01, layout: marker_deck, initial_position: [-1.0, -1.0, 0.02]}
//     - {name: ground_1, layout: single, initial_position: [0.5, 0, 0.1], streaming_id: 40}
//
// (streaming_id, optional: the robot's id to NatNet clients, as rigid_body_database.hpp's.)
//
// A layout has one marker, or three or more no rotation maps onto each other (its orientation
// would be ambiguous); two robots of one layout start further apart than the layout's size
// (its widest marker distance; kMinMarkerSeparation for one marker), or which is which would be
// a guess from the first frame.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "volume/rigid_bodies/rigid_body_database.hpp"

namespace mocap::volume {

struct MarkerLayout {
  std::string name;
  std::vector<Eigen::Vector3d> markers;  // metres, in the robot's frame
  double top_speed_mps = 3;

  // Its widest marker distance (metres), kMinMarkerSeparation for one marker.
  double size_m() const;
};

struct SwarmRobot {
  std::string name;
  size_t layout = 0;                                           // index in SwarmDatabase::layouts
  Eigen::Vector3d initial_position = Eigen::Vector3d::Zero();  // world frame, metres
  std::optional<int32_t> streaming_id = std::nullopt;
};

struct SwarmDatabase {
  std::vector<MarkerLayout> layouts;
  std::vector<SwarmRobot> robots;
};

// The swarm of `text` (`source` names it in messages: "robots.yaml:7: ..."). Throws
// RigidBodyError for a malformed file, a layout of two markers or with markers closer than
// kMinMarkerSeparation or that a rotation maps onto itself within `tolerance` (metres), a name
// or a streaming_id given twice, a robot of an unknown layout, and two robots of one layout that
// start closer than its size.
SwarmDatabase parse_swarm(const std::string& text, const std::string& source, double tolerance);
SwarmDatabase load_swarm(const std::string& path, double tolerance);

}  // namespace mocap::volume
