// The pose of a body seen by a volume of fixed cameras (pose_fusion.hpp): on the same
// frames, against each camera's own pose of it (planar_pose.hpp), with pixel noise; a body that
// only one camera sees; a camera whose extrinsics have moved.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "test/volume/synthetic_volume.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"
#include "volume/pose_fusion/pose_fusion.hpp"

namespace mocap::volume {
namespace {

using test::kBoard;
using test::kPi;
using test::random_pose;
using test::views_of;
using test::Volume;

double quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(q * values.size()))];
}

double position_error(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}
double rotation_error(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return pose::rotation_angle_between(Eigen::Quaterniond(a.rotation()),
                                      Eigen::Quaterniond(b.rotation()));
}

// The accuracy target, on frames every camera sees: the fused pose's position and
// orientation errors at least twice lower than the best single camera's, median and p95.
TEST(MultiCameraPose, FusedIsTwiceAsAccurateAsTheBestSingleCamera) {
  const Volume volume;
  std::mt19937 random(7);
  const size_t cameras = volume.extrinsics.size();
  std::vector<double> fused_position, fused_rotation;
  std::vector<std::vector<double>> single_position(cameras), single_rotation(cameras);
  int frames = 0;
  while (frames < 300) {
    const Eigen::Isometry3d truth = random_pose(random);
    const std::vector<CameraView> views = views_of(volume, truth, 0.3, random);
    if (std::any_of(views.begin(), views.end(),
                    [](const CameraView& v) { return v.body_points.empty(); })) {
      continue;  // the same frames for every estimate
    }
    std::vector<Eigen::Isometry3d> singles;
    for (const CameraView& view : views) {
      const pose::PlanarPose single =
          pose::estimate_planar_pose(*view.camera, view.body_points, view.pixels);
      ASSERT_TRUE(single.valid) << single.rejection;
      singles.push_back(view.camera_from_world.inverse() * single.camera_from_object);
    }
    const MultiCameraPose fused = estimate_multi_camera_pose(views, singles.front());
    ASSERT_TRUE(fused.valid) << fused.rejection;
    EXPECT_EQ(fused.cameras_used, 4);
    EXPECT_EQ(fused.points_used, 32);
    fused_position.push_back(position_error(fused.world_from_body, truth));
    fused_rotation.push_back(rotation_error(fused.world_from_body, truth));
    for (size_t c = 0; c < cameras; ++c) {
      single_position[c].push_back(position_error(singles[c], truth));
      single_rotation[c].push_back(rotation_error(singles[c], truth));
    }
    ++frames;
  }
  for (double q : {0.5, 0.95}) {
    double best_position = 1e9, best_rotation = 1e9;
    for (size_t c = 0; c < cameras; ++c) {
      best_position = std::min(best_position, quantile(single_position[c], q));
      best_rotation = std::min(best_rotation, quantile(single_rotation[c], q));
    }
    const double position = quantile(fused_position, q), rotation = quantile(fused_rotation, q);
    EXPECT_LE(2 * position, best_position) << "quantile " << q << ": fused " << position * 1e3
                                           << " mm, best camera " << best_position * 1e3 << " mm";
    EXPECT_LE(2 * rotation, best_rotation)
        << "quantile " << q << ": fused " << rotation * 180 / kPi << " deg, best camera "
        << best_rotation * 180 / kPi << " deg";
    std::printf("quantile %.2f: fused %.3f mm %.4f deg; best single camera %.3f mm %.4f deg\n", q,
                position * 1e3, rotation * 180 / kPi, best_position * 1e3,
                best_rotation * 180 / kPi);
  }
}

// A body only one camera sees still gets a pose, said to be that camera's alone.
TEST(MultiCameraPose, OneCameraAloneGivesItsPoseFlaggedAsSuch) {
  const Volume volume;
  std::mt19937 random(3);
  const Eigen::Isometry3d truth = random_pose(random);
  std::vector<CameraView> views = views_of(volume, truth, 0.0, random);
  for (size_t c = 1; c < views.size(); ++c) {
    views[c].body_points.clear();
    views[c].pixels.clear();
  }
  ASSERT_FALSE(views[0].body_points.empty());
  Eigen::Isometry3d start = truth;
  start.translation() += Eigen::Vector3d(0.02, -0.01, 0.03);
  const MultiCameraPose fused = estimate_multi_camera_pose(views, start);
  ASSERT_TRUE(fused.valid) << fused.rejection;
  EXPECT_EQ(fused.cameras_used, 1);
  EXPECT_LT(position_error(fused.world_from_body, truth), 1e-6);
  EXPECT_EQ(fused.view_rms_px.size(), views.size());
  EXPECT_EQ(fused.view_rms_px[1], 0.0);
}

// Points on one line of the body leave the pose free to turn about it, however many cameras
// see them: two cameras that see only the board's first side (three markers, and two of them)
// give no pose, and say why; one marker off that line fixes it.
TEST(MultiCameraPose, PointsOnOneLineDoNotFixThePose) {
  const Volume volume;
  std::mt19937 random(5);
  Eigen::Isometry3d truth;
  std::vector<CameraView> views;
  do {
    truth = random_pose(random);
    views = views_of(volume, truth, 0.1, random);
  } while (views[0].body_points.empty() || views[1].body_points.empty());
  auto keep = [](CameraView& view, const std::vector<size_t>& markers) {
    CameraView kept{view.camera, view.camera_from_world, {}, {}, {}};
    for (size_t m : markers) {
      kept.body_points.push_back(view.body_points[m]);
      kept.pixels.push_back(view.pixels[m]);
    }
    view = kept;
  };
  std::vector<CameraView> line = views;
  keep(line[0], {0, 1, 2});  // (0, 0), (0.10, 0), (0.30, 0): the side along x
  keep(line[1], {0, 2});
  for (size_t c = 2; c < line.size(); ++c) keep(line[c], {});
  const MultiCameraPose on_a_line = estimate_multi_camera_pose(line, truth);
  EXPECT_FALSE(on_a_line.valid);
  EXPECT_NE(on_a_line.rejection.find("the points do not fix the pose"), std::string::npos)
      << on_a_line.rejection;

  std::vector<CameraView> off_the_line = views;
  keep(off_the_line[0], {0, 1, 2});
  keep(off_the_line[1], {0, 2, 4});  // and (0.30, 0.20)
  for (size_t c = 2; c < off_the_line.size(); ++c) keep(off_the_line[c], {});
  const MultiCameraPose fixed = estimate_multi_camera_pose(off_the_line, truth);
  ASSERT_TRUE(fixed.valid) << fixed.rejection;
  EXPECT_LT(position_error(fixed.world_from_body, truth), 2e-3);
  EXPECT_LT(rotation_error(fixed.world_from_body, truth), 0.5 * kPi / 180);
}

// A camera bumped by half a degree after calibration: its residuals stand out (by its index),
// and the covariance is that of a 6-DoF pose.
TEST(MultiCameraPose, ABumpedCameraStandsOutInItsResiduals) {
  Volume volume;
  std::mt19937 random(11);
  Eigen::Isometry3d truth;
  std::vector<CameraView> views;
  do {
    truth = random_pose(random);
    views = views_of(volume, truth, 0.1, random);
  } while (std::any_of(views.begin(), views.end(),
                       [](const CameraView& v) { return v.body_points.empty(); }));
  // The images were taken by the moved camera 2; the fusion still believes the old extrinsics.
  const Eigen::Isometry3d bump(Eigen::AngleAxisd(0.5 * kPi / 180, Eigen::Vector3d::UnitY()));
  views[2].camera_from_world = bump * views[2].camera_from_world;
  MultiCameraPoseOptions options;
  options.max_reprojection_rms_px = 100;  // keep the pose, to look at the residuals
  const MultiCameraPose fused = estimate_multi_camera_pose(views, truth, options);
  ASSERT_TRUE(fused.valid) << fused.rejection;
  // The fused pose spreads the moved camera's error over every view; without it, the others
  // agree to the noise, and without any other camera they do not.
  const std::vector<double> without = rms_without_each_view_px(views, truth);
  ASSERT_EQ(without.size(), views.size());
  EXPECT_LT(without[2], 0.3);
  for (size_t c = 0; c < views.size(); ++c) {
    if (c != 2) {
      EXPECT_GT(without[c], 10 * without[2]) << "without camera " << c;
    }
  }
  for (int k = 0; k < 6; ++k) EXPECT_GT(fused.covariance(k, k), 0) << k;
  // With the default bound, the bumped camera's disagreement rejects the pose.
  const MultiCameraPose strict = estimate_multi_camera_pose(views, truth);
  EXPECT_FALSE(strict.valid);
  EXPECT_NE(strict.rejection.find("reprojection RMS"), std::string::npos) << strict.rejection;
}

// Points whose detections err differently, and say so: most within 0.05 px, one pulled 1 px
// (a blob merged with a neighbour) whose detector says 1 px. Weighed by their sigmas, the pull
// barely moves the pose; weighed alike, it tilts it. The RMS stays in pixels either way.
TEST(MultiCameraPose, EachPointCountsByItsSigma) {
  const Volume volume;
  std::mt19937 random(5);
  double weighted_deg = 0, alike_deg = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Isometry3d truth = random_pose(random);
    std::vector<CameraView> views = views_of(volume, truth, 0.05, random);
    bool pulled = false;
    for (CameraView& view : views) {
      view.pixel_sigma_px.assign(view.pixels.size(), 0.05);
      if (!pulled && !view.pixels.empty()) {
        view.pixels[0].x() += 1.0;
        view.pixel_sigma_px[0] = 1.0;
        pulled = true;
      }
    }
    const MultiCameraPose weighted = estimate_multi_camera_pose(views, truth);
    for (CameraView& view : views) view.pixel_sigma_px.clear();
    const MultiCameraPose alike = estimate_multi_camera_pose(views, truth);
    ASSERT_TRUE(weighted.valid && alike.valid) << weighted.rejection << alike.rejection;
    weighted_deg += rotation_error(weighted.world_from_body, truth) / 50;
    alike_deg += rotation_error(alike.world_from_body, truth) / 50;
    // The weighted fit leaves the pulled point its whole pull: a larger RMS in pixels.
    EXPECT_GT(weighted.reprojection_rms_px, alike.reprojection_rms_px);
  }
  std::printf("mean orientation error: %.4f deg weighed by sigma, %.4f deg alike\n", weighted_deg,
              alike_deg);
  EXPECT_LT(weighted_deg, alike_deg / 2);
}

TEST(MultiCameraPose, TooFewPointsAreSaidAndBadOptionsThrow) {
  const Volume volume;
  CameraView view{volume.camera.get(), volume.extrinsics[0], {kBoard[0], kBoard[1]}, {}, {}};
  view.pixels = {{600, 300}, {620, 300}};
  const MultiCameraPose result = estimate_multi_camera_pose({view}, Eigen::Isometry3d::Identity());
  EXPECT_FALSE(result.valid);
  EXPECT_EQ(result.rejection, "2 points in all views, 4 needed");
  MultiCameraPoseOptions options;
  options.min_points = 2;
  EXPECT_THROW(estimate_multi_camera_pose({view}, Eigen::Isometry3d::Identity(), options),
               std::invalid_argument);
  view.pixel_sigma_px = {0.1};  // one sigma for two pixels
  EXPECT_THROW(estimate_multi_camera_pose({view}, Eigen::Isometry3d::Identity()),
               std::invalid_argument);
  view.pixel_sigma_px.clear();
  view.pixels.pop_back();
  EXPECT_THROW(estimate_multi_camera_pose({view}, Eigen::Isometry3d::Identity()),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::volume
