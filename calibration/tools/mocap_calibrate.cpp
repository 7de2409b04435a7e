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
#include <mocap/calibration/calibration_config.hpp>
#include <mocap/calibration/calibration_problem.hpp>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pixart_rig.hpp"

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
  if (reference.empty()) reference = config.cameras.front().name;
  // Read before solving, so that a wrong rig file costs no solver time.
  const Eigen::Isometry3d world_from_reference =
      rig_path.empty() ? Eigen::Isometry3d::Identity() : rig_pose(rig_path, reference);
  CalibrationProblem problem(config, {.robust_scale_px = robust_px});
  const CalibrationReport report = problem.solve();
  fmt::print("{}", report.summary());
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

  // The corners of each image where the whole board is found, as shots of one data entry.
  DataSpec data;
  data.type = "chessboard";
  data.camera = name;
  data.data_file = folder.string();
  data.data_path = folder.string();
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      data.object_points.emplace_back(c * square, r * square, 0.0);
      data.corners.push_back(r * columns + c);
    }
  }
  std::vector<std::vector<cv::Point3f>> cv_objects;
  std::vector<std::vector<cv::Point2f>> cv_images;
  cv::Size size;
  for (size_t i = 0; i < files.size(); ++i) {
    cv::Mat image = cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) {
      fmt::print("skipped {}: not an image\n", files[i].string());
      continue;
    }
    if (size.area() == 0) size = image.size();
    if (image.size() != size) {
      throw CalibrationError(fmt::format("{}: {}x{}, but the first image is {}x{}",
                                         files[i].string(), image.cols, image.rows, size.width,
                                         size.height));
    }
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(image, {columns, rows}, corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      fmt::print("skipped {}: no {}x{} board found\n", files[i].string(), columns, rows);
      continue;
    }
    cv::cornerSubPix(image, corners, {5, 5}, {-1, -1},
                     {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3});
    Shot shot;
    shot.frame = i;
    for (const cv::Point2f& p : corners) shot.points.emplace_back(p.x, p.y);
    data.shots.push_back(std::move(shot));
    cv_images.push_back(corners);
    std::vector<cv::Point3f> object;
    for (const Eigen::Vector3d& p : data.object_points) {
      object.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.0f);
    }
    cv_objects.push_back(std::move(object));
  }
  if (data.shots.empty()) {
    throw CalibrationError(folder.string() + ": no image shows the whole board");
  }
  data.image_width = size.width;
  data.image_height = size.height;

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
