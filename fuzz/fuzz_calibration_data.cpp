// A calibration data file (calibration_config.hpp: frames of the cameras' board points), as
// mocap_calibration_record writes it and mocap_calibrate reads it through its configuration:
// the input is the file, read by the seed's stereo configuration for each pair of camera names
// the project's files use. Each read returns the shots or throws CalibrationConfigError naming
// the data file or the configuration, nothing else. What reads must go through the writer,
// write_data_file(), and back to the same shots in the same frames.
// The configurations are fixed and name the data file only, in this process's scratch folder.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <mocap/calibration/board_recording.hpp>
#include <mocap/calibration/calibration_config.hpp>

#include "fuzz/scratch_files.hpp"

namespace {

using namespace mocap::calibration;

// The seed's stereo configuration (test_calibration_config.cpp) for cameras @A and @B, their
// shots in the data file @F.
constexpr std::string_view kConfig = R"({
  "transformations": [{"name": "board"}, {"name": "stereo", "global": true}],
  "cameras": [{"name": "@A", "type": "eucm", "value": [0.01, 1, 1175, 1175, 512, 384]},
              {"name": "@B", "type": "eucm", "value": [0.01, 1, 1175, 1175, 512, 384]}],
  "data": [
    {"type": "ir_data", "camera": "@A", "transform_chain": [{"name": "board"}], "data_file": "@F",
     "object": {"points": [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]]}},
    {"type": "ir_data", "camera": "@B",
     "transform_chain": [{"name": "stereo", "direct": false}, {"name": "board"}], "data_file": "@F",
     "object": {"points": [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]]}}]})";

std::string config_for(const std::string& a, const std::string& b, const std::string& file) {
  std::string text(kConfig);
  auto put = [&](std::string_view mark, const std::string& value) {
    for (size_t at = text.find(mark); at != std::string::npos;
         at = text.find(mark, at + value.size())) {
      text.replace(at, mark.size(), value);
    }
  };
  put("@A", a);
  put("@B", b);
  put("@F", file);
  return text;
}

// The cameras of the project's data files: the seed's, mocap_calibration_record's for the
// shipped rig, and the write_data_file test's ("camera3": a camera it was given no name for).
const std::pair<std::string, std::string> kCameraPairs[] = {
    {"cam0", "cam1"}, {"camera2", "camera3"}, {"left", "camera3"}};

std::optional<CalibrationConfig> read(const std::filesystem::path& folder, const std::string& a,
                                      const std::string& b, const std::string& file) {
  try {
    return parse_calibration_config(config_for(a, b, file), "calib.json", folder.string());
  } catch (const CalibrationConfigError& error) {
    const std::string_view what = error.what();
    if (!what.starts_with("calib.json:") && !what.starts_with((folder / file).string() + ":")) {
      std::abort();
    }
    return std::nullopt;
  }
}

// Writes the shots of `config` as mocap_calibration_record does, one frame a second, and reads
// them back.
void write_and_read_back(const std::filesystem::path& folder, const CalibrationConfig& config) {
  std::vector<BoardShot> shots;
  std::map<int, std::string> names;
  for (size_t e = 0; e < config.data.size(); ++e) {
    names[static_cast<int>(e)] = config.data[e].camera;
    for (const Shot& shot : config.data[e].shots) {
      BoardShot board{static_cast<int>(e), static_cast<int64_t>(shot.frame) * 1'000'000'000, {}};
      std::copy(shot.points.begin(), shot.points.end(), board.points.begin());
      // The writer keeps 1/1000 of a pixel: of a sensor's pixels, not of any double.
      for (const Eigen::Vector2d& point : board.points) {
        if (!(point.cwiseAbs().maxCoeff() < 1e9)) return;
      }
      shots.push_back(board);
    }
  }
  write_data_file((folder / "written.json").string(), shots, names);
  const auto again = read(folder, config.data[0].camera, config.data[1].camera, "written.json");
  if (!again) std::abort();
  std::map<size_t, size_t> frame_of;  // read -> read back
  for (size_t e = 0; e < config.data.size(); ++e) {
    const std::vector<Shot>& before = config.data[e].shots;
    const std::vector<Shot>& after = again->data[e].shots;
    if (before.size() != after.size()) std::abort();
    for (size_t s = 0; s < before.size(); ++s) {
      if (frame_of.emplace(before[s].frame, after[s].frame).first->second != after[s].frame) {
        std::abort();
      }
      for (size_t p = 0; p < before[s].points.size(); ++p) {
        if (!((before[s].points[p] - after[s].points[p]).cwiseAbs().maxCoeff() <= 1e-3)) {
          std::abort();
        }
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path& folder = fuzz::fresh_scratch_folder("fuzz_calibration_data");
  fuzz::write_files(folder, {"board.json"}, {{reinterpret_cast<const char*>(data), size}});
  for (const auto& [a, b] : kCameraPairs) {
    if (const auto config = read(folder, a, b, "board.json")) write_and_read_back(folder, *config);
  }
  return 0;
}
