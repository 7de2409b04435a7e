// Camera files: ROS camera_info YAML (what camera_calibration writes), read into a model, and
// the same layout extended to the EUCM, UCM and Mei lenses and to where the camera is.
//
//   camera_name: ir_camera            # also the frame id unless `frame_id` is given
//   frame_id: camera_ir_optical       # optional
//   image_width: 1280
//   image_height: 720
//   distortion_model: plumb_bob       # pinhole with k1 k2 p1 p2 k3
//   camera_matrix: {rows: 3, cols: 3, data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]}
//   distortion_coefficients: {rows: 1, cols: 5, data: [k1, k2, p1, p2, k3]}
//
// `rectification_matrix` and `projection_matrix` may be present and are ignored.
//
// An EUCM camera (eucm_camera.hpp) replaces the matrices by its six parameters:
//
//   distortion_model: eucm
//   eucm: {alpha: 0.6, beta: 1.1, fu: 1175, fv: 1175, u0: 512, v0: 384}
//
// and so do the unified cameras (unified_camera.hpp), with visgeom's names:
//
//   distortion_model: ucm
//   ucm: {xi: 0.9, fu: 760, fv: 760, u0: 320, v0: 240}
//   distortion_model: mei
//   mei: {xi: 0.9, k1: -0.1, k2: 0.02, k3: 0, k4: 0.001, k5: -0.0005,
//         fu: 760, fv: 760, u0: 320, v0: 240}
//
// Any of them may say where the camera is, as the calibration of a rig finds it: the camera's
// optical frame in the rig's (world) frame, the quaternion normalised on reading (its norm
// must be within 1e-3 of 1):
//
//   pose: {translation: [x, y, z], rotation: [qx, qy, qz, qw]}   # world_from_camera
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::calibration {

struct CameraFile {
  std::string name;
  std::string frame_id;
  std::shared_ptr<const CameraModel> model;
  // The file's `pose`: the camera's optical frame in the rig's frame.
  std::optional<Eigen::Isometry3d> world_from_camera;
};

// A camera file that cannot be used; the message starts with "FILE:LINE:" where known.
class CameraFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

CameraFile load_camera_file(const std::string& path);
// `source` names the text in error messages.
CameraFile parse_camera_file(const std::string& text, const std::string& source);

// The file text of `camera`: a pinhole in the camera_info layout (with the identity
// rectification and the matching projection matrix, as ROS tools expect), an EUCM camera in its
// own, the pose when there is one. Numbers are written in the shortest form that reads back to
// the same double, so parsing the text gives the same model; the pose reads back to within
// rounding (it is written as a quaternion). Throws std::invalid_argument for a missing model or
// one that has no file form.
std::string format_camera_file(const CameraFile& camera);
// Writes format_camera_file(camera) to `path` (through a temporary file renamed over it, so a
// reader never sees half a file); CameraFileError when it cannot.
void save_camera_file(const std::string& path, const CameraFile& camera);

}  // namespace mocap::calibration
