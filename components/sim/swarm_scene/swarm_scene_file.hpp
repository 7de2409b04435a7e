// A swarm scene from a YAML file: marker layouts, and groups of robots each flying one of the
// builders of swarm_scene.hpp (config/scenes/README.md documents every key):
//
//   duration_s: 60
//   layouts:
//     - {name: marker_deck, markers: [[0, 0.021, 0.012], ...]}
//     - {name: single, markers: [[0, 0, 0]]}
//   groups:
//     - {flight: takeoff_grid, layout: marker_deck, prefix: cf, rows: 5, columns: 10,
//        spacing_m: 0.3, height_m: 1.0, climb_s: 1.5}
//     - {flight: random_flight, layout: single, prefix: rover, count: 50, extent_m: 3.0,
//        height_m: 0.6, min_separation_m: 0.1, seed: 36}
//
// and the robots file the volume's fusion reads for it (swarm_database.hpp): each robot with
// its layout and where the scene has it at time 0.
#pragma once

#include <stdexcept>
#include <string>

#include "sim/swarm_scene/swarm_scene.hpp"

namespace mocap::synthetic {

// Why a swarm scene cannot be used: one line, "FILE:LINE: what is wrong".
class SwarmSceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

SwarmScene parse_swarm_scene(const std::string& text, const std::string& source);
SwarmScene load_swarm_scene(const std::string& path);

// The robots file of `scene` (YAML): its layouts (named as the scene names them) and each
// robot at its place at time 0, with `top_speed_mps` for every layout.
std::string robots_file_of(const SwarmScene& scene, double top_speed_mps = 3);

}  // namespace mocap::synthetic
