// mocap_calibrate --images on real image files: chessboards rendered through a distorting
// pinhole camera (OpenCV's model, so the truth does not come from the solver's own formulas),
// written as PNG, found by OpenCV's corner detector in the tool and solved by our solver. The
// camera file it writes must give the camera back.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>

#include "test_support.hpp"

namespace mocap::calibration {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr int kColumns = 9, kRows = 6;  // inner corners
constexpr double kSquare = 0.03;
constexpr int kSamples = 3;  // per pixel and axis: edges a detector can place to a tenth of a pixel

const cv::Matx33d kCamera(610, 0, 322.5, 0, 607, 236.4, 0, 0, 1);
const std::vector<double> kDistortion = {-0.21, 0.06, 0.0007, -0.0004, 0};  // k1 k2 p1 p2 k3

// The board's brightness at a point of its plane (metres from its first inner corner): squares
// of kSquare, a white margin of one square round the (kColumns + 1) x (kRows + 1) squares, grey
// beyond.
double board_brightness(double x, double y) {
  const double column = std::floor(x / kSquare) + 1, row = std::floor(y / kSquare) + 1;
  if (column < -1 || row < -1 || column > kColumns + 1 || row > kRows + 1) return 90;
  if (column < 0 || row < 0 || column > kColumns || row > kRows) return 230;
  return (static_cast<int>(column + row) % 2 == 0) ? 25 : 230;
}

// Every sample's ray through the lens (z = 1), computed once: the camera does not move.
std::vector<cv::Point2d> sample_rays(const cv::Matx33d& camera = kCamera,
                                     const std::vector<double>& distortion = kDistortion) {
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < kHeight * kSamples; ++v) {
    for (int u = 0; u < kWidth * kSamples; ++u) {
      pixels.emplace_back((u + 0.5) / kSamples - 0.5, (v + 0.5) / kSamples - 0.5);
    }
  }
  std::vector<cv::Point2d> rays;
  cv::undistortPoints(pixels, rays, camera, distortion, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-12));
  return rays;
}

// The board seen from `rvec`, `tvec` (camera_from_board), each pixel the mean of its samples.
cv::Mat render(const std::vector<cv::Point2d>& rays, const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  // A ray d meets the board plane (normal n = r's third column, through t) at s d, s = n·t / n·d;
  // the point in board coordinates is rᵀ (s d − t).
  const cv::Vec3d n(r(0, 2), r(1, 2), r(2, 2));
  const double n_t = n.dot(tvec);
  cv::Mat image(kHeight, kWidth, CV_8UC1);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      double sum = 0;
      for (int sv = 0; sv < kSamples; ++sv) {
        for (int su = 0; su < kSamples; ++su) {
          const cv::Point2d& ray = rays[static_cast<size_t>(
              (v * kSamples + sv) * kWidth * kSamples + u * kSamples + su)];
          const cv::Vec3d d(ray.x, ray.y, 1);
          const double s = n_t / n.dot(d);
          const cv::Vec3d on_board = r.t() * (s * d - tvec);
          sum += board_brightness(on_board[0], on_board[1]);
        }
      }
      image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(sum / (kSamples * kSamples));
    }
  }
  return image;
}

// Whether the whole board (margin included) seen from `rvec`, `tvec` lies in the image with
// room to spare.
bool board_inside(const cv::Vec3d& rvec, const cv::Vec3d& tvec, const cv::Matx33d& camera,
                  const std::vector<double>& distortion) {
  const std::vector<cv::Point3d> outline = {{-2 * kSquare, -2 * kSquare, 0},
                                            {(kColumns + 1) * kSquare, -2 * kSquare, 0},
                                            {(kColumns + 1) * kSquare, (kRows + 1) * kSquare, 0},
                                            {-2 * kSquare, (kRows + 1) * kSquare, 0}};
  std::vector<cv::Point2d> corners;
  cv::projectPoints(outline, rvec, tvec, camera, distortion, corners);
  bool inside = true;
  for (const cv::Point2d& p : corners) {
    inside = inside && p.x > 15 && p.y > 15 && p.x < kWidth - 15 && p.y < kHeight - 15;
  }
  return inside;
}

// Board poses 0.45-0.8 m away, centred anywhere in the image, tilted up to 40 degrees, whose
// whole board (margin included) lies in the image with room to spare: the corners of the image
// show the lens's distortion, the tilts its focal length.
std::vector<std::pair<cv::Vec3d, cv::Vec3d>> board_poses(int count, std::mt19937& random) {
  std::uniform_real_distribution<double> depth(0.45, 0.8), tilt(-0.7, 0.7), spin(-0.3, 0.3),
      u(0, kWidth), v(0, kHeight);
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> poses;
  while (static_cast<int>(poses.size()) < count) {
    const cv::Vec3d rvec{tilt(random), tilt(random), spin(random)};
    cv::Matx33d r;
    cv::Rodrigues(rvec, r);
    const cv::Vec3d centre((kColumns - 1) * kSquare / 2, (kRows - 1) * kSquare / 2, 0);
    const double d = depth(random);
    const cv::Vec3d at{(u(random) - kCamera(0, 2)) / kCamera(0, 0) * d,
                       (v(random) - kCamera(1, 2)) / kCamera(1, 1) * d, d};
    const cv::Vec3d tvec = at - r * centre;
    if (board_inside(rvec, tvec, kCamera, kDistortion)) poses.emplace_back(rvec, tvec);
  }
  return poses;
}

// The standard deviations the report gives `camera`'s values ("  [i] value (from ...) ± s").
std::vector<double> reported_sigmas(const std::string& output, const std::string& camera) {
  std::vector<double> sigmas;
  size_t at = output.find("camera " + camera + " (");
  for (size_t i = 0; at != std::string::npos; ++i) {
    at = output.find(fmt::format("  [{}] ", i), at);
    if (at == std::string::npos) break;
    const size_t line_end = output.find('\n', at);
    const size_t plus_minus = output.find("± ", at);
    if (plus_minus == std::string::npos || plus_minus > line_end) break;
    sigmas.push_back(std::stod(output.substr(plus_minus + std::string("± ").size())));
  }
  return sigmas;
}

TEST(ChessboardImages, MocapCalibrateFindsTheBoardsAndGivesTheCameraBack) {
  test::TempDir dir;
  const std::vector<cv::Point2d> rays = sample_rays();
  std::mt19937 random(3);
  const auto poses = board_poses(14, random);
  for (size_t i = 0; i < poses.size(); ++i) {
    ASSERT_TRUE(cv::imwrite((dir / fmt::format("board{:02}.png", i)).string(),
                            render(rays, poses[i].first, poses[i].second)));
  }
  // A picture without the board and a file that is no picture are skipped, and said so.
  ASSERT_TRUE(cv::imwrite((dir / "empty.png").string(), cv::Mat(kHeight, kWidth, CV_8UC1, 90)));
  test::write_file(dir / "notes.txt", "shot list\n");

  auto [code, output] = test::run_command(
      {(test::bin_dir() / "mocap_calibrate").string(), "--images", dir.path().string(), "--board",
       "9x6", "--square", "0.03", "--output", (dir / "out").string(), "--name", "tracker"});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("skipped " + (dir / "empty.png").string() + ": no 9x6 board found"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("skipped " + (dir / "notes.txt").string() + ": not an image"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("camera tracker (pinhole): 14 shots"), std::string::npos) << output;

  const CameraFile file = load_camera_file((dir / "out" / "tracker.yaml").string());
  ASSERT_EQ(file.model->type(), "pinhole");
  const std::vector<double> found = camera_parameters(*file.model);
  ASSERT_EQ(found.size(), 9u);
  // Rendering and corner detection leave a few hundredths of a pixel of error per corner.
  EXPECT_NEAR(found[0], kCamera(0, 0), 0.003 * kCamera(0, 0)) << output;
  EXPECT_NEAR(found[1], kCamera(1, 1), 0.003 * kCamera(1, 1)) << output;
  EXPECT_NEAR(found[2], kCamera(0, 2), 2.0) << output;
  EXPECT_NEAR(found[3], kCamera(1, 2), 2.0) << output;
  EXPECT_NEAR(found[4], kDistortion[0], 0.02) << output;
  // Every value within 4 of the standard deviations the report gives it: k2 and k3, which
  // trade off where the boards do not reach the image's corners, are as uncertain as it says.
  const std::vector<double> truth = {kCamera(0, 0),  kCamera(1, 1),  kCamera(0, 2),
                                     kCamera(1, 2),  kDistortion[0], kDistortion[1],
                                     kDistortion[2], kDistortion[3], kDistortion[4]};
  for (size_t i = 0; i < truth.size(); ++i) {
    const std::string line = fmt::format("  [{}] ", i);
    const size_t at = output.find(line);
    ASSERT_NE(at, std::string::npos) << output;
    const size_t plus_minus = output.find("± ", at);
    ASSERT_NE(plus_minus, std::string::npos) << output;
    const double sigma = std::stod(output.substr(plus_minus + std::string("± ").size()));
    EXPECT_LT(std::abs(found[i] - truth[i]), 4 * sigma) << "value " << i << "\n" << output;
  }
}

// A stereo pair calibrated from a configuration in visgeom's own form (its stereo example's
// shape: "images" entries, "parameters" flag lists, "init": "none", the "checkboard" object),
// and again from the same corners written as "ir_data": both give the same cameras, each
// within its reported standard deviations of the other and of the truth.
TEST(ChessboardImages, AVisgeomStereoConfigurationRunsUnchangedAndAgreesWithIrData) {
  test::TempDir dir;
  // camera2 hangs 12 cm to the right of camera1, turned 4 degrees towards it.
  const cv::Matx33d camera2(596, 0, 314.2, 0, 598.5, 247.9, 0, 0, 1);
  const std::vector<double> distortion2 = {-0.17, 0.035, -0.0005, 0.0006, 0};
  const cv::Vec3d cam1_from_cam2_r(0, -0.07, 0), cam1_from_cam2_t(0.12, 0, 0);
  cv::Matx33d r12;
  cv::Rodrigues(cam1_from_cam2_r, r12);
  const std::vector<cv::Point2d> rays1 = sample_rays(), rays2 = sample_rays(camera2, distortion2);

  std::mt19937 random(5);
  const int kPairs = 12;
  std::filesystem::create_directories(dir / "stereo" / "bottom");
  std::filesystem::create_directories(dir / "stereo" / "top");
  std::vector<std::string> names;
  for (const auto& [rvec, tvec] : board_poses(4 * kPairs, random)) {
    // The board as camera2 sees it: cam2_from_board = cam1_from_cam2⁻¹ cam1_from_board.
    cv::Matx33d r;
    cv::Rodrigues(rvec, r);
    cv::Vec3d rvec2;
    cv::Rodrigues(r12.t() * r, rvec2);
    const cv::Vec3d tvec2 = r12.t() * (tvec - cam1_from_cam2_t);
    if (!board_inside(rvec2, tvec2, camera2, distortion2)) continue;
    const std::string name = fmt::format("{:06}.png", names.size() + 1);
    ASSERT_TRUE(
        cv::imwrite((dir / "stereo" / "bottom" / name).string(), render(rays1, rvec, tvec)));
    ASSERT_TRUE(cv::imwrite((dir / "stereo" / "top" / name).string(), render(rays2, rvec2, tvec2)));
    names.push_back("\"" + name + "\"");
    if (static_cast<int>(names.size()) == kPairs) break;
  }
  ASSERT_EQ(static_cast<int>(names.size()), kPairs);

  const std::string cameras = R"("cameras": [
    {"name" : "camera1", "type" : "pinhole", "constant" : false, "value" : [600, 600, 320, 240, 0, 0, 0, 0, 0]},
    {"name" : "camera2", "type" : "pinhole", "constant" : false, "value" : [600, 600, 320, 240, 0, 0, 0, 0, 0]}
],)";
  const std::string transformations = R"("transformations" : [
    {"name" : "xiCamBoardStereo", "global" : false, "constant" : false, "prior" : false},
    {
        "name" : "xiCam12",
        "global" : true,
        "constant" : false,
        "prior" : true,
        "value" : [0.1, 0, 0, 0, 0, 0]
    }
],)";
  const std::string object =
      fmt::format(R"({{"type" : "checkboard", "rows" : {}, "cols" : {}, "size" : {}}})", kRows,
                  kColumns, kSquare);
  test::write_file(dir / "visgeom.json",
                   fmt::format(R"({{
{}
{}
"data" : [ 
    {{
        "type" : "images",
        "camera" : "camera1",
        "transform_chain" : [
            {{"name" : "xiCamBoardStereo", "direct" : true}}
        ],
        "init" : "xiCamBoardStereo",
        "object" : {},    
        "parameters" : ["_check_extraction", "show_outliers", "_user_guided", "improve_detection"],
        "images" : {{
            "prefix" : "stereo/bottom/",
            "names" : [{}]
        }}
    }}, 
    {{
        "type" : "images",
        "camera" : "camera2",
        "transform_chain" : [
            {{"name" : "xiCam12", "direct" : false}},
            {{"name" : "xiCamBoardStereo", "direct" : true}}
        ],
        "init" : "none",
        "object" : {},
        "parameters" : ["check_extraction", "show_outliers", "_user_guided", "improve_detection", "_save_outlire_images"],
        "images" : {{
            "prefix" : "stereo/top/",
            "names" : [{}]
        }}
    }}
]
}}
)",
                               transformations, cameras, object, fmt::join(names, ", "), object,
                               fmt::join(names, ", ")));

  // The same corners as ir_data: found as the tool finds them, one frame per pair.
  std::string frames;
  for (size_t i = 0; i < names.size(); ++i) {
    std::string frame;
    for (const auto& [camera, folder] : {std::pair{"camera1", "bottom"}, {"camera2", "top"}}) {
      const std::string file = (dir / "stereo" / folder / fmt::format("{:06}.png", i + 1)).string();
      const cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
      std::vector<cv::Point2f> corners;
      if (!cv::findChessboardCorners(image, {kColumns, kRows}, corners,
                                     cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
        continue;
      }
      cv::cornerSubPix(image, corners, {5, 5}, {-1, -1},
                       {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3});
      std::vector<std::string> points;
      for (const cv::Point2f& p : corners) points.push_back(fmt::format("[{}, {}]", p.x, p.y));
      frame += fmt::format(R"({}{{"camera": "{}", "points": [{}]}})", frame.empty() ? "" : ", ",
                           camera, fmt::join(points, ", "));
    }
    frames += fmt::format("{}[{}]\n", frames.empty() ? "" : ", ", frame);
  }
  test::write_file(dir / "corners.json", "[" + frames + "]");
  std::vector<std::string> object_points;
  for (int i = 0; i < kRows; ++i) {
    for (int j = 0; j < kColumns; ++j) {
      object_points.push_back(fmt::format("[{}, {}, 0]", j * kSquare, i * kSquare));
    }
  }
  const std::string ir_object =
      fmt::format(R"({{"points": [{}]}})", fmt::join(object_points, ", "));
  test::write_file(dir / "ir_data.json", fmt::format(R"({{
{}
{}
"data": [
  {{"type": "ir_data", "camera": "camera1", "image_width": {}, "image_height": {},
    "transform_chain": [{{"name": "xiCamBoardStereo"}}], "data_file": "corners.json",
    "object": {}}},
  {{"type": "ir_data", "camera": "camera2", "image_width": {}, "image_height": {},
    "transform_chain": [{{"name": "xiCam12", "direct": false}}, {{"name": "xiCamBoardStereo"}}],
    "data_file": "corners.json", "object": {}}}
]
}}
)",
                                                     transformations, cameras, kWidth, kHeight,
                                                     ir_object, kWidth, kHeight, ir_object));

  const std::string tool = (test::bin_dir() / "mocap_calibrate").string();
  auto [code, output] = test::run_command(
      {tool, (dir / "visgeom.json").string(), "--output", (dir / "visgeom").string()});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("visgeom flags without a meaning here, ignored: check_extraction\n"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find(fmt::format("camera camera1 (pinhole): {} shots", kPairs)),
            std::string::npos)
      << output;
  EXPECT_NE(output.find(fmt::format("camera camera2 (pinhole): {} shots", kPairs)),
            std::string::npos)
      << output;
  auto [ir_code, ir_output] = test::run_command(
      {tool, (dir / "ir_data.json").string(), "--output", (dir / "ir_data").string()});
  ASSERT_EQ(ir_code, 0) << ir_output;

  struct Truth {
    std::string name;
    cv::Matx33d k;
    std::vector<double> distortion;
  };
  for (const Truth& truth :
       {Truth{"camera1", kCamera, kDistortion}, Truth{"camera2", camera2, distortion2}}) {
    const CameraFile from_images =
        load_camera_file((dir / "visgeom" / (truth.name + ".yaml")).string());
    const CameraFile from_ir =
        load_camera_file((dir / "ir_data" / (truth.name + ".yaml")).string());
    const std::vector<double> a = camera_parameters(*from_images.model);
    const std::vector<double> b = camera_parameters(*from_ir.model);
    const std::vector<double> sigma = reported_sigmas(output, truth.name);
    const std::vector<double> expected = {
        truth.k(0, 0),       truth.k(1, 1),       truth.k(0, 2),
        truth.k(1, 2),       truth.distortion[0], truth.distortion[1],
        truth.distortion[2], truth.distortion[3], truth.distortion[4]};
    ASSERT_EQ(a.size(), 9u);
    ASSERT_EQ(b.size(), 9u);
    ASSERT_EQ(sigma.size(), 9u) << output;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_LT(std::abs(a[i] - b[i]), sigma[i]) << truth.name << " value " << i;
      EXPECT_LT(std::abs(a[i] - expected[i]), 4 * sigma[i]) << truth.name << " value " << i << "\n"
                                                            << output;
    }
    // camera2 placed relative to camera1: the rig's baseline and turn.
    if (truth.name == "camera2") {
      ASSERT_TRUE(from_images.world_from_camera.has_value());
      const Eigen::Isometry3d cam1_from_cam2 = *from_images.world_from_camera;
      EXPECT_NEAR((cam1_from_cam2.translation() - Eigen::Vector3d(0.12, 0, 0)).norm(), 0, 0.002);
      const Eigen::AngleAxisd turn(cam1_from_cam2.rotation());
      EXPECT_NEAR(turn.angle() * turn.axis().y(), -0.07, 0.002);
    }
  }
}

}  // namespace
}  // namespace mocap::calibration
