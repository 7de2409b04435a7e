// Camera files: ROS camera_info YAML (what camera_calibration writes), read into a model.
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
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::calibration {

struct CameraFile {
  std::string name;
  std::string frame_id;
  std::shared_ptr<const CameraModel> model;
};

// A camera file that cannot be used; the message starts with "FILE:LINE:" where known.
class CameraFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

CameraFile load_camera_file(const std::string& path);
// `source` names the text in error messages.
CameraFile parse_camera_file(const std::string& text, const std::string& source);

}  // namespace mocap::calibration
