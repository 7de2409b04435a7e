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
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "test/test_support.hpp"
#include "test/volume/rendered_calibration.hpp"
#include "test/volume/rendered_volume.hpp"

namespace mocap::volume {
namespace {

using test::against_best_camera;
using test::Figure;
using test::quantile;

// The four-camera orientation ratios as measured on the test's 5 s (1.92x at the median, 2.62x
// at the p95; 2.08x and 2.69x over 20 s, volume_accuracy_bench), less the hundredths a build's
// rounding moves them by.
constexpr double kFourCameraOrientationMedian = 1.9;
constexpr double kFourCameraOrientationP95 = 2.55;
// A pose's error beyond its covariance's 3-sigma ellipsoid: chi-square with 3 degrees of
// freedom above 14.16 (probability 0.27 % when the covariance is right), in position or in
// orientation.
constexpr double kThreeSigma = 14.16;
bool beyond_three_sigma(const test::BodyFrame& body) {
  return body.position_nees > kThreeSigma || body.orientation_nees > kThreeSigma;
}
// Whether a camera's message for a frame is late past the fusion's wait, for 10 % of them: a
// fixed pseudo-random pattern, the same frames in every build; another `pattern`, other frames.
bool late_at_random(size_t camera, int frame, uint64_t pattern = 0) {
  const uint64_t x =
      (static_cast<uint64_t>(frame) * 4 + camera + pattern * 1000003) * 0x9E3779B97F4A7C15ull;
  return (x >> 40) % 10 == 0;
}

bool false_identification(const test::BodyFrame& body) {
  return body.fused.position_m > 0.05 || body.fused.rotation_deg > 5;
}

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
// none more than 2 mm or a degree off and at most 1 % beyond its covariance's 3 sigma. (Where
// one camera's markers are cut by the occluder's edge, 6 to 34 sigmas off, the worst of them
// are left out: leaving that camera out instead put the pose on the other camera alone, 2 to
// 6 mm off.)
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
  int expected = 0, tracked = 0, beyond = 0, over_2mm = 0;
  std::vector<double> position_m;
  for (const test::BodyFrame& body : volume.body_frames) {
    if (body.frame < first_posed[body.body]) continue;
    ++expected;
    if (!body.fused.posed()) continue;
    ++tracked;
    position_m.push_back(body.fused.position_m);
    beyond += beyond_three_sigma(body) ? 1 : 0;
    over_2mm += body.fused.position_m > 2e-3 || body.fused.rotation_deg > 1 ? 1 : 0;
  }
  std::printf(
      "first posed at frames %d, %d, %d, %d; then %d of %d body-frames posed, %.3f mm "
      "median; %d more than 2 mm or 1 degree off, %d beyond their covariance's 3 sigma\n",
      first_posed["board_1"], first_posed["board_2"], first_posed["board_3"],
      first_posed["board_4"], tracked, expected, quantile(position_m, 0.5) * 1e3, over_2mm, beyond);
  EXPECT_GE(tracked, expected * 995 / 1000);
  EXPECT_EQ(over_2mm, 0);
  EXPECT_LE(beyond, tracked / 100);
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

// Cameras missing from frames: one camera away for good (its process down), and every camera's
// message missing from a tenth of the frames at random (late past the fusion's wait on a busy
// machine). Then bodies rest on fewer cameras, often one, whose depth is poor: a frame must go
// without a body's pose rather than hand out a wrong one. No pose more than 5 cm or 5 degrees
// off (a false identification: the evaluator's), poses within what their covariance says (the
// error beyond the covariance's 3-sigma ellipsoid, chi-square 14.16 with 3 degrees of freedom,
// in at most 1 % of poses, position or orientation: 0.5 % when it is right), and nearly every
// body-frame still posed.
TEST(VolumeAccuracy, CamerasMissingFromFramesNeverGiveAWrongPose) {
  struct Scene {
    std::string name;
    std::function<bool(size_t camera, int frame)> missing;
  };
  std::vector<Scene> scenes;
  for (int away = 0; away < 4; ++away) {
    scenes.push_back({"cam_" + std::to_string(away) + " away",
                      [away](size_t camera, int) { return static_cast<int>(camera) == away; }});
  }
  scenes.push_back({"each camera missing from 10 % of frames",
                    [](size_t camera, int frame) { return late_at_random(camera, frame); }});
  for (const Scene& scene : scenes) {
    test::RenderedVolumeOptions options;
    options.frames = 900;
    options.missing = scene.missing;
    const test::RenderedVolume volume =
        test::render_volume((mocap::test::source_dir() / "config").string(), options);
    int posed = 0, false_identifications = 0, beyond = 0;
    std::vector<double> position_m;
    for (const test::BodyFrame& body : volume.body_frames) {
      if (!body.fused.posed()) continue;
      ++posed;
      position_m.push_back(body.fused.position_m);
      if (false_identification(body)) {
        ++false_identifications;
        ADD_FAILURE() << scene.name << ": " << body.body << " in frame " << body.frame << " "
                      << body.fused.position_m * 1e3 << " mm, " << body.fused.rotation_deg
                      << " deg off, on " << body.cameras_used << " camera(s)";
      }
      beyond += beyond_three_sigma(body) ? 1 : 0;
    }
    std::printf(
        "%s: %d of %zu body-frames posed, %d false identifications, %d beyond their covariance's "
        "3 sigma, %.3f mm median\n",
        scene.name.c_str(), posed, volume.body_frames.size(), false_identifications, beyond,
        quantile(position_m, 0.5) * 1e3);
    EXPECT_EQ(false_identifications, 0) << scene.name;
    EXPECT_LE(beyond, posed / 100) << scene.name;
    EXPECT_GE(posed, static_cast<int>(volume.body_frames.size()) * 98 / 100) << scene.name;
  }
}

// The moment the multi-host demo once gave a false identification, on a busy machine: cam_1's
// process down, board_2 leaving cam_0's and cam_3's views (scene time 2115.6 s), and cam_0's
// message late past the fusion's wait for one frame. cam_2 then sees four markers of one side of
// board_2, and cam_3 two of the same line: points that leave the pose free to turn about that
// line, whose fit stood 34 mm and 11 degrees off at residuals as usual, and the track followed
// it. Over the sensor noise of three seeds, each camera's message late in turn and late at
// random: no pose beyond the evaluator's bounds.
TEST(VolumeAccuracy, APoseItsPointsDoNotFixIsNotHandedOut) {
  const int late_frame = 38;  // scene time 2115.6 s
  for (uint64_t seed = 0; seed < 3; ++seed) {
    for (int late_camera : {-1, 0, 2, 3, 4}) {  // none, each, at random (4)
      test::RenderedVolumeOptions options;
      options.frames = 60;
      options.start_s = 2115.6 - late_frame / options.rate_hz;
      options.noise_seed = seed;
      options.missing = [=](size_t camera, int frame) {
        if (camera == 1) return true;
        if (late_camera == 4) return late_at_random(camera, frame, seed);
        return static_cast<int>(camera) == late_camera && frame == late_frame;
      };
      const test::RenderedVolume volume =
          test::render_volume((mocap::test::source_dir() / "config").string(), options);
      int posed = 0;
      for (const test::BodyFrame& body : volume.body_frames) {
        if (!body.fused.posed()) continue;
        ++posed;
        EXPECT_FALSE(false_identification(body))
            << "seed " << seed << ", late camera " << late_camera << ": " << body.body
            << " in frame " << body.frame << " " << body.fused.position_m * 1e3 << " mm, "
            << body.fused.rotation_deg << " deg off, on " << body.cameras_used << " camera(s)";
      }
      std::printf("seed %d, late camera %d: %d of %zu body-frames posed\n", static_cast<int>(seed),
                  late_camera, posed, volume.body_frames.size());
    }
  }
}

}  // namespace
}  // namespace mocap::volume
