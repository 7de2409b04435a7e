// The calibration's configuration file, in the JSON format of the seed's calibration program
// (seed 002 §8: transformations, cameras, data), and the data files it names (seed 002
// Dictionary 7.1, generalised: any object points, any cameras per frame).
//
//   {
//     "transformations": [
//       {"name": "xiCamBoard", "global": false, "constant": false, "prior": false},
//       {"name": "xi12", "global": true, "prior": true, "stiffness": 10,
//        "value": [1, 0, 0, 0, 0, 1.57]}
//     ],
//     "cameras": [
//       {"name": "cam0", "type": "eucm", "constant": false,
//        "value": [0.01, 1, 1175, 1175, 512, 384]},
//       {"name": "cam1", "type": "pinhole", "value": [1175, 1175, 512, 384]}
//     ],
//     "data": [
//       {"type": "ir_data", "camera": "cam1",
//        "transform_chain": [{"name": "xi12", "direct": false},
//                            {"name": "xiCamBoard", "direct": true}],
//        "init": "none",
//        "image_width": 1024, "image_height": 768,
//        "data_file": "board.json",
//        "object": {"points": [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]],
//                   "corners": [0, 1, 2, 3]}}
//     ]
//   }
//
// Defaults: "global", "constant", "prior" false; "direct" true; "stiffness" 1; "corners" every
// object point in order; the image 1024 x 768 (the PixArt sensor). A transformation that is
// constant or has a prior needs a "value". "init" is a transform value, or (as the seed's files
// have it) "none" or the chain's per-shot transformation's name, which leave the start to the
// solver. "data_file" is relative to the configuration's folder.
// Keys starting with '_' are ignored, as the seed's program ignored them: "_points" keeps a
// variant at hand without deleting it. Any other unknown key is an error.
//
// visgeom's configurations run unchanged (seed 002's calibration ran on visgeom). Data entries
// may carry its "parameters" flag list and be of its "images" type: chessboard images, found
// by the program that solves (mocap_calibrate), one frame per image:
//
//       {"type": "images", "camera": "cam0",
//        "transform_chain": [{"name": "xiCamBoard", "direct": true}], "init": "xiCamBoard",
//        "object": {"type": "checkboard", "rows": 6, "cols": 9, "size": 0.03},
//        "parameters": ["show_outliers", "improve_detection", "_check_extraction"],
//        "images": {"prefix": "left/", "names": ["000001.png", "000002.png"]}}
//
// "rows" and "cols" count inner corners; corner i·cols + j is at (j·size, i·size, 0). An image
// is the string prefix + name, relative to the configuration's folder. Entries whose chains
// share a per-shot transformation share a board pose per image index, as in visgeom: the i-th
// image of a stereo pair's two entries is one shot. Flags: "improve_detection" refines the
// corners to a fraction of a pixel; "show_outliers" names the outlying shots' images; visgeom's
// other flags (interactive, drawing, solver switches) have no meaning here and are listed once
// in `ignored_flags`; a leading '_' switches a flag off, as in visgeom; any other flag is an
// error.
//
// A data file is a JSON array of frames (one board position each); a frame is an array of the
// cameras that saw the board then, each {"camera": name, "points": [[u, v], ...]} ("Cam_id" is
// accepted for "camera", as the seed wrote it; "stamp_ns", when the recording was made, is
// optional). A point is null when the camera did not see it: that frame is then not a shot of
// that camera.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mocap::calibration {

struct TransformSpec {
  std::string name;
  // One instance for the whole problem (camera to camera); false: one per shot (board poses).
  bool global = false;
  bool constant = false;  // held at `value`
  bool prior = false;     // tied to `value` with `prior_stiffness`
  // Optional key "stiffness": weight of the prior residual (per metre / per radian).
  double prior_stiffness = 1.0;
  std::optional<Eigen::Isometry3d> value;  // from 3, 6, 7 or 12 numbers (seed 002 §8.2)
};

struct CameraSpec {
  std::string name;
  std::string type;  // one of camera_factory.hpp's kCameraTypes
  bool constant = false;
  std::vector<double> value;  // in the type's order (camera_factory.hpp)
};

struct ChainLink {
  std::string name;
  bool direct = true;  // false: the inverse
};

// One frame of a data file as seen by one camera.
struct Shot {
  // Index of the frame in its data file (shots of one frame share the per-shot transform).
  size_t frame = 0;
  std::vector<Eigen::Vector2d> points;  // in the order of DataSpec::corners
};

struct DataSpec {
  std::string type;    // "ir_data" or "images"
  std::string camera;  // a CameraSpec name
  // camera <- ... <- board, combined left to right: T = T1 * T2 * ...; pixel = project(T * X).
  std::vector<ChainLink> transform_chain;
  std::optional<Eigen::Isometry3d> init;  // starting value of the chain's per-shot transform
  int image_width = 0, image_height = 0;
  // ir_data: the data file as written and resolved against the config's folder. images: the
  // prefix as written, and "images" for every such entry. Entries with the same data_path and
  // per-shot transformation share a pose per frame.
  std::string data_file;
  std::string data_path;
  // visgeom's "parameters" flags that are on (without the ones a '_' switches off).
  std::vector<std::string> flags;
  // images: the files, frame i being image_files[i] (resolved), and the board's inner corners.
  std::vector<std::string> image_files;
  int board_columns = 0, board_rows = 0;
  // "object": {"points": [[x,y,z],...], "corners": [i,...]}
  std::vector<Eigen::Vector3d> object_points;
  // Which object points the data's points are, in order (default 0..n-1).
  std::vector<int> corners;
  // The frames of the data file that hold this camera with all corners. images: empty until
  // the boards are found in the images (image_width and image_height 0 until then too).
  std::vector<Shot> shots;

  bool has_flag(std::string_view flag) const;
};

struct CalibrationConfig {
  std::string source;  // the file
  std::vector<TransformSpec> transformations;
  std::vector<CameraSpec> cameras;
  std::vector<DataSpec> data;
  // visgeom flags that are on somewhere but mean nothing here ("check_extraction", ...), each
  // once, in order of appearance: for one line that says so.
  std::vector<std::string> ignored_flags;
};

// A configuration or data file that cannot be used. One line: the file, the line, the key path
// and what is wrong, e.g. "calib.json:14: transformations[1].value: 3, 6, 7 or 12 numbers, not 5".
class CalibrationConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads the config and every data file it references. Errors (CalibrationConfigError) name the
// file, the line and the key path: unknown or repeated keys (with the nearest known one), wrong
// types, duplicate names, a chain naming an undeclared transformation or camera, a chain without
// exactly one per-shot transformation, camera value counts, image sizes that are not positive,
// malformed JSON (with its line and column), and a data file's own errors with that file's name
// ("ir.json:4: [3][0].points: ..."). A data entry whose camera has no complete frame in its data
// file is an error too: it would calibrate nothing. The files are read by yaml-cpp, which takes
// a little more than JSON (a trailing comma in a list; YAML of the same shape).
CalibrationConfig load_calibration_config(const std::string& path);
// `source` names the text in messages; data files are looked up relative to `base_directory`
// (unless absolute).
CalibrationConfig parse_calibration_config(const std::string& text, const std::string& source,
                                           const std::string& base_directory);

// The transform of 3 ([x, y, theta]: z, x- and y-rotation 0), 6 ([x, y, z, rx, ry, rz]:
// translation and rotation vector), 7 ([x, y, z, qx, qy, qz, qw]: a unit quaternion, within
// 1e-3) or 12 (the rows of [R | t], R a rotation within 1e-4) numbers, seed 002 §8.2.
// Throws std::invalid_argument otherwise ("3, 6, 7 or 12 numbers, not 5", non-finite
// numbers, a quaternion or matrix that is not a rotation).
Eigen::Isometry3d transform_from_values(std::span<const double> values);
// [x, y, z, rx, ry, rz]: the rotation vector's angle in [0, pi].
std::vector<double> transform_to_values6(const Eigen::Isometry3d& transform);

}  // namespace mocap::calibration
