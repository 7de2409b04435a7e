// mocap_volume_calibrate: a volume's cameras calibrated from two recorded sessions
// (volume_calibration.hpp): the board waved through the volume, then laid on the floor where
// the world's origin is to be, or at three or more measured marks, a bag each. Each bag holds
// the cameras' /volume/<camera>/constellations (launch_yaml/volume_calibration.yaml records
// them); the camera files give the intrinsics and the names. Writes each camera file again,
// with its calibrated `pose`, into the output folder, and prints the report
// (calibration_session.hpp: each bag's sightings, the wave's coverage, the solve, each camera's
// RMS and how far it moved from its input file's pose); its progress as a bar on a terminal.
// scripts/calibrate_volume.sh runs the same session in the volume_calibration_solve component,
// whose page shows it.
//
//   mocap_volume_calibrate --waved BAG --floor BAG[:X,Y]... --output DIR [--board NAME]
//                          [--database FILE] CAMERA_FILE...
//
// Exit status: 0 calibrated, 1 the sessions cannot calibrate the volume, 2 bad arguments or
// unreadable files.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <mocap/config_files.hpp>

#include "volume/volume_calibration/calibration_session.hpp"

namespace {

using mocap::volume::CalibrationSession;
using mocap::volume::SessionProgress;

constexpr const char* kUsage =
    "usage: mocap_volume_calibrate --waved BAG --floor BAG[:X,Y]... --output DIR\n"
    "                              [--board NAME] [--database FILE] CAMERA_FILE...\n"
    "  BAG: a recording of /volume/<camera>/constellations (launch_yaml/volume_calibration.yaml)\n"
    "  --floor: the board lying on the floor, its centre at the mark X,Y (metres, default 0,0);\n"
    "           once (its axes are the room's), or at three marks or more not in a line\n"
    "  --board: the board waved and laid on the floor (default board_a), in --database\n"
    "           (default the shipped config/constellations.yaml)\n";

// The session's progress as a bar redrawn in place on a terminal (at most ten times a second),
// and elsewhere a line as each stage begins.
class ProgressDisplay {
 public:
  void operator()(const SessionProgress& progress) {
    if (!on_terminal_) {
      if (progress.stage != stage_)
        std::printf("%s\n", mocap::volume::progress_line(progress).c_str());
      stage_ = progress.stage;
      return;
    }
    const auto now = std::chrono::steady_clock::now();
    if (progress.stage == stage_ && now - drawn_ < std::chrono::milliseconds(100)) return;
    stage_ = progress.stage;
    drawn_ = now;
    std::printf("\r\033[K%s", mocap::volume::progress_line(progress).c_str());
    std::fflush(stdout);
  }
  // Ends the bar's line before the report.
  void finish() const {
    if (on_terminal_ && !stage_.empty()) std::printf("\n");
  }

 private:
  const bool on_terminal_ = isatty(STDOUT_FILENO) == 1;
  std::string stage_;
  std::chrono::steady_clock::time_point drawn_{};
};

int run(const CalibrationSession& session) {
  ProgressDisplay display;
  mocap::volume::CalibrationSessionResult result;
  try {
    result = mocap::volume::run_calibration_session(
        session, [&](const SessionProgress& progress) { display(progress); });
  } catch (const mocap::volume::VolumeCalibrationError& e) {
    display.finish();
    fmt::print(stderr, "cannot calibrate the volume: {}\n", e.what());
    return 1;
  } catch (const mocap::volume::CalibrationSessionError& e) {
    display.finish();
    fmt::print(stderr, "{}\n", e.what());
    return 2;
  }
  display({"done", 1, ""});
  display.finish();
  for (const std::string& line : mocap::volume::problem_lines(result)) {
    fmt::print(stderr, "{}\n", line);
  }
  for (const std::string& line : mocap::volume::report_lines(result)) fmt::print("{}\n", line);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CalibrationSession arguments;
  arguments.database = mocap::config_file("constellations.yaml");
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        fmt::print(stderr, "{} needs a value\n{}", argument, kUsage);
        std::exit(2);
      }
      return argv[++i];
    };
    if (argument == "--waved") {
      arguments.waved = value();
    } else if (argument == "--floor") {
      std::optional<mocap::volume::FloorRecording> bag =
          mocap::volume::parse_floor_recording(value());
      if (!bag) {
        fmt::print(stderr, "--floor {}: the mark after ':' is not X,Y in metres\n", argv[i]);
        return 2;
      }
      arguments.floor.push_back(*bag);
    } else if (argument == "--output") {
      arguments.output = value();
    } else if (argument == "--board") {
      arguments.board = value();
    } else if (argument == "--database") {
      arguments.database = value();
    } else if (argument == "-h" || argument == "--help") {
      fmt::print("{}", kUsage);
      return 0;
    } else if (argument.starts_with("--")) {
      fmt::print(stderr, "unknown option {}\n{}", argument, kUsage);
      return 2;
    } else {
      arguments.camera_files.push_back(argument);
    }
  }
  if (arguments.waved.empty() || arguments.floor.empty() || arguments.output.empty() ||
      arguments.camera_files.empty()) {
    fmt::print(stderr, "--waved, --floor, --output and camera files are needed\n{}", kUsage);
    return 2;
  }
  try {
    return run(arguments);
  } catch (const std::exception& e) {  // unreadable bags, camera files, databases
    fmt::print(stderr, "{}\n", e.what());
    return 2;
  }
}
