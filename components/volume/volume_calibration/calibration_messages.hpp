// The volume calibration's types and its messages: a camera's ConstellationArray (what
// constellation_identifier publishes) as a BoardSighting, and the coverage, the solve's progress
// and its result as the page reads them (/calibration/coverage, /progress, /result).
#pragma once

#include <optional>

#include <mocap_msgs/msg/calibration_coverage.hpp>
#include <mocap_msgs/msg/calibration_progress.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>
#include <mocap_msgs/msg/volume_calibration_result.hpp>

#include "tracking/constellation_database/constellation_database.hpp"
#include "volume/volume_calibration/calibration_coverage.hpp"
#include "volume/volume_calibration/calibration_session.hpp"
#include "volume/volume_calibration/volume_calibration.hpp"

namespace mocap::volume {

// `board`'s sighting in `array` by camera `camera`, stamped with its fiducials' capture time;
// nullopt when the array does not hold the board. Lines not of the board and non-finite pixels
// are left out.
std::optional<BoardSighting> board_sighting(const mocap_msgs::msg::ConstellationArray& array,
                                            size_t camera,
                                            const constellations::ConstellationModel& board);

// Every camera's coverage, and the session's (the least covered camera's); `latest_ns` stamps
// it (the latest sighting's capture time).
mocap_msgs::msg::CalibrationCoverage coverage_message(const std::vector<CameraCoverage>& cameras,
                                                      const CoverageOptions& options,
                                                      int64_t latest_ns);

mocap_msgs::msg::CalibrationProgress progress_message(const SessionProgress& progress);

mocap_msgs::msg::VolumeCalibrationResult result_message(const CalibrationSessionResult& result);

}  // namespace mocap::volume
