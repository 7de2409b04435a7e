// A volume calibrated from data (volume_calibration.hpp): a board waved through the synthetic
// volume and laid on the floor, seen with pixel noise; the cameras' poses against the truth,
// and the fused poses the calibrated cameras give against those the true ones give.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "test/volume/synthetic_volume.hpp"
#include "volume/volume_calibration/volume_calibration.hpp"

namespace mocap::volume {
namespace {

// Each camera's view of the board at `world_from_board`, whole or not at all, with noise.
std::vector<BoardSighting> sightings(const test::Volume& volume, const Eigen::Isometry3d& pose,
                                     int64_t stamp_ns, std::mt19937& random) {
  std::vector<BoardSighting> out;
  const std::vector<CameraView> views = test::views_of(volume, pose, 0.3, random);  // by camera
  for (size_t camera = 0; camera < views.size(); ++camera) {
    const CameraView& view = views[camera];
    if (view.pixels.empty()) continue;
    BoardSighting sighting{stamp_ns, camera, {}};
    for (const Eigen::Vector2d& pixel : view.pixels) sighting.pixels.emplace_back(pixel);
    out.push_back(std::move(sighting));
  }
  return out;
}

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180 / test::kPi;
}

// 300 board positions waved through the volume (20 s at 15 Hz), then 20 s of it on the floor
// (600 frames at 30 Hz: the floor board's tilt, which moves every camera with it, is the largest
// error left): every camera within 2 mm and 0.05 degrees of the truth, and poses fused through
// the calibrated cameras within 20 % of the accuracy the true cameras give.
TEST(VolumeCalibration, CamerasFromAWavedBoardAndTheFloor) {
  const test::Volume volume;
  std::mt19937 random(17);
  std::vector<BoardSighting> waved, floor;
  for (int64_t i = 0; i < 300; ++i) {
    for (BoardSighting& s : sightings(volume, test::random_pose(random), i * 66'000'000, random)) {
      waved.push_back(std::move(s));
    }
  }
  for (int64_t i = 0; i < 600; ++i) {
    for (BoardSighting& s : sightings(volume, Eigen::Isometry3d::Identity(),
                                      30'000'000'000 + i * 66'000'000, random)) {
      floor.push_back(std::move(s));
    }
  }
  std::vector<CalibrationCamera> cameras;
  for (size_t c = 0; c < volume.extrinsics.size(); ++c) {
    cameras.push_back({"cam_" + std::to_string(c), volume.camera});
  }
  const VolumeCalibration result =
      calibrate_volume(cameras, test::kBoard, waved, {{Eigen::Vector2d::Zero(), floor}});
  ASSERT_EQ(result.camera_from_world.size(), 4u);
  ASSERT_EQ(result.floor.size(), 1u);
  std::printf("%zu capture times, RMS %.3f px; floor seen by %zu cameras, RMS %.3f px\n",
              result.frames_used, result.report.rms_px, result.floor[0].cameras,
              result.floor[0].rms_px);
  EXPECT_LT(result.report.rms_px, 0.5);
  EXPECT_EQ(result.floor[0].cameras, 4u);
  for (size_t c = 0; c < 4; ++c) {
    const Eigen::Isometry3d truth = volume.extrinsics[c].inverse();  // world_from_camera
    const Eigen::Isometry3d found = result.camera_from_world[c].inverse();
    const double position_mm = (found.translation() - truth.translation()).norm() * 1e3;
    const double rotation_deg = angle_deg(found.linear(), truth.linear());
    std::printf("cam_%zu: position %.3f mm, rotation %.4f deg from the truth\n", c, position_mm,
                rotation_deg);
    EXPECT_LT(position_mm, 2.0) << c;
    EXPECT_LT(rotation_deg, 0.05) << c;
  }

  // The same views fused through the truth and through the calibration.
  std::vector<double> with_truth, with_calibration;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Isometry3d pose = test::random_pose(random);
    std::vector<CameraView> views = test::views_of(volume, pose, 0.3, random);
    const MultiCameraPose truth = estimate_multi_camera_pose(views, pose);
    for (size_t c = 0; c < views.size(); ++c)
      views[c].camera_from_world = result.camera_from_world[c];
    const MultiCameraPose calibrated = estimate_multi_camera_pose(views, pose);
    if (!truth.valid || !calibrated.valid) continue;
    with_truth.push_back((truth.world_from_body.translation() - pose.translation()).norm());
    with_calibration.push_back(
        (calibrated.world_from_body.translation() - pose.translation()).norm());
  }
  ASSERT_GT(with_truth.size(), 300u);
  std::sort(with_truth.begin(), with_truth.end());
  std::sort(with_calibration.begin(), with_calibration.end());
  const double truth_median = with_truth[with_truth.size() / 2];
  const double calibrated_median = with_calibration[with_calibration.size() / 2];
  std::printf("fused position error median: %.3f mm with the true cameras, %.3f mm calibrated\n",
              truth_median * 1e3, calibrated_median * 1e3);
  EXPECT_LT(calibrated_median, 1.2 * truth_median);
}

// `frames` frames of the board lying still at `mark` on the floor. A still board's detection
// errors are the same in every frame (they follow where its markers fall on the pixel grid),
// so recording longer does not average them: a fixed offset per camera and marker, `bias_px`
// (1 sigma), under 0.05 px of noise.
FloorPlacement still_on_floor(const test::Volume& volume, const Eigen::Vector2d& mark, int frames,
                              double bias_px, std::mt19937& random) {
  const Eigen::Isometry3d pose(Eigen::Translation3d(mark.x(), mark.y(), 0));
  std::normal_distribution<double> bias(0, bias_px);
  std::vector<std::vector<Eigen::Vector2d>> offsets(volume.extrinsics.size());
  for (auto& camera : offsets) {
    for (size_t i = 0; i < test::kBoard.size(); ++i)
      camera.emplace_back(bias(random), bias(random));
  }
  FloorPlacement placement{mark, {}};
  for (int64_t i = 0; i < frames; ++i) {
    for (BoardSighting& s : sightings(volume, pose, 40'000'000'000 + i * 33'000'000, random)) {
      for (size_t m = 0; m < s.pixels.size(); ++m) *s.pixels[m] += offsets[s.camera][m];
      placement.sightings.push_back(std::move(s));
    }
  }
  return placement;
}

// The board laid once turns the world by what its markers' offsets do over its 0.3 m; laid at
// five marks 1 m apart, by what the offsets of its centres do over the marks' spread: the
// cameras' rotation from the truth at least halved. Each mark's centre lies within a fraction
// of a millimetre of it.
TEST(VolumeCalibration, MarksOnTheFloorTurnTheWorldLessThanTheBoardLaidOnce) {
  const test::Volume volume;
  std::mt19937 random(29);
  std::vector<BoardSighting> waved;
  for (int64_t i = 0; i < 300; ++i) {
    for (BoardSighting& s : sightings(volume, test::random_pose(random), i * 66'000'000, random)) {
      waved.push_back(std::move(s));
    }
  }
  std::vector<CalibrationCamera> cameras;
  for (size_t c = 0; c < volume.extrinsics.size(); ++c) {
    cameras.push_back({"cam_" + std::to_string(c), volume.camera});
  }
  std::vector<FloorPlacement> marks;
  for (const Eigen::Vector2d& mark :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1), Eigen::Vector2d(-1, 0),
        Eigen::Vector2d(0, -1)}) {
    marks.push_back(still_on_floor(volume, mark, 60, 0.06, random));
  }
  auto worst_rotation_deg = [&](const VolumeCalibration& result) {
    double worst = 0;
    for (size_t c = 0; c < volume.extrinsics.size(); ++c) {
      worst = std::max(
          worst, angle_deg(result.camera_from_world[c].linear(), volume.extrinsics[c].linear()));
    }
    return worst;
  };
  const VolumeCalibration once = calibrate_volume(cameras, test::kBoard, waved, {marks[0]});
  const VolumeCalibration at_marks = calibrate_volume(cameras, test::kBoard, waved, marks);
  std::printf("worst camera rotation: %.4f deg from the board laid once, %.4f from 5 marks\n",
              worst_rotation_deg(once), worst_rotation_deg(at_marks));
  EXPECT_LT(worst_rotation_deg(at_marks), worst_rotation_deg(once) / 2);
  ASSERT_EQ(at_marks.floor.size(), marks.size());
  for (const VolumeCalibration::Placement& placement : at_marks.floor) {
    EXPECT_GE(placement.cameras, 1u);
    EXPECT_LT(placement.off_mark_m, 0.5e-3);
  }
}

// Nothing ties a camera to the others, or nothing shows the floor: said, not guessed.
TEST(VolumeCalibration, MissingDataIsSaid) {
  const test::Volume volume;
  std::mt19937 random(3);
  std::vector<CalibrationCamera> cameras;
  for (size_t c = 0; c < 4; ++c) cameras.push_back({"cam_" + std::to_string(c), volume.camera});
  std::vector<BoardSighting> waved;
  for (int64_t i = 0; i < 50; ++i) {
    for (BoardSighting& s : sightings(volume, test::random_pose(random), i * 66'000'000, random)) {
      if (s.camera != 3) waved.push_back(std::move(s));
    }
  }
  try {
    calibrate_volume(cameras, test::kBoard, waved, {FloorPlacement{}});
    FAIL() << "calibrated without cam_3";
  } catch (const VolumeCalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("camera cam_3: no capture time"), std::string::npos)
        << e.what();
  }
  cameras.pop_back();
  try {
    calibrate_volume(cameras, test::kBoard, waved, {});
    FAIL() << "calibrated without the floor";
  } catch (const VolumeCalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("board on the floor"), std::string::npos) << e.what();
  }
  try {
    calibrate_volume(cameras, test::kBoard, waved, {{Eigen::Vector2d(1, 0.5), {}}});
    FAIL() << "calibrated from a placement nobody saw";
  } catch (const VolumeCalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("no camera saw the board on the floor at (1, 0.5)"),
              std::string::npos)
        << e.what();
  }
  try {
    calibrate_volume(cameras, test::kBoard, waved, {FloorPlacement{}, FloorPlacement{}});
    FAIL() << "calibrated from two marks";
  } catch (const VolumeCalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("two marks"), std::string::npos) << e.what();
  }
}

// Options built in code are refused before any solve, naming the field.
TEST(VolumeCalibrationOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(VolumeCalibrationOptions{}.problem(), std::nullopt);
  EXPECT_EQ(VolumeCalibrationOptions{.same_capture_s = -0.002}.problem(),
            "same_capture_s: -0.002 is below 0");
  EXPECT_EQ(VolumeCalibrationOptions{.max_frames = 0}.problem(),
            "max_frames: 0 leaves no capture time for the solve");
  EXPECT_EQ(VolumeCalibrationOptions{.robust_scale_px = 0}.problem(), std::nullopt);  // no Huber
  EXPECT_EQ(VolumeCalibrationOptions{.robust_scale_px = -1}.problem(),
            "robust_scale_px: -1 is below 0");
  try {
    calibrate_volume({}, {}, {}, {}, {.max_frames = 0});
    ADD_FAILURE() << "max_frames 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "VolumeCalibrationOptions::max_frames: 0 leaves no capture time for the solve");
  }
}

}  // namespace
}  // namespace mocap::volume
