// A camera's ConstellationArray (what constellation_identifier publishes) as the calibration's
// BoardSighting: the board's markers by their index in the board's model, each where the camera
// saw it.
#pragma once

#include <optional>

#include <mocap_msgs/msg/constellation_array.hpp>

#include "tracking/constellation_database/constellation_database.hpp"
#include "volume/volume_calibration/volume_calibration.hpp"

namespace mocap::volume {

// `board`'s sighting in `array` by camera `camera`, stamped with its fiducials' capture time;
// nullopt when the array does not hold the board. Lines not of the board and non-finite pixels
// are left out.
std::optional<BoardSighting> board_sighting(const mocap_msgs::msg::ConstellationArray& array,
                                            size_t camera,
                                            const constellations::ConstellationModel& board);

}  // namespace mocap::volume
