// A volume's calibration from its recorded sessions, start to end, as mocap_volume_calibrate and
// the volume_calibration_solve component run it: each bag of the identified board read into
// sightings (calibration_messages.hpp), the waved session's coverage, the solve
// (volume_calibration.hpp), each camera file written again with its calibrated pose, and a
// report of each camera: its RMS, where it is, how far from where its input file had it. Its
// progress, as it goes, for a bar on the command line and in the page.
//
//   CalibrationSessionResult result = run_calibration_session(session, [](auto& p) { show(p); });
//   for (const std::string& line : report_lines(result)) print(line);
#pragma once

#include <functional>
#include <optional>
#include <stdexcept>
#include <stop_token>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "volume/volume_calibration/calibration_coverage.hpp"
#include "volume/volume_calibration/volume_calibration.hpp"

namespace mocap::volume {

// A bag of the board lying on the floor, its centre at `mark` (world x, y, metres).
struct FloorRecording {
  std::string bag;
  Eigen::Vector2d mark = Eigen::Vector2d::Zero();
};

// "BAG" or "BAG:X,Y"; nullopt when what follows the last ':' looks like a mark but is not
// X,Y in metres. A path whose last ':' is followed by no comma is all path.
std::optional<FloorRecording> parse_floor_recording(const std::string& argument);

struct CalibrationSession {
  std::string waved;                  // the bag of the board waved through the volume
  std::vector<FloorRecording> floor;  // one, or three or more not in a line
  std::vector<std::string> camera_files;
  std::string board = "board_a";
  std::string database;  // the board's constellation database
  std::string output;    // the folder the calibrated camera files are written into
};

// Where a session is: `fraction` of all of it (reading the bags, the solve, placing the floor,
// writing), the stage's name and what it is doing ("iteration 7, RMS 0.412 px").
struct SessionProgress {
  std::string stage;  // "reading", "solving", "writing"
  double fraction = 0;
  std::string detail;
};

// What one bag held: the board's sightings, camera by camera, and what could not be read.
struct RecordingRead {
  std::string path;
  std::vector<size_t> sightings_per_camera;
  std::vector<std::string> problems;  // the reader's, and messages that could not be decoded
};

struct CalibratedCamera {
  std::string name;
  double rms_px = 0;  // over its points in the waved session's solve
  int shots = 0;      // capture times of the solve it saw the board in
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
  // Where its input file had it, and how far the calibration moved and turned it from there.
  std::optional<Eigen::Isometry3d> previous;
  double moved_m = 0, turned_deg = 0;
  std::string file;  // the camera file written
};

struct CalibrationSessionResult {
  std::string board;
  RecordingRead waved;
  std::vector<RecordingRead> floor;
  std::vector<FloorRecording> marks;     // the floor's, as given
  std::vector<CameraCoverage> coverage;  // of the waved session
  int64_t coverage_stamp_ns = 0;         // its latest sighting's capture time
  VolumeCalibration calibration;
  std::vector<CalibratedCamera> cameras;  // in the camera files' order
};

// Unreadable input: a bag, a camera file, a database without the board. (A session that reads
// but cannot calibrate the volume throws VolumeCalibrationError.)
class CalibrationSessionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Runs the session; `progress`, when given, is called as it goes, on this thread. A stop
// requested through `stop` ends it between two messages of a bag or two iterations of the solve
// (VolumeCalibrationError "stopped"). Throws CalibrationSessionError and VolumeCalibrationError.
CalibrationSessionResult run_calibration_session(
    const CalibrationSession& session,
    const std::function<void(const SessionProgress&)>& progress = {}, std::stop_token stop = {});

// The result, line by line, as mocap_volume_calibrate prints it: each bag's sightings, the
// waved coverage, the solve, each placement on the floor, each camera.
std::vector<std::string> report_lines(const CalibrationSessionResult& result);

// What the bags' readers could not read, a line each ("BAG: 3 messages could not be decoded").
std::vector<std::string> problem_lines(const CalibrationSessionResult& result);

// "solve [=========           ]  45 %: solving, iteration 7, RMS 0.412 px".
std::string progress_line(const SessionProgress& progress);

}  // namespace mocap::volume
