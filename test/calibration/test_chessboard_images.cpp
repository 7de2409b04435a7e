// mocap_calibrate on real image files: chessboards rendered through a distorting pinhole camera
// or an omnidirectional one (OpenCV's models, so the truth does not come from the solver's own
// formulas), written as PNG, found by OpenCV's corner detector in the tool and solved by our
// solver. The camera files it writes must give the cameras back.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/ccalib/omnidir.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>

#include "test/test_support.hpp"

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

// A lens the tests render through, with OpenCV's formulas rather than the solver's: a pinhole
// with radial-tangential distortion, or, given xi, Mei's omnidirectional camera (cv::omnidir:
// visgeom's "mei" with k3 = 0, k4 = p1, k5 = p2; "ucm" when the distortion is 0).
struct Lens {
  cv::Matx33d k;
  std::vector<double> distortion;  // k1 k2 p1 p2 [k3]
  std::optional<double> xi;

  std::vector<cv::Point2d> project(const std::vector<cv::Point3d>& points, const cv::Vec3d& rvec,
                                   const cv::Vec3d& tvec) const {
    std::vector<cv::Point2d> pixels;
    if (xi) {
      cv::omnidir::projectPoints(
          points, pixels, rvec, tvec, k, *xi,
          cv::Vec4d(distortion[0], distortion[1], distortion[2], distortion[3]));
    } else {
      cv::projectPoints(points, rvec, tvec, k, distortion, pixels);
    }
    return pixels;
  }
  // The rays (x/z, y/z) the pixels see.
  std::vector<cv::Point2d> rays(const std::vector<cv::Point2d>& pixels) const {
    std::vector<cv::Point2d> rays;
    if (xi) {
      cv::omnidir::undistortPoints(pixels, rays, k, cv::Vec4d(distortion.data()), *xi,
                                   cv::Matx33d::eye());
    } else {
      cv::undistortPoints(
          pixels, rays, k, distortion, cv::noArray(), cv::noArray(),
          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-12));
    }
    return rays;
  }
  // Pixels per radian at the centre.
  double focal() const { return k(0, 0) / (1 + xi.value_or(0)); }
};

const Lens kLens{kCamera, kDistortion, std::nullopt};

// Every sample's ray through the lens (z = 1), computed once: the camera does not move.
std::vector<cv::Point2d> sample_rays(const Lens& lens = kLens) {
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < kHeight * kSamples; ++v) {
    for (int u = 0; u < kWidth * kSamples; ++u) {
      pixels.emplace_back((u + 0.5) / kSamples - 0.5, (v + 0.5) / kSamples - 0.5);
    }
  }
  return lens.rays(pixels);
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
bool board_inside(const cv::Vec3d& rvec, const cv::Vec3d& tvec, const Lens& lens) {
  const std::vector<cv::Point3d> outline = {{-2 * kSquare, -2 * kSquare, 0},
                                            {(kColumns + 1) * kSquare, -2 * kSquare, 0},
                                            {(kColumns + 1) * kSquare, (kRows + 1) * kSquare, 0},
                                            {-2 * kSquare, (kRows + 1) * kSquare, 0}};
  bool inside = true;
  for (const cv::Point2d& p : lens.project(outline, rvec, tvec)) {
    inside = inside && p.x > 15 && p.y > 15 && p.x < kWidth - 15 && p.y < kHeight - 15;
  }
  return inside;
}

// Board poses `near`-`far` metres away, centred anywhere in the image, tilted up to 40 degrees,
// whose whole board (margin included) lies in the image with room to spare: the corners of the
// image show the lens's distortion, the tilts its focal length.
std::vector<std::pair<cv::Vec3d, cv::Vec3d>> board_poses(int count, std::mt19937& random,
                                                         const Lens& lens = kLens,
                                                         double near = 0.45, double far = 0.8) {
  std::uniform_real_distribution<double> depth(near, far), tilt(-0.7, 0.7), spin(-0.3, 0.3),
      u(0, kWidth), v(0, kHeight);
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> poses;
  while (static_cast<int>(poses.size()) < count) {
    const cv::Vec3d rvec{tilt(random), tilt(random), spin(random)};
    cv::Matx33d r;
    cv::Rodrigues(rvec, r);
    const cv::Vec3d centre((kColumns - 1) * kSquare / 2, (kRows - 1) * kSquare / 2, 0);
    const double d = depth(random);
    const cv::Vec3d at{(u(random) - lens.k(0, 2)) / lens.focal() * d,
                       (v(random) - lens.k(1, 2)) / lens.focal() * d, d};
    const cv::Vec3d tvec = at - r * centre;
    if (board_inside(rvec, tvec, lens)) poses.emplace_back(rvec, tvec);
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
  const Lens lens2{camera2, distortion2, std::nullopt};
  const std::vector<cv::Point2d> rays1 = sample_rays(), rays2 = sample_rays(lens2);

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
    if (!board_inside(rvec2, tvec2, lens2)) continue;
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

// visgeom's unified cameras, "mei" and "ucm", calibrated from a configuration in visgeom's form:
// boards rendered through OpenCV's omnidirectional camera, whose wide view (about 120 degrees
// across) is where xi shows. The camera files written must image every ray as the truth does.
TEST(ChessboardImages, VisgeomsMeiAndUcmCamerasComeBackFromTheirImages) {
  test::TempDir dir;
  struct Truth {
    std::string name, type;
    Lens lens;
    std::vector<double> values;  // in visgeom's order
  };
  const double xi1 = 0.85, xi2 = 1.1;
  const std::vector<Truth> truths = {
      {"omni1",
       "mei",
       Lens{
           cv::Matx33d(560, 0, 322.5, 0, 556, 238.4, 0, 0, 1), {-0.12, 0.03, 0.0008, -0.0005}, xi1},
       {xi1, -0.12, 0.03, 0, 0.0008, -0.0005, 560, 556, 322.5, 238.4}},
      {"omni2",
       "ucm",
       Lens{cv::Matx33d(640, 0, 318.2, 0, 642, 243.1, 0, 0, 1), {0, 0, 0, 0}, xi2},
       {xi2, 640, 642, 318.2, 243.1}},
  };
  const int kShots = 20;
  std::mt19937 random(11);
  std::string cameras, transformations, data;
  std::vector<std::vector<std::pair<cv::Vec3d, cv::Vec3d>>> poses;
  for (const Truth& truth : truths) {
    std::filesystem::create_directories(dir / truth.name);
    const std::vector<cv::Point2d> rays = sample_rays(truth.lens);
    std::vector<std::string> names;
    poses.push_back(board_poses(kShots, random, truth.lens, 0.22, 0.45));
    for (const auto& [rvec, tvec] : poses.back()) {
      names.push_back(fmt::format("\"{:06}.png\"", names.size() + 1));
      ASSERT_TRUE(cv::imwrite((dir / truth.name / fmt::format("{:06}.png", names.size())).string(),
                              render(rays, rvec, tvec)));
    }
    // Started as visgeom's examples start a camera: nothing bent, the centre in the middle.
    const std::string start = truth.type == "mei" ? "[0.5, 0, 0, 0, 0, 0, 450, 450, 320, 240]"
                                                  : "[0.5, 450, 450, 320, 240]";
    cameras +=
        fmt::format(R"({}{{"name" : "{}", "type" : "{}", "constant" : false, "value" : {}}})",
                    cameras.empty() ? "" : ",\n    ", truth.name, truth.type, start);
    transformations += fmt::format(
        R"({}{{"name" : "board_{}", "global" : false, "constant" : false, "prior" : false}})",
        transformations.empty() ? "" : ",\n    ", truth.name);
    data += fmt::format(R"({}{{
        "type" : "images",
        "camera" : "{}",
        "transform_chain" : [{{"name" : "board_{}", "direct" : true}}],
        "init" : "none",
        "object" : {{"type" : "checkboard", "rows" : {}, "cols" : {}, "size" : {}}},
        "parameters" : ["show_outliers", "improve_detection"],
        "images" : {{"prefix" : "{}/", "names" : [{}]}}
    }})",
                        data.empty() ? "" : ",\n    ", truth.name, truth.name, kRows, kColumns,
                        kSquare, truth.name, fmt::join(names, ", "));
  }
  test::write_file(dir / "omni.json",
                   fmt::format("{{\n\"cameras\" : [\n    {}\n],\n\"transformations\" : [\n    "
                               "{}\n],\n\"data\" : [\n    {}\n]\n}}\n",
                               cameras, transformations, data));

  // Two wide-angle cameras' boards found in their images and solved: more than the default
  // minute under AddressSanitizer in a CI run beside a compiling sanitizer tree.
  auto [code, output] =
      test::run_command({(test::bin_dir() / "mocap_calibrate").string(),
                         (dir / "omni.json").string(), "--output", (dir / "out").string()},
                        {}, std::chrono::seconds(180));
  ASSERT_EQ(code, 0) << output;
  for (size_t t = 0; t < truths.size(); ++t) {
    const Truth& truth = truths[t];
    SCOPED_TRACE(truth.name);
    // A board seen obliquely in a corner of so wide a view may not be found; most are.
    const std::string heading = fmt::format("camera {} ({}): ", truth.name, truth.type);
    const size_t at = output.find(heading);
    ASSERT_NE(at, std::string::npos) << output;
    EXPECT_GE(std::stoi(output.substr(at + heading.size())), kShots / 2) << output;
    const CameraFile file = load_camera_file((dir / "out" / (truth.name + ".yaml")).string());
    ASSERT_EQ(file.model->type(), truth.type);
    const std::vector<double> found = camera_parameters(*file.model);
    ASSERT_EQ(found.size(), truth.values.size());

    // The same camera where the boards that were found showed it: every ray there lands on the
    // pixel it came from. (Beyond them nothing says what the lens does, and a polynomial's
    // extrapolation can be far off.)
    cv::Mat seen(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
    std::vector<cv::Point3d> grid;
    for (int i = 0; i < kRows; ++i) {
      for (int j = 0; j < kColumns; ++j) grid.emplace_back(j * kSquare, i * kSquare, 0);
    }
    for (size_t k = 0; k < poses[t].size(); ++k) {
      const auto image = dir / truth.name / fmt::format("{:06}.png", k + 1);
      if (output.find("skipped " + image.string()) != std::string::npos) continue;
      const std::vector<cv::Point2d> corners =
          truth.lens.project(grid, poses[t][k].first, poses[t][k].second);
      for (int i = 0; i + 1 < kRows; ++i) {
        for (int j = 0; j + 1 < kColumns; ++j) {
          const auto corner = [&](int row, int column) {
            const cv::Point2d& p = corners[static_cast<size_t>(row * kColumns + column)];
            return cv::Point(cvRound(p.x), cvRound(p.y));
          };
          const std::vector<cv::Point> cell = {corner(i, j), corner(i, j + 1), corner(i + 1, j + 1),
                                               corner(i + 1, j)};
          cv::fillConvexPoly(seen, cell, cv::Scalar(255));
        }
      }
    }
    std::vector<cv::Point2d> pixels;
    for (int v = 0; v < kHeight; v += 4) {
      for (int u = 0; u < kWidth; u += 4) {
        if (seen.at<uint8_t>(v, u)) pixels.emplace_back(u, v);
      }
    }
    EXPECT_GT(pixels.size(), kWidth * kHeight / 16 / 4)
        << "the boards cover a quarter of the image";
    const std::vector<cv::Point2d> rays = truth.lens.rays(pixels);
    double worst = 0;
    for (size_t i = 0; i < pixels.size(); ++i) {
      const auto pixel = file.model->project({rays[i].x, rays[i].y, 1});
      ASSERT_TRUE(pixel) << pixels[i];
      worst = std::max(worst, std::hypot(pixel->x() - pixels[i].x, pixel->y() - pixels[i].y));
    }
    EXPECT_LT(worst, 1.0) << output;
    // The centre is where the lens model matters least: within a pixel.
    EXPECT_NEAR(found[found.size() - 2], truth.values[found.size() - 2], 1.0) << output;
    EXPECT_NEAR(found[found.size() - 1], truth.values[found.size() - 1], 1.0) << output;
    // The UCM has one value per effect and every value comes back within 4 of its reported
    // standard deviations. Mei's xi, k1, k2 and k3 trade off along a valley the image cannot
    // tell apart (which the comparison of rays above shows): its values are not compared.
    if (truth.type == "ucm") {
      const std::vector<double> sigma = reported_sigmas(output, truth.name);
      ASSERT_EQ(sigma.size(), truth.values.size()) << output;
      for (size_t i = 0; i < found.size(); ++i) {
        EXPECT_LT(std::abs(found[i] - truth.values[i]), 4 * sigma[i]) << "value " << i << "\n"
                                                                      << output;
      }
    }
  }
}

}  // namespace
}  // namespace mocap::calibration
