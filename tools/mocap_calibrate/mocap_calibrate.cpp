// mocap_calibrate: camera calibration with Ceres (calibration_problem.hpp), from a visgeom-style
// configuration (seed 002 §8) or from chessboard images.
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/calibration/calibration_config.hpp>
#include <mocap/calibration/calibration_problem.hpp>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <opencv2/calib3d.hpp>

#include "mocap_calibrate/board_images.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"

namespace {

namespace fs = std::filesystem;
using namespace mocap::calibration;

constexpr const char* kUsage = R"(usage:
  mocap_calibrate CONFIG.json [--output DIR] [--reference CAMERA] [--rig RIG.yaml]
                  [--robust PIXELS]
  mocap_calibrate --images DIR --board COLSxROWS --square METRES [--output DIR] [--name NAME]

  CONFIG.json   transformations, cameras and data as in seed 002 §8 (calibration/README.md);
                solves every camera's intrinsics, the board poses and the transforms between
                cameras, prints the report and writes DIR/<camera>.yaml for each camera: its
                model, intrinsics and pose relative to the reference camera (default: the
                first), which pose_estimator and pixart_localizer read
  --rig         a PixArt rig file: writes every pose in the rig's world frame instead,
                world_from_reference x reference_from_camera, so that the rig's `camera_file:`
                entries can use the files as they are. The reference camera (by name) is
                taken to hang exactly where the rig file says: the board shots tell where
                the cameras are relative to each other, not where the rig is in the room
  --images      a folder of chessboard images (PNG, JPEG, ...); COLSxROWS counts the inner
                corners, --square is the side of a square; solves a pinhole camera with
                distortion (k1 k2 p1 p2 k3) and writes DIR/NAME.yaml (NAME: camera)
  --output      where the camera files go (default: the current folder)
  --robust      Huber loss with this scale, pixels (default: none)
exit status: 0 calibrated; 1 the input cannot be calibrated or the solver did not converge;
2 bad arguments
)";

[[noreturn]] void usage_error(const std::string& message) {
  fmt::print(stderr, "mocap_calibrate: {}\n\n{}", message, kUsage);
  std::exit(2);
}

double parse_positive(const std::string& option, const std::string& text) {
  double value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !(value > 0)) {
    usage_error(fmt::format("{} {}: expected a positive number", option, text));
  }
  return value;
}

// Writes one camera file per calibrated camera, placed by `poses` (camera_from_frame, the frame
// being the reference camera's or the rig's world); returns the paths.
std::vector<std::string> write_cameras(
    const CalibrationReport& report,
    const std::vector<std::pair<std::string, Eigen::Isometry3d>>& poses,
    const CalibrationConfig& config, const fs::path& output) {
  fs::create_directories(output);
  std::vector<std::string> written;
  for (const CameraResult& camera : report.cameras) {
    int width = 0, height = 0;
    for (const DataSpec& data : config.data) {
      if (data.camera == camera.name) {
        width = data.image_width;
        height = data.image_height;
        break;
      }
    }
    if (width == 0) continue;  // no data: nothing was calibrated
    CameraFile file;
    file.name = camera.name;
    file.frame_id = camera.name;
    file.model = make_camera_model(camera.type, width, height, camera.value);
    for (const auto& [name, camera_from_frame] : poses) {
      if (name == camera.name) file.world_from_camera = camera_from_frame.inverse();
    }
    const fs::path path = output / (camera.name + ".yaml");
    save_camera_file(path.string(), file);
    written.push_back(path.string());
  }
  return written;
}

// Where the rig file `rig_path` hangs the camera `reference`: world_from_reference.
Eigen::Isometry3d rig_pose(const std::string& rig_path, const std::string& reference) {
  const mocap::pixart::Rig rig = mocap::pixart::load_rig(rig_path);
  for (const mocap::pixart::RigCamera& camera : rig.cameras) {
    if (camera.name == reference) return camera.world_from_camera;
  }
  throw CalibrationError(
      fmt::format("{}: no camera named '{}' (the reference camera) to place the others from",
                  rig_path, reference));
}

int calibrate_config(const std::string& config_path, const fs::path& output, std::string reference,
                     const std::string& rig_path, double robust_px) {
  CalibrationConfig config = load_calibration_config(config_path);
  if (config.cameras.empty()) throw CalibrationError(config_path + ": no cameras");
  if (!config.ignored_flags.empty()) {
    fmt::print("visgeom flags without a meaning here, ignored: {}\n",
               fmt::join(config.ignored_flags, ", "));
  }
  for (size_t d = 0; d < config.data.size(); ++d) {
    DataSpec& data = config.data[d];
    if (data.type != "images") continue;
    find_board_shots(data, fmt::format("{}: data[{}]", config_path, d),
                     data.has_flag("improve_detection"));
  }
  if (reference.empty()) reference = config.cameras.front().name;
  // Read before solving, so that a wrong rig file costs no solver time.
  const Eigen::Isometry3d world_from_reference =
      rig_path.empty() ? Eigen::Isometry3d::Identity() : rig_pose(rig_path, reference);
  CalibrationProblem problem(config, {.robust_scale_px = robust_px});
  const CalibrationReport report = problem.solve();
  fmt::print("{}", report.summary());
  // visgeom's show_outliers shows the outlying images; the report names them here.
  for (const ShotResult& shot : report.shots) {
    const DataSpec& data = config.data[shot.data];
    if (shot.outlier && data.has_flag("show_outliers") && shot.frame < data.image_files.size()) {
      fmt::print("outlier image: {} (data[{}], RMS {:.3f} px)\n", data.image_files[shot.frame],
                 shot.data, shot.rms_px);
    }
  }
  if (!report.converged) {
    fmt::print(stderr, "mocap_calibrate: {}: the solver did not converge: {}\n", config_path,
               report.termination);
    return 1;
  }
  std::vector<std::pair<std::string, Eigen::Isometry3d>> poses = problem.camera_poses(reference);
  for (auto& [name, camera_from_frame] : poses) {
    camera_from_frame = camera_from_frame * world_from_reference.inverse();
  }
  for (const std::string& path : write_cameras(report, poses, config, output)) {
    fmt::print("wrote {}\n", path);
  }
  return 0;
}

int calibrate_chessboard(const fs::path& folder, const std::string& board, double square,
                         const fs::path& output, const std::string& name) {
  int columns = 0, rows = 0;
  if (std::sscanf(board.c_str(), "%dx%d", &columns, &rows) != 2 || columns < 2 || rows < 2) {
    usage_error("--board " + board + ": expected COLSxROWS of inner corners, e.g. 9x6");
  }
  if (!fs::is_directory(folder)) {
    throw CalibrationError(folder.string() + ": not a folder of images");
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());

  // One data entry: the images in name order, a shot each where the whole board shows.
  DataSpec data;
  data.type = "images";
  data.camera = name;
  data.data_file = folder.string();
  data.data_path = "images";
  data.board_columns = columns;
  data.board_rows = rows;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      data.object_points.emplace_back(c * square, r * square, 0.0);
      data.corners.push_back(r * columns + c);
    }
  }
  for (const fs::path& file : files) data.image_files.push_back(file.string());
  find_board_shots(data, folder.string(), true);
  std::vector<std::vector<cv::Point3f>> cv_objects;
  std::vector<std::vector<cv::Point2f>> cv_images;
  for (const Shot& shot : data.shots) {
    std::vector<cv::Point2f> corners;
    for (const Eigen::Vector2d& p : shot.points) {
      corners.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    }
    cv_images.push_back(std::move(corners));
    std::vector<cv::Point3f> object;
    for (const Eigen::Vector3d& p : data.object_points) {
      object.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.0f);
    }
    cv_objects.push_back(std::move(object));
  }
  const cv::Size size(data.image_width, data.image_height);

  // A starting camera from the boards' homographies.
  const cv::Mat k = cv::initCameraMatrix2D(cv_objects, cv_images, size);
  CalibrationConfig config;
  config.source = folder.string();
  config.transformations.push_back({"board", false, false, false, 1.0, std::nullopt});
  config.cameras.push_back({name,
                            "pinhole",
                            false,
                            {k.at<double>(0, 0), k.at<double>(1, 1), k.at<double>(0, 2),
                             k.at<double>(1, 2), 0, 0, 0, 0, 0}});
  data.transform_chain = {{"board", true}};
  config.data.push_back(std::move(data));

  CalibrationProblem problem(config);
  const CalibrationReport report = problem.solve();
  fmt::print("{}", report.summary());
  if (!report.converged) {
    fmt::print(stderr, "mocap_calibrate: {}: the solver did not converge: {}\n", folder.string(),
               report.termination);
    return 1;
  }
  for (const std::string& path : write_cameras(report, {}, config, output)) {
    fmt::print("wrote {}\n", path);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    fmt::print("{}", kUsage);
    return args.empty() ? 2 : 0;
  }
  std::string config, images, board, reference, rig, name = "camera";
  fs::path output = ".";
  double square = 0, robust = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    auto value = [&](const char* option) -> const std::string& {
      if (i + 1 >= args.size()) usage_error(fmt::format("{} needs a value", option));
      return args[++i];
    };
    if (args[i] == "--output") {
      output = value("--output");
    } else if (args[i] == "--reference") {
      reference = value("--reference");
    } else if (args[i] == "--rig") {
      rig = value("--rig");
    } else if (args[i] == "--robust") {
      robust = parse_positive("--robust", value("--robust"));
    } else if (args[i] == "--images") {
      images = value("--images");
    } else if (args[i] == "--board") {
      board = value("--board");
    } else if (args[i] == "--square") {
      square = parse_positive("--square", value("--square"));
    } else if (args[i] == "--name") {
      name = value("--name");
    } else if (args[i].starts_with("--")) {
      usage_error("unknown option " + args[i]);
    } else if (config.empty()) {
      config = args[i];
    } else {
      usage_error("one configuration file, not " + config + " and " + args[i]);
    }
  }
  try {
    if (!images.empty()) {
      if (!config.empty()) usage_error("either a configuration file or --images, not both");
      if (!rig.empty()) usage_error("--rig places the cameras of a configuration, not --images");
      if (board.empty() || square == 0) usage_error("--images needs --board and --square");
      return calibrate_chessboard(images, board, square, output, name);
    }
    if (config.empty()) usage_error("no configuration file");
    return calibrate_config(config, output, reference, rig, robust);
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_calibrate: {}\n", e.what());
    return 1;
  }
}
