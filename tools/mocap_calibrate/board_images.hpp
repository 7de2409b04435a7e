// Chessboards in image files: the shots of a configuration's "images" entries (visgeom's form)
// and of `mocap_calibrate --images`.
#pragma once

#include <string>

#include <mocap/calibration/calibration_config.hpp>

namespace mocap::calibration {

// Finds `data`'s board (board_columns x board_rows inner corners) in each of its image files:
// one shot per image that shows the whole board, its frame the image's index, its corners
// refined to a fraction of a pixel where `refine`; sets image_width and image_height. Prints a
// line for each image it skips (not an image, no board). Throws CalibrationConfigError, its
// message starting with `where`, when images differ in size or none shows the board.
void find_board_shots(DataSpec& data, const std::string& where, bool refine);

}  // namespace mocap::calibration
