// OpenSim's TRC marker trajectories: a header of tab-separated lines (PathFileType 4, the rates,
// counts and units, the marker names, their X/Y/Z columns), then one row per frame: frame number
// (from 1), time (s), and each marker's x y z, empty where it is missing. Y up, as OpenSim reads
// its world: our (x, y, z) as (x, z, -y).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "recording/motion_export/body_trajectories.hpp"

namespace mocap::motion_export {

// A body as TRC's markers: its origin and the ends of its three axes, kAxisLength along them
// ("<body>_origin", "<body>_x", "<body>_y", "<body>_z"), a common way analysis tools read a
// rigid body from marker trajectories.
inline constexpr double kAxisLength = 0.1;  // metres

// `trajectories`' frames and the bodies named in `bodies` (each a key of bodies()): rows at the
// frames' times (s since the first), the data rate their median interval's. `file_name` goes in
// the first line, as OpenSim writes it. Positions in metres to the nanometre.
void write_trc(std::ostream& out, const std::string& file_name,
               const BodyTrajectories& trajectories, const std::vector<std::string>& bodies);

}  // namespace mocap::motion_export
