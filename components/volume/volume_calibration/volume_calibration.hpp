// A volume's cameras calibrated from data: a board waved through the volume gives the cameras'
// poses relative to one of them (CalibrationProblem, the rig solver of mocap_calibrate: every
// shot's board pose and every camera's transform fitted to the pixels at once), and the same
// board laid on the floor then sets the world frame (floor_frame.hpp). The cameras' intrinsics
// are taken as known (their camera files); the extrinsics are what a volume loses when it is
// set up or bumped.
//
//   VolumeCalibration result = calibrate_volume(cameras, board_markers, waved, on_floor);
//   for (c ...) save world_from_camera = result.camera_from_world[c].inverse();
#pragma once

#include <cstdint>
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

struct CalibrationCamera {
  std::string name;
  std::shared_ptr<const calibration::CameraModel> model;  // the intrinsics, held constant
};

struct VolumeCalibrationOptions {
  // Sightings whose stamps differ by no more than this are one capture time.
  double same_capture_s = 0.002;
  // Of the waved session's capture times with the board whole in two cameras or more, at most
  // this many, evenly spread, go into the solve (its time grows with the shots).
  size_t max_frames = 400;
  // Huber loss scale on each point's pixel error: a mis-detected marker cannot drag the fit.
  double robust_scale_px = 1.0;
};

struct VolumeCalibration {
  calibration::CalibrationReport report;
  // Per camera, in the input's order: its pose in the floor's frame (the world).
  std::vector<Eigen::Isometry3d> camera_from_world;
  size_t frames_used = 0;    // capture times of the waved session in the solve
  size_t floor_cameras = 0;  // cameras that saw the board on the floor
  double floor_rms_px = 0;   // the floor board's reprojection error over them
};

// Why a volume cannot be calibrated from the sightings: a camera no shot ties to the others,
// no camera that saw the board on the floor, a solve that did not converge.
class VolumeCalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `board`: the board's markers in its frame (metres, planar), indexing the sightings' pixels;
// camera 0 is the reference of the solve. Throws VolumeCalibrationError.
VolumeCalibration calibrate_volume(const std::vector<CalibrationCamera>& cameras,
                                   const std::vector<Eigen::Vector3d>& board,
                                   const std::vector<BoardSighting>& waved,
                                   const std::vector<BoardSighting>& on_floor,
                                   const VolumeCalibrationOptions& options = {});

}  // namespace mocap::volume
