// The volume's accuracy on the demo's own images (rendered_volume.hpp: the scene rendered
// through the cameras, fiducials detected, bodies identified by their markers' distances and
// fused) against its single cameras on the same body-frames: each figure (position and
// orientation error, median and p95) against the camera best at that figure, whose pose is
// refined and weighed as the fusion's are. The single cameras are given their markers by the
// renderer's truth, so they lose nothing to identification: the comparison is of geometry alone.
//
// What N cameras can give: in position, a single camera's depth rests on the board's apparent
// size and is far worse than its sideways position, so fusing adds much more than N. In
// orientation, one camera is nearly as good as the fusion: both rest on the same markers'
// detection errors, so N equal views bring sqrt(N) at best (2x for four cameras, 2.8x for
// eight) and the best camera is better than the average.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "rendered_calibration.hpp"
#include "rendered_volume.hpp"
#include "test_support.hpp"

namespace mocap::volume {
namespace {

using test::against_best_camera;
using test::Figure;
using test::quantile;

// The four-camera orientation ratios as measured on the test's 5 s (1.99x at the median, 3.08x
// at the p95; 2.12x and 2.96x over 20 s, volume_accuracy_bench), less the hundredths a build's
// rounding moves them by.
constexpr double kFourCameraOrientationMedian = 1.95;
constexpr double kFourCameraOrientationP95 = 2.9;

// Every camera poses the boards (none looks away), and the fusion poses nearly every
// body-frame.
void expect_every_camera_poses(const test::RenderedVolume& volume) {
  size_t fused = 0;
  for (const test::BodyFrame& body : volume.body_frames) fused += body.fused.posed() ? 1 : 0;
  EXPECT_GE(fused, volume.body_frames.size() * 95 / 100) << "of " << volume.body_frames.size();
  for (size_t c = 0; c < volume.cameras.size(); ++c) {
    size_t posed = 0;
    for (const test::BodyFrame& body : volume.body_frames) {
      posed += body.fused.posed() && body.by_camera[c].posed() ? 1 : 0;
    }
    EXPECT_GE(posed, 100u) << volume.cameras[c] << " posed too few: does it look away?";
  }
}

// The figure against the camera best at it, printed.
test::AgainstBestCamera figure(const test::RenderedVolume& volume, Figure which, double q) {
  const test::AgainstBestCamera best = against_best_camera(volume, which, q);
  std::printf("%zu cameras, %s %s: best camera %s %.4f, fused %.4f on its %zu body-frames: %.2fx\n",
              volume.cameras.size(), which == Figure::Position ? "position mm" : "orientation deg",
              q == 0.5 ? "median" : "p95", best.camera.c_str(), best.camera_value, best.fused_value,
              best.body_frames, best.ratio());
  return best;
}

// Four cameras: position twice as accurate as the best camera's, median and p95; orientation
// at the measured ratio, near the sqrt(4) = 2 that four equal views allow.
TEST(VolumeAccuracy, FourCamerasFuseTwiceAsAccuratePositionsAndNearlyTwiceAsAccurateOrientations) {
  const test::RenderedVolume volume =
      test::render_volume((mocap::test::source_dir() / "config").string());
  expect_every_camera_poses(volume);
  for (double q : {0.5, 0.95}) {
    EXPECT_GE(figure(volume, Figure::Position, q).ratio(), 2) << "position, quantile " << q;
  }
  EXPECT_GE(figure(volume, Figure::Orientation, 0.5).ratio(), kFourCameraOrientationMedian);
  EXPECT_GE(figure(volume, Figure::Orientation, 0.95).ratio(), kFourCameraOrientationP95);
}

// Eight cameras: twice as accurate as the best of them in both, median and p95 (sqrt(8) = 2.8
// is the limit in orientation).
TEST(VolumeAccuracy, EightCamerasFuseTwiceAsAccuratePositionsAndOrientations) {
  test::RenderedVolumeOptions eight;
  eight.cameras = 8;
  const test::RenderedVolume volume =
      test::render_volume((mocap::test::source_dir() / "config").string(), eight);
  expect_every_camera_poses(volume);
  for (double q : {0.5, 0.95}) {
    EXPECT_GE(figure(volume, Figure::Position, q).ratio(), 2) << "position, quantile " << q;
    EXPECT_GE(figure(volume, Figure::Orientation, q).ratio(), 2) << "orientation, quantile " << q;
  }
}

// A marker merged with another's or half hidden, kept in the fit, tilts a pose by tenths of a
// degree while its RMS stays under the limit (VolumeTracker::trim_strays): over every body-frame
// fused, the p95 stays within a few times the median.
TEST(VolumeAccuracy, NoFusedPoseIsTiltedByAStrayPoint) {
  const test::RenderedVolume volume =
      test::render_volume((mocap::test::source_dir() / "config").string());
  std::vector<double> position_m, rotation_deg;
  for (const test::BodyFrame& body : volume.body_frames) {
    if (!body.fused.posed()) continue;
    position_m.push_back(body.fused.position_m);
    rotation_deg.push_back(body.fused.rotation_deg);
  }
  std::printf(
      "fused over %zu body-frames: position %.3f / %.3f mm, orientation %.4f / %.4f deg "
      "(median / p95)\n",
      position_m.size(), quantile(position_m, 0.5) * 1e3, quantile(position_m, 0.95) * 1e3,
      quantile(rotation_deg, 0.5), quantile(rotation_deg, 0.95));
  EXPECT_LT(quantile(position_m, 0.95), 0.15e-3);
  EXPECT_LT(quantile(rotation_deg, 0.95), 0.06);
}

// The occlusion target without processes or timing: each camera's view of every board
// cut by an occluder from a side of its own (left, right, top, bottom, 40 %), as
// VolumeDemo.BoardsNoCameraSeesWholeAreTracked does live; no camera sees a board whole, yet
// from the frame each board is first identified on, it is posed in at least 99.5 % of frames,
// none more than 2 mm or a degree off.
TEST(VolumeAccuracy, BoardsNoCameraSeesWholeAreTrackedInNearlyEveryFrame) {
  test::RenderedVolumeOptions options;
  options.frames = 300;
  options.per_camera = [](size_t camera, synthetic::Scene& scene) {
    using Side = synthetic::ObjectOcclusion::Side;
    const Side sides[] = {Side::Left, Side::Right, Side::Top, Side::Bottom};
    for (synthetic::SceneObject& object : scene.objects) {
      object.occlusion = synthetic::ObjectOcclusion{0.4, sides[camera % 4], 0, 0};
    }
  };
  const test::RenderedVolume volume =
      test::render_volume((mocap::test::source_dir() / "config").string(), options);
  std::map<std::string, int> first_posed;
  for (const test::BodyFrame& body : volume.body_frames) {
    EXPECT_LT(body.most_markers_seen, 12) << body.body << " seen whole in frame " << body.frame;
    if (body.fused.posed() && !first_posed.contains(body.body)) first_posed[body.body] = body.frame;
  }
  ASSERT_EQ(first_posed.size(), 4u);
  int expected = 0, tracked = 0, far_off = 0;
  std::vector<double> position_m;
  for (const test::BodyFrame& body : volume.body_frames) {
    if (body.frame < first_posed[body.body]) continue;
    ++expected;
    if (!body.fused.posed()) continue;
    ++tracked;
    position_m.push_back(body.fused.position_m);
    if (body.fused.position_m > 2e-3 || body.fused.rotation_deg > 1) ++far_off;
  }
  std::printf(
      "first posed at frames %d, %d, %d, %d; then %d of %d body-frames posed, %.3f mm "
      "median\n",
      first_posed["board_1"], first_posed["board_2"], first_posed["board_3"],
      first_posed["board_4"], tracked, expected, quantile(position_m, 0.5) * 1e3);
  EXPECT_GE(tracked, expected * 995 / 1000);
  EXPECT_EQ(far_off, 0);
  EXPECT_LT(quantile(position_m, 0.5), 0.5e-3);
}

// The calibration targets on rendered images (rendered_calibration.hpp), calibrated as
// scripts/calibrate_volume.sh does, with half its default wave: a minute of the board carried
// through the volume and the board laid at nine marks, twice at each (turned half round). The
// cameras are within 2 mm and 0.05 degrees of the truth, and poses fused through them within 20 %
// of the accuracy the true cameras give, median and p95. volume_calibration_bench: the same for
// other waves and floors.
TEST(VolumeAccuracy, CamerasCalibratedFromRenderedImagesFuseWithinTwentyPercentOfTheTrueOnes) {
  const std::string config = (mocap::test::source_dir() / "config").string();
  const test::RenderedCalibrationScenes scenes(config);
  const VolumeCalibration calibrated =
      calibrate_volume(scenes.cameras(), scenes.board(), scenes.waved(60),
                       scenes.on_floor(test::kFloorMarks, {0, 180}));
  for (size_t c = 0; c < scenes.cameras().size(); ++c) {
    const test::CameraOffset off =
        test::camera_offset(calibrated.camera_from_world[c], scenes.true_camera_from_world()[c]);
    std::printf("%s: %.3f mm, %.4f deg from the truth\n", scenes.cameras()[c].name.c_str(),
                off.position_m * 1e3, off.rotation_deg);
    EXPECT_LT(off.position_m, 2e-3) << scenes.cameras()[c].name;
    EXPECT_LT(off.rotation_deg, 0.05) << scenes.cameras()[c].name;
  }

  test::RenderedVolumeOptions rendering;
  rendering.frames = 300;
  const std::vector<double> on_truth =
      test::render_volume(config, rendering).fused_position_errors_mm();
  rendering.tracked_camera_from_world = calibrated.camera_from_world;
  const std::vector<double> on_calibrated =
      test::render_volume(config, rendering).fused_position_errors_mm();
  ASSERT_GE(on_calibrated.size(), on_truth.size() * 99 / 100);
  for (double q : {0.5, 0.95}) {
    std::printf(
        "fused position error, quantile %.2f: %.4f mm on the true cameras, %.4f mm on "
        "the calibrated ones\n",
        q, quantile(on_truth, q), quantile(on_calibrated, q));
    EXPECT_LE(quantile(on_calibrated, q), 1.2 * quantile(on_truth, q)) << "quantile " << q;
  }
}

}  // namespace
}  // namespace mocap::volume
