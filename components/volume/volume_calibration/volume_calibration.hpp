// A volume's cameras calibrated from data: a board waved through the volume gives the cameras'
// poses relative to one of them (CalibrationProblem, the rig solver of mocap_calibrate: every
// shot's board pose and every camera's transform fitted to the pixels at once), and the same
// board laid on the floor, at one mark or several, then sets the world frame (floor_frame.hpp).
// The cameras' intrinsics are taken as known (their camera files); the extrinsics are what a
// volume loses when it is set up or bumped.
//
//   VolumeCalibration result = calibrate_volume(cameras, board_markers, waved, {{mark, seen}});
//   for (c ...) save world_from_camera = result.camera_from_world[c].inverse();
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <mocap/calibration/calibration_problem.hpp>
#include <mocap/calibration/camera_model.hpp>

namespace mocap::volume {

// One camera's view of the board at one capture time: each board marker's pixel, or nothing
// where the camera did not see it.
struct BoardSighting {
  int64_t stamp_ns = 0;
  size_t camera = 0;  // index into the cameras
  std::vector<std::optional<Eigen::Vector2d>> pixels;
};

// The board lying still on the floor at a mark: every camera's sightings of it.
struct FloorPlacement {
  // World x, y of the board's origin (the shipped boards' centre), metres.
  Eigen::Vector2d mark = Eigen::Vector2d::Zero();
  std::vector<BoardSighting> sightings;
};

struct CalibrationCamera {
  std::string name;
  std::shared_ptr<const calibration::CameraModel> model;  // the intrinsics, held constant
};

struct VolumeCalibrationOptions {
  // Sightings whose stamps differ by no more than this are one capture time.
  double same_capture_s = 0.002;
  // Of the waved session's capture times with the board whole in two cameras or more, at most
  // this many, evenly spread, go into the solve: its time grows with the shots (a second for
  // 1,300 on one core), and every one of a few minutes' waving still counts.
  size_t max_frames = 6000;
  // Huber loss scale on each point's pixel error: a mis-detected marker cannot drag the fit.
  // 0: plain least squares.
  double robust_scale_px = 1.0;
  // Called after each iteration of the solve (calibration_problem.hpp), on the calling thread;
  // false stops the solve (calibrate_volume then throws VolumeCalibrationError).
  std::function<bool(const calibration::SolveIteration&)> on_iteration{};

  // Why these options cannot be used, naming the field ("max_frames: 0; ..."); nullopt when
  // they can. calibrate_volume throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct VolumeCalibration {
  calibration::CalibrationReport report;
  // Per camera, in the input's order: its pose in the floor's frame (the world).
  std::vector<Eigen::Isometry3d> camera_from_world;
  size_t frames_used = 0;  // capture times of the waved session in the solve
  // Per placement on the floor: the cameras that saw the board whole, its reprojection error
  // over them, and (three marks or more) how far its centre lies from its mark in the world the
  // marks set, metres: a board laid off its mark, or a mark measured wrong.
  struct Placement {
    size_t cameras = 0;
    double rms_px = 0;
    double off_mark_m = 0;
  };
  std::vector<Placement> floor;
};

// Why a volume cannot be calibrated from the sightings: a camera no shot ties to the others,
// a placement on the floor no camera saw, two marks or marks in a line, a solve that did not
// converge.
class VolumeCalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `board`: the board's markers in its frame (metres, planar), indexing the sightings' pixels;
// camera 0 is the reference of the solve. `on_floor`: one placement, whose board's axes are the
// room's, or three or more at marks not in a line, whose centres alone set the frame.
// Throws VolumeCalibrationError, and std::invalid_argument for options that cannot be used.
VolumeCalibration calibrate_volume(const std::vector<CalibrationCamera>& cameras,
                                   const std::vector<Eigen::Vector3d>& board,
                                   const std::vector<BoardSighting>& waved,
                                   const std::vector<FloorPlacement>& on_floor,
                                   const VolumeCalibrationOptions& options = {});

}  // namespace mocap::volume
