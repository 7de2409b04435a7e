// OpenSim's TRC marker trajectories: a header of tab-separated lines (PathFileType 4, the rates,
// counts and units, the marker names, their X/Y/Z columns), then one row per frame: frame number
// (from 1), time (s), and each marker's x y z, empty where it is missing. Y up, as OpenSim reads
// its world: our (x, y, z) as (x, z, -y).
#pragma once

#include <ostream>
#include <string>

#include "recording/motion_export/point_table.hpp"

namespace mocap::motion_export {

// `table`'s points as TRC markers, a row per frame at its time (s since the first frame), the
// data rate the table's. `file_name` goes in the first line, as OpenSim writes it. Metres to
// the nanometre.
void write_trc(std::ostream& out, const std::string& file_name, const PointTable& table);

}  // namespace mocap::motion_export
