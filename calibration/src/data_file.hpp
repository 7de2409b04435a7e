// A calibration data file as read (calibration_config.hpp describes the format): its frames,
// each the cameras that saw the board then.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace mocap::calibration {

struct DataFileEntry {
  std::string camera;
  std::vector<std::optional<Eigen::Vector2d>> points;  // nullopt: not seen
  int line = 0;                                        // of "points", for messages
};

struct DataFile {
  std::string path;
  std::vector<std::vector<DataFileEntry>> frames;
  std::vector<std::string> cameras;  // every camera named, in order of first appearance
};

// Throws CalibrationConfigError naming `path`, the line and the key path.
DataFile read_data_file(const std::string& text, const std::string& path);

// The file's bytes; `error` says why there are none.
std::string read_text(const std::string& path, std::string& error);

}  // namespace mocap::calibration
