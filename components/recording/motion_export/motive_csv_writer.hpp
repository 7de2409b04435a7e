// OptiTrack Motive's CSV export, as Motive 2 and 3 write it (format 1.23; OptiTrack's "Data
// Export: CSV" page and Motive's own files): CRLF lines; a line of take information (key, value
// pairs); an empty line; the Type, Name, ID and category rows and the axis row ("Frame,Time
// (Seconds),X,Y,Z,W,..."); then a row per frame from frame 0. Rigid bodies first, each its
// rotation quaternion X Y Z W and position X Y Z, then the markers, each its position X Y Z:
// "<body>:Marker<n>" for a labeled marker, "Unlabeled <track>" for the others. Motive's default
// length unit and axes: metres, Y up ((x, z, -y) of ours). Every number "%.6f", a gap as empty
// cells. No quality statistics: Motive's mean marker error is in metres and ours in pixels.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "recording/motion_export/body_trajectories.hpp"
#include "recording/motion_export/marker_trajectories.hpp"

namespace mocap::motion_export {

// A row for each of `frames` (capture stamps, any order, each written once), at its time since
// the first; `bodies` (keys of trajectories.bodies()) then every marker of `markers`. `take_name`
// goes in the take information; its capture start time is the first frame's, local time, as
// Motive writes it. Returns the rows written: the frames, each once.
size_t write_motive_csv(std::ostream& out, const std::string& take_name,
                        const std::vector<int64_t>& frames, const BodyTrajectories& trajectories,
                        const std::vector<std::string>& bodies, const MarkerTrajectories& markers);

}  // namespace mocap::motion_export
