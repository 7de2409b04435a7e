// mocap_calibrate --images on real image files: chessboards rendered through a distorting
// pinhole camera (OpenCV's model, so the truth does not come from the solver's own formulas),
// written as PNG, found by OpenCV's corner detector in the tool and solved by our solver. The
// camera file it writes must give the camera back.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

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
std::vector<cv::Point2d> sample_rays() {
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < kHeight * kSamples; ++v) {
    for (int u = 0; u < kWidth * kSamples; ++u) {
      pixels.emplace_back((u + 0.5) / kSamples - 0.5, (v + 0.5) / kSamples - 0.5);
    }
  }
  std::vector<cv::Point2d> rays;
  cv::undistortPoints(pixels, rays, kCamera, kDistortion, cv::noArray(), cv::noArray(),
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

// Board poses 0.45-0.8 m away, centred anywhere in the image, tilted up to 40 degrees, whose
// whole board (margin included) lies in the image with room to spare: the corners of the image
// show the lens's distortion, the tilts its focal length.
std::vector<std::pair<cv::Vec3d, cv::Vec3d>> board_poses(int count, std::mt19937& random) {
  std::uniform_real_distribution<double> depth(0.45, 0.8), tilt(-0.7, 0.7), spin(-0.3, 0.3),
      u(0, kWidth), v(0, kHeight);
  const std::vector<cv::Point3d> outline = {{-2 * kSquare, -2 * kSquare, 0},
                                            {(kColumns + 1) * kSquare, -2 * kSquare, 0},
                                            {(kColumns + 1) * kSquare, (kRows + 1) * kSquare, 0},
                                            {-2 * kSquare, (kRows + 1) * kSquare, 0}};
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
    std::vector<cv::Point2d> corners;
    cv::projectPoints(outline, rvec, tvec, kCamera, kDistortion, corners);
    bool inside = true;
    for (const cv::Point2d& p : corners) {
      inside = inside && p.x > 15 && p.y > 15 && p.x < kWidth - 15 && p.y < kHeight - 15;
    }
    if (inside) poses.emplace_back(rvec, tvec);
  }
  return poses;
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

}  // namespace
}  // namespace mocap::calibration
