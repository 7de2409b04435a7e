// The synthetic IR camera's library: trajectories, scene files, and what the renderer draws
// compared with where the camera model says the markers are.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/calibration/pinhole_camera.hpp>

#include "sim/synthetic_ir_camera/ir_renderer.hpp"
#include "sim/synthetic_ir_camera/scene.hpp"
#include "sim/synthetic_ir_camera/trajectory.hpp"
#include "test/test_support.hpp"
#include "tracking/constellation_database/constellation_database.hpp"

namespace mocap::synthetic {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

const constellations::ConstellationDatabase& shipped_database() {
  static const constellations::ConstellationDatabase database = constellations::load_database(
      (test::source_dir() / "config" / "constellations.yaml").string());
  return database;
}

// An ideal lens, so that expected pixels follow from the intrinsics alone.
std::shared_ptr<const calibration::CameraModel> ideal_camera() {
  calibration::PinholeIntrinsics intrinsics;
  intrinsics.fx = intrinsics.fy = 600;
  intrinsics.cx = 319.5;
  intrinsics.cy = 239.5;
  return std::make_shared<calibration::PinholeCamera>(640, 480, intrinsics);
}

std::shared_ptr<const calibration::CameraModel> shipped_camera() {
  return calibration::load_camera_file(
             (test::source_dir() / "config" / "cameras" / "synthetic_ir_1280x720.yaml").string())
      .model;
}

// No noise and no saturation: pixel values follow from the geometry alone.
RenderOptions clean_options() {
  RenderOptions options;
  options.noise_sigma_dn = 0;
  options.exposure = 0.8;
  options.background_dn = 8;
  return options;
}

Scene board_scene(Trajectory trajectory, RenderOptions options = clean_options(),
                  const std::string& board = "board_a") {
  const constellations::ConstellationModel* model = shipped_database().find(board);
  EXPECT_NE(model, nullptr);
  Scene scene;
  scene.render = options;
  scene.objects.push_back({board, model->points, std::move(trajectory), std::nullopt});
  return scene;
}

// One marker at the origin of its constellation frame: nothing else in its image.
Scene single_marker_scene(Trajectory trajectory, RenderOptions options) {
  Scene scene;
  scene.render = options;
  scene.objects.push_back(
      {"single", {Eigen::Vector3d::Zero()}, std::move(trajectory), std::nullopt});
  return scene;
}

void expect_near(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected,
                 double tolerance = 1e-9) {
  EXPECT_LT((actual - expected).norm(), tolerance)
      << "actual " << actual.transpose() << ", expected " << expected.transpose();
}

// The angle of the rotation from `a` to `b`.
double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

// Intensity above `background` in a square window around `centre`: its sum, intensity-weighted
// centroid and second central moments.
struct BlobMoments {
  double sum = 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};

BlobMoments moments(const cv::Mat& image, const Eigen::Vector2d& centre, int half_size,
                    double background) {
  BlobMoments blob;
  int u0 = static_cast<int>(std::lround(centre.x())),
      v0 = static_cast<int>(std::lround(centre.y()));
  Eigen::Vector2d first = Eigen::Vector2d::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
  for (int v = std::max(v0 - half_size, 0); v <= std::min(v0 + half_size, image.rows - 1); ++v) {
    for (int u = std::max(u0 - half_size, 0); u <= std::min(u0 + half_size, image.cols - 1); ++u) {
      double weight = std::max(image.at<uint8_t>(v, u) - background, 0.0);
      Eigen::Vector2d p(u, v);
      blob.sum += weight;
      first += weight * p;
      second += weight * p * p.transpose();
    }
  }
  if (blob.sum > 0) {
    blob.centroid = first / blob.sum;
    blob.covariance = second / blob.sum - blob.centroid * blob.centroid.transpose();
  }
  return blob;
}

// ---------------------------------------------------------------------------------------------
// Trajectories

TEST(Trajectory, FacingMeansMarkersTowardsTheCameraAndAnglesTurnAsDocumented) {
  Eigen::Matrix3d facing = facing_orientation();
  expect_near(facing.col(0), Eigen::Vector3d(1, 0, 0));   // board x: right
  expect_near(facing.col(1), Eigen::Vector3d(0, -1, 0));  // board y: up
  expect_near(facing.col(2), Eigen::Vector3d(0, 0, -1));  // board z: towards the camera
  // Yaw +90: the marker side faces the camera's right.
  expect_near(facing_orientation({0, 0, 90}).col(2), Eigen::Vector3d(1, 0, 0));
  // Pitch +90: the marker side faces down.
  expect_near(facing_orientation({0, 90, 0}).col(2), Eigen::Vector3d(0, 1, 0));
  // Roll +90: counter-clockwise as the camera sees it, board x points up.
  expect_near(facing_orientation({90, 0, 0}).col(0), Eigen::Vector3d(0, -1, 0));
}

TEST(Trajectory, StaticHoldsItsPose) {
  StaticTrajectory motion{{0.1, -0.2, 1.7}, {0, 0, 30}};
  for (double t : {-5.0, 0.0, 12.5}) {
    Eigen::Isometry3d pose = pose_at(motion, t);
    expect_near(pose.translation(), {0.1, -0.2, 1.7});
    EXPECT_NEAR(angle_between(pose.linear(), facing_orientation()), 30 * kDeg, 1e-9);
  }
}

TEST(Trajectory, KeyframesInterpolateLinearlyAndBySlerp) {
  KeyframeTrajectory motion;
  motion.keyframes = {
      {1.0, {0, 0, 1}, {0, 0, 0}}, {3.0, {1, 0, 3}, {0, 0, 90}}, {4.0, {1, 1, 3}, {0, 0, 90}}};
  Eigen::Isometry3d middle = pose_at(motion, 2.0);
  expect_near(middle.translation(), {0.5, 0, 2});
  expect_near(middle.linear().col(2), facing_orientation({0, 0, 45}).col(2));
  EXPECT_NEAR(angle_between(middle.linear(), facing_orientation()), 45 * kDeg, 1e-9);
  // A quarter of the way: 22.5 degrees, 0.25 m.
  Eigen::Isometry3d quarter = pose_at(motion, 1.5);
  expect_near(quarter.translation(), {0.25, 0, 1.5});
  EXPECT_NEAR(angle_between(quarter.linear(), facing_orientation()), 22.5 * kDeg, 1e-9);
  expect_near(pose_at(motion, 3.5).translation(), {1, 0.5, 3});
  // Holds before the first and after the last keyframe.
  expect_near(pose_at(motion, -10).translation(), {0, 0, 1});
  expect_near(pose_at(motion, 10).translation(), {1, 1, 3});

  motion.loop = true;  // period 3 s from t = 1
  expect_near(pose_at(motion, 5.0).translation(), {0.5, 0, 2});
  expect_near(pose_at(motion, -1.0).translation(), {0.5, 0, 2});
  expect_near(pose_at(motion, 6.5).translation(), {1, 0.5, 3});
}

TEST(Trajectory, OrbitRunsRoundItsCentre) {
  OrbitTrajectory motion;
  motion.centre = {0.2, 0.1, 2};
  motion.radius_m = 0.5;
  motion.period_s = 8;
  expect_near(pose_at(motion, 0).translation(), {0.7, 0.1, 2});
  // Counter-clockwise as the camera sees it: a quarter turn later it is above (-y).
  expect_near(pose_at(motion, 2).translation(), {0.2, -0.4, 2});
  expect_near(pose_at(motion, 4).translation(), {-0.3, 0.1, 2});
  expect_near(pose_at(motion, 8).translation(), {0.7, 0.1, 2});
  EXPECT_NEAR(angle_between(pose_at(motion, 3).linear(), facing_orientation()), 0, 1e-9);

  motion.phase_deg = 90;
  expect_near(pose_at(motion, 0).translation(), {0.2, -0.4, 2});
  motion.tilt_deg = 30;  // the top of the circle moves away from the camera
  expect_near(pose_at(motion, 0).translation(),
              {0.2, 0.1 - 0.5 * std::cos(30 * kDeg), 2 + 0.5 * std::sin(30 * kDeg)});

  motion.tilt_deg = 0;
  motion.phase_deg = 0;
  motion.plane = OrbitTrajectory::Plane::Horizontal;
  expect_near(pose_at(motion, 2).translation(), {0.2, 0.1, 2.5});
  expect_near(pose_at(motion, 6).translation(), {0.2, 0.1, 1.5});
}

TEST(Trajectory, WalkGoesBackAndForthAndSwingsItsYaw) {
  WalkTrajectory motion;
  motion.from = {-1, 0, 2};
  motion.to = {1, 0, 2};
  motion.speed_mps = 0.5;  // 4 s per leg
  motion.yaw_swing_deg = 20;
  motion.swing_period_s = 4;
  expect_near(pose_at(motion, 0).translation(), {-1, 0, 2});
  expect_near(pose_at(motion, 1).translation(), {-0.5, 0, 2});
  expect_near(pose_at(motion, 4).translation(), {1, 0, 2});
  expect_near(pose_at(motion, 5).translation(), {0.5, 0, 2});
  expect_near(pose_at(motion, 8).translation(), {-1, 0, 2});
  // The swing peaks a quarter period in, turning the marker side to the right.
  Eigen::Matrix3d peak = pose_at(motion, 1).linear();
  EXPECT_NEAR(angle_between(peak, facing_orientation()), 20 * kDeg, 1e-9);
  EXPECT_GT(peak.col(2).x(), 0);
  EXPECT_NEAR(angle_between(pose_at(motion, 2).linear(), facing_orientation()), 0, 1e-9);
}

TEST(Trajectory, SpinTurnsAboutTheBoardsAxis) {
  SpinTrajectory motion;
  motion.position = {0, 0, 1};
  motion.axis = {0, 0, 2};  // normalised internally
  motion.rate_deg_s = 90;
  Eigen::Isometry3d pose = pose_at(motion, 1);
  expect_near(pose.translation(), {0, 0, 1});
  expect_near(pose.linear().col(0), Eigen::Vector3d(0, -1, 0));  // board x now points up
  expect_near(pose.linear().col(2), Eigen::Vector3d(0, 0, -1));  // still facing the camera

  motion.axis = {0, 1, 0};  // about the vertical: its back shows after 90 degrees
  EXPECT_LT(pose_at(motion, 0.5).linear().col(2).z(), 0);
  EXPECT_GT(pose_at(motion, 1.5).linear().col(2).z(), 0);
}

// ---------------------------------------------------------------------------------------------
// Scene files

TEST(SceneFile, ReadsEveryKey) {
  Scene scene = parse_scene(R"(
seed: 42
render: {marker_diameter_m: 0.02, exposure: 0.5, background_dn: 10, noise_sigma_dn: 1.5,
         blur_sigma_px: 0.8, motion_blur_s: 0.01, motion_blur_steps: 5, supersampling: 6}
objects:
  - constellation: board_b
    trajectory: {type: static, position: [0.1, 0.2, 1.5], rpy_deg: [1, 2, 3]}
    occlusion: {fraction: 0.25, side: bottom}
  - constellation: board_c
    trajectory:
      type: keyframes
      loop: true
      keyframes:
        - {t: 0, position: [0, 0, 1]}
        - {t: 2, position: [1, 0, 1], rpy_deg: [0, 0, 45]}
  - constellation: board_d
    trajectory: {type: orbit, centre: [0, 0, 2], radius_m: 0.3, period_s: 5, phase_deg: 10,
                 plane: horizontal, tilt_deg: 5, rpy_deg: [0, 0, 10]}
  - constellation: board_e
    trajectory: {type: walk, from: [0, 0, 1], to: [1, 0, 1], speed_mps: 0.2, yaw_swing_deg: 15,
                 swing_period_s: 3}
  - constellation: board_f
    trajectory: {type: spin, position: [0, 0, 2], axis: [0, 1, 0], rate_deg_s: 45}
distractors:
  blobs:
    - {shape: rectangle, position_px: [100, 50], size_px: [30, 6], angle_deg: 45,
       brightness_dn: 200}
  hot_points: {count: 5, brightness_dn: 250, fixed: true}
  lamp: {position_px: [600, 40], radius_px: 12, brightness_dn: 240, glow_px: 6}
  occluders:
    - {position_px: [300, 0], size_px: [20, 480], level_dn: 30}
)",
                            "scene.yaml", shipped_database());
  EXPECT_EQ(scene.seed, 42u);
  EXPECT_EQ(scene.source, "scene.yaml");
  EXPECT_DOUBLE_EQ(scene.render.marker_diameter_m, 0.02);
  EXPECT_DOUBLE_EQ(scene.render.exposure, 0.5);
  EXPECT_DOUBLE_EQ(scene.render.background_dn, 10);
  EXPECT_DOUBLE_EQ(scene.render.noise_sigma_dn, 1.5);
  EXPECT_DOUBLE_EQ(scene.render.blur_sigma_px, 0.8);
  EXPECT_DOUBLE_EQ(scene.render.motion_blur_s, 0.01);
  EXPECT_EQ(scene.render.motion_blur_steps, 5);
  EXPECT_EQ(scene.render.supersampling, 6);

  ASSERT_EQ(scene.objects.size(), 5u);
  EXPECT_EQ(scene.objects[0].constellation, "board_b");
  EXPECT_EQ(scene.objects[0].markers, shipped_database().find("board_b")->points);
  ASSERT_TRUE(scene.objects[0].occlusion);
  EXPECT_DOUBLE_EQ(scene.objects[0].occlusion->fraction, 0.25);
  EXPECT_EQ(scene.objects[0].occlusion->side, ObjectOcclusion::Side::Bottom);
  const auto& still = std::get<StaticTrajectory>(scene.objects[0].trajectory);
  expect_near(still.position, {0.1, 0.2, 1.5});
  expect_near(still.rpy_deg, {1, 2, 3});
  const auto& keys = std::get<KeyframeTrajectory>(scene.objects[1].trajectory);
  EXPECT_TRUE(keys.loop);
  ASSERT_EQ(keys.keyframes.size(), 2u);
  EXPECT_DOUBLE_EQ(keys.keyframes[1].time_s, 2);
  expect_near(keys.keyframes[1].rpy_deg, {0, 0, 45});
  const auto& orbit = std::get<OrbitTrajectory>(scene.objects[2].trajectory);
  EXPECT_EQ(orbit.plane, OrbitTrajectory::Plane::Horizontal);
  EXPECT_DOUBLE_EQ(orbit.radius_m, 0.3);
  EXPECT_DOUBLE_EQ(orbit.period_s, 5);
  EXPECT_DOUBLE_EQ(orbit.phase_deg, 10);
  EXPECT_DOUBLE_EQ(orbit.tilt_deg, 5);
  const auto& walk = std::get<WalkTrajectory>(scene.objects[3].trajectory);
  EXPECT_DOUBLE_EQ(walk.speed_mps, 0.2);
  EXPECT_DOUBLE_EQ(walk.yaw_swing_deg, 15);
  EXPECT_DOUBLE_EQ(walk.swing_period_s, 3);
  const auto& spin = std::get<SpinTrajectory>(scene.objects[4].trajectory);
  expect_near(spin.axis, {0, 1, 0});
  EXPECT_DOUBLE_EQ(spin.rate_deg_s, 45);
  EXPECT_EQ(type_name(scene.objects[4].trajectory), "spin");

  const Distractors& distractors = scene.distractors;
  ASSERT_EQ(distractors.blobs.size(), 1u);
  EXPECT_EQ(distractors.blobs[0].shape, Blob::Shape::Rectangle);
  EXPECT_EQ(distractors.blobs[0].centre_px, Eigen::Vector2d(100, 50));
  EXPECT_EQ(distractors.blobs[0].size_px, Eigen::Vector2d(30, 6));
  EXPECT_DOUBLE_EQ(distractors.blobs[0].angle_deg, 45);
  EXPECT_DOUBLE_EQ(distractors.blobs[0].brightness_dn, 200);
  EXPECT_EQ(distractors.hot_points.count, 5);
  EXPECT_TRUE(distractors.hot_points.fixed);
  EXPECT_DOUBLE_EQ(distractors.hot_points.brightness_dn, 250);
  ASSERT_TRUE(distractors.lamp);
  EXPECT_DOUBLE_EQ(distractors.lamp->radius_px, 12);
  EXPECT_DOUBLE_EQ(distractors.lamp->glow_px, 6);
  ASSERT_EQ(distractors.occluders.size(), 1u);
  EXPECT_EQ(distractors.occluders[0].size_px, Eigen::Vector2d(20, 480));
  EXPECT_DOUBLE_EQ(distractors.occluders[0].level_dn, 30);
}

// The message of the SceneError that parsing `text` throws.
std::string scene_error(const std::string& text) {
  try {
    parse_scene(text, "bad.yaml", shipped_database());
  } catch (const SceneError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no SceneError for:\n" << text;
  return "";
}

TEST(SceneFile, ErrorsNameTheFileTheLineAndTheProblem) {
  constexpr const char* kObject =
      "objects:\n"
      "  - constellation: board_a\n"
      "    trajectory: {type: static, position: [0, 0, 1]}\n";
  // An unknown key, with the key it probably meant.
  EXPECT_EQ(scene_error(std::string(kObject) + "render:\n  exposre: 2\n"),
            "bad.yaml:5: unknown key 'exposre' in 'render' (did you mean 'exposure'?)");
  // Far from every key: the keys it may be.
  EXPECT_EQ(scene_error(std::string(kObject) + "render:\n  brightness: 2\n"),
            "bad.yaml:5: unknown key 'brightness' in 'render' (keys: marker_diameter_m, exposure, "
            "background_dn, noise_sigma_dn, blur_sigma_px, motion_blur_s, motion_blur_steps, "
            "supersampling)");
  EXPECT_EQ(scene_error("objects:\n"
                        "  - constellation: board_z\n"
                        "    trajectory: {type: static, position: [0, 0, 1]}\n"),
            "bad.yaml:2: unknown constellation 'board_z' (known: board_a, board_b, board_c, "
            "board_d, board_e, board_f, board_g, board_h)");
  EXPECT_EQ(scene_error("objects:\n"
                        "  - constellation: board_a\n"
                        "    trajectory:\n"
                        "      type: orbit\n"
                        "      centre: [0, 0, 2]\n"
                        "      period_s: fast\n"),
            "bad.yaml:6: 'period_s' must be a number, not 'fast'");
  EXPECT_EQ(scene_error("objects:\n"
                        "  - constellation: board_a\n"
                        "    trajectory: {type: static, position: [0, 1]}\n"),
            "bad.yaml:3: 'position' must be a list of 3 numbers, not a list of 2");
  EXPECT_EQ(scene_error("objects:\n"
                        "  - constellation: board_a\n"
                        "    trajectory: {type: teleport}\n"),
            "bad.yaml:3: 'type' is 'teleport', must be one of: static, keyframes, orbit, walk, "
            "spin");
  EXPECT_EQ(scene_error("objects:\n"
                        "  - constellation: board_a\n"
                        "    trajectory:\n"
                        "      type: walk\n"
                        "      to: [1, 0, 1]\n"),
            "bad.yaml:4: a walk trajectory needs 'from'");
  EXPECT_EQ(scene_error("objects:\n"
                        "  - constellation: board_a\n"
                        "    trajectory:\n"
                        "      type: keyframes\n"
                        "      keyframes:\n"
                        "        - {t: 1, position: [0, 0, 1]}\n"
                        "        - {t: 1, position: [0, 0, 2]}\n"),
            "bad.yaml:7: keyframe times must increase: 1 follows 1");
  EXPECT_EQ(scene_error(std::string(kObject) + "render: {noise_sigma_dn: -1}\n"),
            "bad.yaml:4: 'noise_sigma_dn' is -1, must be in [0, 100]");
  EXPECT_EQ(scene_error(std::string(kObject) + "distractors:\n  hot_points: {count: 2.5}\n"),
            "bad.yaml:5: 'count' must be an integer, not '2.5'");
  EXPECT_EQ(scene_error(std::string(kObject) + "seed: 1\nseed: 2\n"),
            "bad.yaml:5: 'seed' appears twice in the scene");
  EXPECT_EQ(scene_error("objects: [\n"),
            "bad.yaml:2:1: YAML error: end of sequence flow not found");
  EXPECT_EQ(scene_error("render: {}\n"), "bad.yaml:1: the scene needs 'objects'");
}

TEST(SceneFile, LoadNamesTheFile) {
  test::TempDir directory;
  std::filesystem::path path = directory / "scene.yaml";
  test::write_file(path, "objects:\n  - constellation: board_a\n    trajectory: {type: static}\n");
  try {
    load_scene(path.string(), shipped_database());
    FAIL() << "no error";
  } catch (const SceneError& error) {
    EXPECT_EQ(std::string(error.what()),
              path.string() + ":3: a static trajectory needs 'position'");
  }
  try {
    load_scene((directory / "missing.yaml").string(), shipped_database());
    FAIL() << "no error";
  } catch (const SceneError& error) {
    EXPECT_EQ(std::string(error.what()), (directory / "missing.yaml").string() +
                                             ": cannot read the scene: No such file or "
                                             "directory");
  }
}

TEST(SceneFile, TheShippedScenesLoadAndShowTheirBoards) {
  std::shared_ptr<const calibration::CameraModel> camera = shipped_camera();
  for (const char* name : {"demo.yaml", "eight_boards.yaml", "distractors.yaml"}) {
    SCOPED_TRACE(name);
    Scene scene =
        load_scene((test::source_dir() / "config" / "scenes" / name).string(), shipped_database());
    ASSERT_FALSE(scene.objects.empty());
    IrRenderer renderer(scene, camera);
    for (double t : {0.0, 2.5, 7.0}) {
      RenderedFrame frame = renderer.render(t, 1);
      for (const ObjectTruth& object : frame.objects) {
        EXPECT_TRUE(object.in_front) << object.constellation;
        EXPECT_TRUE(object.facing_camera) << object.constellation;
        EXPECT_GE(object.visible_markers(), 8) << object.constellation << " at " << t;
      }
    }
  }
  Scene eight = load_scene((test::source_dir() / "config/scenes/eight_boards.yaml").string(),
                           shipped_database());
  ASSERT_EQ(eight.objects.size(), 8u);
  RenderedFrame frame = IrRenderer(eight, camera).render(3.0, 0);
  for (const ObjectTruth& object : frame.objects) EXPECT_EQ(object.visible_markers(), 12);
}

// ---------------------------------------------------------------------------------------------
// Rendering

TEST(IrRenderer, GroundTruthIsTheCameraModelsProjection) {
  std::shared_ptr<const calibration::CameraModel> camera = shipped_camera();
  Scene scene = board_scene(StaticTrajectory{{0.3, -0.1, 1.8}, {5, 20, -30}});
  IrRenderer renderer(scene, camera);
  RenderedFrame frame = renderer.render(0.5);
  EXPECT_DOUBLE_EQ(frame.time_s, 0.5);
  ASSERT_EQ(frame.objects.size(), 1u);
  const ObjectTruth& truth = frame.objects[0];
  EXPECT_EQ(truth.constellation, "board_a");
  EXPECT_TRUE(truth.in_front);
  EXPECT_TRUE(truth.facing_camera);
  expect_near(truth.pose.translation(), {0.3, -0.1, 1.8});
  ASSERT_EQ(truth.markers.size(), scene.objects[0].markers.size());
  for (size_t i = 0; i < truth.markers.size(); ++i) {
    Eigen::Vector2d expected = *camera->project(truth.pose * scene.objects[0].markers[i]);
    EXPECT_LT((truth.markers[i].pixel - expected).norm(), 1e-12);
    EXPECT_TRUE(truth.markers[i].visible);
  }
  EXPECT_EQ(truth.visible_markers(), 12);
}

TEST(IrRenderer, AMovingCameraSeesTheWorldFromWhereItStands) {
  const Eigen::Vector3d board_in_world(1.3, 0.4, 1.5), rpy(5, 20, -30);
  IrRenderer moving(board_scene(StaticTrajectory{board_in_world, rpy}), shipped_camera());
  // Moved by (1, 0.5, −0.3): the same picture as a fixed camera with the board that much
  // nearer, pixel for pixel.
  Eigen::Isometry3d world_from_camera(Eigen::Translation3d(1.0, 0.5, -0.3));
  RenderedFrame seen = moving.render(0, 0, world_from_camera.inverse());
  IrRenderer fixed(
      board_scene(StaticTrajectory{board_in_world - Eigen::Vector3d(1.0, 0.5, -0.3), rpy}),
      shipped_camera());
  RenderedFrame expected = fixed.render(0, 0);
  ASSERT_EQ(seen.objects.size(), 1u);
  expect_near(seen.objects[0].pose.translation(), {0.3, -0.1, 1.8});
  EXPECT_EQ(seen.objects[0].visible_markers(), 12);
  EXPECT_EQ(cv::norm(seen.image, expected.image, cv::NORM_INF), 0);
  // Turned as well: the truth is the board in the camera's frame.
  world_from_camera.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0).normalized()));
  RenderedFrame turned = moving.render(0, 0, world_from_camera.inverse());
  const Eigen::Isometry3d board = pose_at(StaticTrajectory{board_in_world, rpy}, 0);
  EXPECT_TRUE(turned.objects[0].pose.isApprox(world_from_camera.inverse() * board, 1e-12));
}

TEST(IrRenderer, MarkerCentroidsLieOnTheProjectedCentres) {
  // Fronto-parallel, off the pixel grid, with the default blur and no noise.
  Scene scene = board_scene(StaticTrajectory{{0.0213, -0.0137, 1.2}, {0, 0, 0}});
  std::shared_ptr<const calibration::CameraModel> camera = ideal_camera();
  IrRenderer renderer(scene, camera);
  RenderedFrame frame = renderer.render(0);
  double radius_px = 600 * 0.0075 / 1.2;
  int window = static_cast<int>(std::ceil(radius_px)) + 4;
  ASSERT_EQ(frame.objects[0].visible_markers(), 12);
  for (const MarkerTruth& marker : frame.objects[0].markers) {
    BlobMoments blob = moments(frame.image, marker.pixel, window, 8);
    EXPECT_LT((blob.centroid - marker.pixel).norm(), 0.1)
        << "centroid " << blob.centroid.transpose() << ", projected " << marker.pixel.transpose();
    // The disc's image has the disc's projected area: sum / peak = area in pixels.
    EXPECT_NEAR(blob.sum / (0.8 * 255), std::numbers::pi * radius_px * radius_px,
                0.02 * std::numbers::pi * radius_px * radius_px);
  }
}

TEST(IrRenderer, MarkerCentroidsFollowTheLensAndTheBoardsTilt) {
  // The shipped camera's lens distortion, a tilted board: centroids still within 0.1 px.
  Scene scene = board_scene(StaticTrajectory{{0.45, 0.2, 1.4}, {10, -25, 35}});
  IrRenderer renderer(scene, shipped_camera());
  RenderedFrame frame = renderer.render(0);
  ASSERT_EQ(frame.objects[0].visible_markers(), 12);
  for (const MarkerTruth& marker : frame.objects[0].markers) {
    BlobMoments blob = moments(frame.image, marker.pixel, 10, 8);
    EXPECT_LT((blob.centroid - marker.pixel).norm(), 0.1)
        << "centroid " << blob.centroid.transpose() << ", projected " << marker.pixel.transpose();
  }
}

TEST(IrRenderer, TiltedMarkersBecomeEllipsesOfTheProjectedArea) {
  // A 3 cm disc on the optical axis at 1.5 m, yawed 60 degrees: its image is half as wide as
  // high, and has half the area.
  RenderOptions options = clean_options();
  options.blur_sigma_px = 0;
  options.marker_diameter_m = 0.03;
  Scene scene = single_marker_scene(StaticTrajectory{{0, 0, 1.5}, {0, 0, 60}}, options);
  RenderedFrame frame = IrRenderer(scene, ideal_camera()).render(0);
  const MarkerTruth& marker = frame.objects[0].markers[0];
  ASSERT_TRUE(marker.visible);
  BlobMoments blob = moments(frame.image, marker.pixel, 12, 8);
  double radius_px = 600 * 0.015 / 1.5;
  EXPECT_NEAR(blob.sum / (0.8 * 255), 0.5 * std::numbers::pi * radius_px * radius_px,
              0.02 * std::numbers::pi * radius_px * radius_px);
  // A uniform ellipse has variance semi-axis^2 / 4 along each axis; whole pixels add 1/12.
  EXPECT_NEAR(2 * std::sqrt(blob.covariance(0, 0) - 1.0 / 12), 0.5 * radius_px, 0.1);
  EXPECT_NEAR(2 * std::sqrt(blob.covariance(1, 1) - 1.0 / 12), radius_px, 0.1);
  EXPECT_NEAR(blob.covariance(0, 1), 0, 0.05);
  EXPECT_LT((blob.centroid - marker.pixel).norm(), 0.1);
}

TEST(IrRenderer, ABoardFacingAwayOrBehindTheCameraDrawsNothing) {
  for (Trajectory trajectory : std::vector<Trajectory>{
           StaticTrajectory{{0, 0, 1.5}, {0, 0, 180}},    // its back to the camera
           StaticTrajectory{{0, 0, 1.5}, {0, 100, 0}},    // tilted beyond edge-on
           StaticTrajectory{{0, 0, -1.5}, {0, 0, 0}}}) {  // behind the camera
    Scene scene = board_scene(trajectory);
    RenderedFrame frame = IrRenderer(scene, ideal_camera()).render(0);
    double min = 0, max = 0;
    cv::minMaxLoc(frame.image, &min, &max);
    EXPECT_EQ(min, 8);
    EXPECT_EQ(max, 8);
    EXPECT_FALSE(frame.objects[0].facing_camera && frame.objects[0].in_front);
    EXPECT_EQ(frame.objects[0].visible_markers(), 0);
  }
  Scene behind = board_scene(StaticTrajectory{{0, 0, -1.5}, {0, 0, 0}});
  EXPECT_FALSE(IrRenderer(behind, ideal_camera()).render(0).objects[0].in_front);
}

TEST(IrRenderer, OccludersHideMarkersAndFlagThemInvisible) {
  Scene scene = board_scene(StaticTrajectory{{0, 0, 1.2}, {0, 0, 0}});
  // A pole over the left half of the image, at its own brightness.
  scene.distractors.occluders.push_back({{0, 0}, {320, 480}, 20});
  RenderedFrame frame = IrRenderer(scene, ideal_camera()).render(0);
  int hidden = 0, shown = 0;
  for (const MarkerTruth& marker : frame.objects[0].markers) {
    BlobMoments blob = moments(frame.image, marker.pixel, 3, 8);
    if (marker.pixel.x() < 319.5) {
      ++hidden;
      EXPECT_FALSE(marker.visible);
      EXPECT_EQ(frame.image.at<uint8_t>(static_cast<int>(std::lround(marker.pixel.y())),
                                        static_cast<int>(std::lround(marker.pixel.x()))),
                20);
    } else {
      ++shown;
      EXPECT_TRUE(marker.visible);
      EXPECT_GT(blob.sum, 500);
    }
  }
  EXPECT_GT(hidden, 3);
  EXPECT_GT(shown, 3);
  cv::Mat left = frame.image(cv::Rect(0, 0, 320, 480));
  EXPECT_EQ(cv::countNonZero(left != 20), 0);
}

TEST(IrRenderer, AnObjectsOcclusionCoversItsShareOfTheBoard) {
  Scene scene = board_scene(StaticTrajectory{{0, 0, 1.2}, {0, 0, 0}});
  scene.objects[0].occlusion = ObjectOcclusion{0.5, ObjectOcclusion::Side::Right};
  RenderedFrame frame = IrRenderer(scene, ideal_camera()).render(0);
  int hidden = 0;
  for (const MarkerTruth& marker : frame.objects[0].markers) {
    bool right_half = marker.pixel.x() > 319.5 + 1;
    bool left_half = marker.pixel.x() < 319.5 - 1;
    BlobMoments blob = moments(frame.image, marker.pixel, 3, 8);
    if (right_half) {
      EXPECT_FALSE(marker.visible);
      EXPECT_EQ(blob.sum, 0);
      ++hidden;
    }
    if (left_half) {
      EXPECT_TRUE(marker.visible);
      EXPECT_GT(blob.sum, 500);
    }
  }
  EXPECT_GT(hidden, 3);
}

TEST(IrRenderer, MotionBlurSmearsMarkersAlongTheirMotion) {
  // 1 m/s to the right at 1.5 m over a 20 ms exposure: 2 cm, 8 px.
  WalkTrajectory walk;
  walk.from = {-1, 0, 1.5};
  walk.to = {1, 0, 1.5};
  walk.speed_mps = 1;
  RenderOptions options = clean_options();
  Scene sharp = single_marker_scene(walk, options);
  options.motion_blur_s = 0.02;
  Scene blurred = single_marker_scene(walk, options);
  std::shared_ptr<const calibration::CameraModel> camera = ideal_camera();
  RenderedFrame still = IrRenderer(sharp, camera).render(1.0);
  RenderedFrame moving = IrRenderer(blurred, camera).render(1.0);
  double smear_px = 600 * 0.02 / 1.5;

  const Eigen::Vector2d& pixel = moving.objects[0].markers[0].pixel;
  EXPECT_LT((pixel - still.objects[0].markers[0].pixel).norm(), 1e-9);  // at mid-exposure
  BlobMoments a = moments(still.image, pixel, 15, 8);
  BlobMoments b = moments(moving.image, pixel, 15, 8);
  // Round when still; when moving, longer along x by the smear (a box of width smear_px adds
  // smear_px^2 / 12 to the variance) and unchanged across.
  EXPECT_NEAR(a.covariance(0, 0), a.covariance(1, 1), 0.05);
  EXPECT_NEAR(b.covariance(0, 0) - a.covariance(0, 0), smear_px * smear_px / 12, 0.2);
  // Across, only the rounding of the dimmer tails to whole DN differs.
  EXPECT_NEAR(b.covariance(1, 1), a.covariance(1, 1), 0.1);
  // The same light, spread out, centred on the mid-exposure position.
  EXPECT_NEAR(b.sum, a.sum, 0.02 * a.sum);
  EXPECT_LT((b.centroid - pixel).norm(), 0.1);
}

TEST(IrRenderer, NoiseHasTheRequestedSpreadAndFollowsTheFrameNumber) {
  Scene scene;
  scene.render.background_dn = 40;  // far from 0, so that no noise is clipped
  scene.render.noise_sigma_dn = 2;
  IrRenderer renderer(scene, ideal_camera());
  cv::Mat first = renderer.render(0, 1).image;
  cv::Scalar mean, deviation;
  cv::meanStdDev(first, mean, deviation);
  EXPECT_NEAR(mean[0], 40, 0.05);
  // Rounding to whole DN adds 1/12 to the variance.
  EXPECT_NEAR(deviation[0], std::sqrt(4 + 1.0 / 12), 0.05);

  cv::Mat again = renderer.render(0, 1).image;
  cv::Mat second = renderer.render(0, 2).image;
  EXPECT_EQ(cv::countNonZero(first != again), 0);  // same frame number, same frame
  // Different frames: the noise of a pixel in two frames is uncorrelated.
  cv::Mat a, b;
  first.convertTo(a, CV_64F, 1, -40);
  second.convertTo(b, CV_64F, 1, -40);
  double correlation = a.dot(b) / std::sqrt(a.dot(a) * b.dot(b));
  EXPECT_LT(std::abs(correlation), 0.01);
  // Neighbouring pixels too.
  double neighbours = a.colRange(0, a.cols - 1).dot(a.colRange(1, a.cols)) / a.dot(a);
  EXPECT_LT(std::abs(neighbours), 0.01);
}

TEST(IrRenderer, HotPointsAreSinglePixelsNewEachFrameUnlessFixed) {
  Scene scene;
  scene.render.noise_sigma_dn = 0;
  scene.distractors.hot_points = {10, 240, false};
  IrRenderer moving(scene, ideal_camera());
  cv::Mat first = moving.render(0, 1).image;
  cv::Mat second = moving.render(0, 2).image;
  EXPECT_EQ(cv::countNonZero(first == 248), 10);
  EXPECT_EQ(cv::countNonZero(first == 8), 640 * 480 - 10);
  EXPECT_GT(cv::countNonZero(first != second), 0);

  scene.distractors.hot_points.fixed = true;
  IrRenderer fixed(scene, ideal_camera());
  cv::Mat third = fixed.render(0, 1).image;
  EXPECT_EQ(cv::countNonZero(third == 248), 10);
  EXPECT_EQ(cv::countNonZero(third != fixed.render(0, 2).image), 0);
}

TEST(IrRenderer, BlobsAndLampsAreDrawnWhereAndHowTheSceneSays) {
  Scene scene;
  scene.render.noise_sigma_dn = 0;
  scene.render.blur_sigma_px = 0;
  scene.distractors.blobs.push_back({Blob::Shape::Ellipse, {200.3, 150.6}, {40, 8}, 30, 100});
  scene.distractors.blobs.push_back({Blob::Shape::Rectangle, {450.5, 300.5}, {20, 10}, 0, 120});
  scene.distractors.lamp = Lamp{{560, 80}, 20, 250, 10};
  RenderedFrame frame = IrRenderer(scene, ideal_camera()).render(0);

  BlobMoments ellipse = moments(frame.image, {200.3, 150.6}, 30, 8);
  EXPECT_LT((ellipse.centroid - Eigen::Vector2d(200.3, 150.6)).norm(), 0.05);
  EXPECT_NEAR(ellipse.sum / 100, std::numbers::pi * 20 * 4, 0.02 * std::numbers::pi * 80);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes(ellipse.covariance);
  Eigen::Vector2d long_axis = axes.eigenvectors().col(1);
  EXPECT_NEAR(std::abs(std::atan(long_axis.y() / long_axis.x())), 30 * kDeg, 0.01);
  // Semi-axes from the variances (a^2 / 4, plus 1/12 for whole pixels).
  EXPECT_NEAR(2 * std::sqrt(axes.eigenvalues()(1) - 1.0 / 12), 20, 0.2);
  EXPECT_NEAR(2 * std::sqrt(axes.eigenvalues()(0) - 1.0 / 12), 4, 0.2);

  // The rectangle's edges fall on pixel edges: 20 x 10 pixels 120 DN above the background.
  cv::Mat rectangle = frame.image(cv::Rect(441, 296, 20, 10));
  EXPECT_EQ(cv::countNonZero(rectangle != 128), 0);
  EXPECT_EQ(cv::countNonZero(frame.image(cv::Rect(430, 285, 40, 30)) != 8), 200);

  // The lamp: saturated inside, a glow that fades outside.
  EXPECT_EQ(frame.image.at<uint8_t>(80, 560), 255);
  EXPECT_EQ(frame.image.at<uint8_t>(80, 560 + 19), 255);
  int glow_near = frame.image.at<uint8_t>(80, 560 + 25);
  int glow_far = frame.image.at<uint8_t>(80, 560 + 35);
  EXPECT_NEAR(glow_near, 8 + 250 * std::exp(-0.5 * 0.25), 3);
  EXPECT_NEAR(glow_far, 8 + 250 * std::exp(-0.5 * 2.25), 3);
}

TEST(IrRenderer, ExposureScalesAndSaturatesMarkers) {
  RenderOptions options = clean_options();
  options.exposure = 1.0;
  Scene bright = board_scene(StaticTrajectory{{0, 0, 1.0}, {0, 0, 0}}, options);
  options.exposure = 0.3;
  Scene dim = board_scene(StaticTrajectory{{0, 0, 1.0}, {0, 0, 0}}, options);
  RenderedFrame a = IrRenderer(bright, ideal_camera()).render(0);
  RenderedFrame b = IrRenderer(dim, ideal_camera()).render(0);
  for (const MarkerTruth& marker : a.objects[0].markers) {
    cv::Point centre(static_cast<int>(std::lround(marker.pixel.x())),
                     static_cast<int>(std::lround(marker.pixel.y())));
    EXPECT_EQ(a.image.at<uint8_t>(centre), 255);  // 8 + 255: saturated
    EXPECT_NEAR(b.image.at<uint8_t>(centre), 8 + 0.3 * 255, 1.0);
  }
}

// A scene file's render options are checked as it loads; options built in code get the checks
// from the renderer, which names the field.
TEST(RenderOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(RenderOptions{}.problem(), std::nullopt);
  EXPECT_EQ(RenderOptions{.marker_diameter_m = 0}.problem(), "marker_diameter_m: 0 is not above 0");
  EXPECT_EQ(RenderOptions{.noise_sigma_dn = -2}.problem(), "noise_sigma_dn: -2 is below 0");
  EXPECT_EQ(RenderOptions{.supersampling = 0}.problem(), "supersampling: 0 is below 1");
  EXPECT_EQ(RenderOptions{.motion_blur_steps = -1}.problem(), "motion_blur_steps: -1 is below 0");
  try {
    IrRenderer renderer(board_scene(StaticTrajectory{}, {.exposure = -1}), ideal_camera());
    ADD_FAILURE() << "negative exposure accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "RenderOptions::exposure: -1 is below 0");
  }
}

}  // namespace
}  // namespace mocap::synthetic
