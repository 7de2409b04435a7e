// C3D, the biomechanics and animation standard (the C3D User Guide, c3d.org): a 512-byte header
// block, the parameter blocks (groups POINT, ANALOG, TRIAL, MANUFACTURER) and the 3D point data
// in the real-number (float) format, Intel byte order. Z up as our world is, millimetres as
// analysis tools expect by default.
#pragma once

#include <ostream>
#include <stdexcept>

#include "recording/motion_export/point_table.hpp"

namespace mocap::motion_export {

struct C3dError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// `table` as C3D: a frame per table frame (1 to n; past 65535 the header's last frame stays
// 65535 and TRIAL:ACTUAL_END_FIELD holds the count, as the guide says), POINT:RATE the table's.
// Points: POINT:LABELS (and LABELS2, LABELS3, ... past 255 points) with their DESCRIPTIONS,
// UNITS "mm". A sample: x y z and a fourth word whose high byte is the cameras that saw it
// (cameras 0 to 6: C3D has seven bits) and whose residual byte is 0 (ours is measured in pixels,
// which C3D's residual, in point units, cannot hold); a gap: 0 0 0 and -1, as C3D marks an
// invalid point. Throws C3dError for what C3D cannot hold: more than 32767 points, a name past
// 255 characters, a rate of zero (fewer than two frames).
void write_c3d(std::ostream& out, const PointTable& table);

}  // namespace mocap::motion_export
