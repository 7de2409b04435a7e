// The calibration's JSON configuration (mocap_calibrate CONFIG.json): whatever it holds,
// parse_calibration_config() returns a usable configuration or throws CalibrationConfigError
// naming the file at fault, nothing else. The text up to the first NUL is the configuration;
// each further NUL-separated part is the next data file it names ("data_file"), the last part
// standing for the rest, all in the scratch folder the configuration is read from.
// Configurations with '/' or '\' are skipped, so that no data file lies outside that folder
// (scratch_files.hpp).
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/calibration/calibration_config.hpp>

#include "fuzz/rigid_transform.hpp"
#include "fuzz/scratch_files.hpp"

namespace {

using namespace mocap::calibration;

using fuzz::is_rigid;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string_view> parts =
      fuzz::split_at_nul({reinterpret_cast<const char*>(data), size});
  if (fuzz::could_name_a_path(parts[0])) return 0;
  const std::filesystem::path& folder = fuzz::fresh_scratch_folder("fuzz_calibration_config");
  fuzz::write_files(folder, fuzz::values_after(parts[0], "\"data_file\""),
                    {parts.begin() + 1, parts.end()});
  CalibrationConfig config;
  try {
    config = parse_calibration_config(std::string(parts[0]), "calib.json", folder.string());
  } catch (const CalibrationConfigError& error) {
    // The configuration's own errors name it; a data file's errors name that file.
    const std::string_view what = error.what();
    if (!what.starts_with("calib.json:") && !what.starts_with((folder / "").string())) {
      std::abort();
    }
    return 0;
  }
  for (const TransformSpec& transform : config.transformations) {
    if (transform.value && !is_rigid(*transform.value)) std::abort();
  }
  for (const DataSpec& entry : config.data) {
    if (entry.init && !is_rigid(*entry.init)) std::abort();
    // An entry without a complete shot is an error, and every shot has every corner.
    if (entry.shots.empty()) std::abort();
    for (const Shot& shot : entry.shots) {
      if (shot.points.size() != entry.corners.size()) std::abort();
    }
    for (int corner : entry.corners) {
      if (corner < 0 || static_cast<size_t>(corner) >= entry.object_points.size()) std::abort();
    }
  }
  return 0;
}
