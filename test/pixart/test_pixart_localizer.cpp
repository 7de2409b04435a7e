// The PixArt localizer: robots placed on the seed's rig (config/pixart/rig.yaml), their lit
// LEDs projected through the rig's camera models and rounded to whole pixels as the sensor
// reports them (at most four per camera), then localized back. The library is driven with
// explicit sample times; the plugin runs in-process through ComponentHost.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/calibration/eucm_camera.hpp>
#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <mocap_msgs/msg/robot_pose_array.hpp>

#include "host/plugin_loader.hpp"
#include "pixart/pixart_localizer/camera_views.hpp"
#include "pixart/pixart_localizer/led_plane_points.hpp"
#include "pixart/pixart_localizer/pixart_localizer.hpp"
#include "pixart/pixart_localizer/planar_fit.hpp"
#include "pixart/pixart_localizer/point_merging.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"
#include "test/test_support.hpp"

namespace mocap::pixart::localization {
namespace {

constexpr int64_t kStart = 1'700'000'000'000'000'000;  // a realistic stamp, ns
constexpr int64_t kSamplePeriod = 3'703'704;           // 270 Hz
constexpr int64_t kMillisecond = 1'000'000;
constexpr double kDegree = M_PI / 180.0;
// What the tests demand of one reading from whole-pixel points (a pixel is ~1.5 mm on the
// LED plane): the measured errors are well below (see AccuracyOverTheWholeFloor).
constexpr double kPositionToleranceM = 0.003;
constexpr double kHeadingToleranceRad = 1.0 * kDegree;
// Two LEDs are 6 to 10 cm apart: half a pixel of rounding at each end turns their direction
// by up to 1.4 degrees.
constexpr double kTwoLedHeadingToleranceRad = 1.5 * kDegree;

const Rig& seed_rig() {
  static const Rig rig = load_rig((test::source_dir() / "config/pixart/rig.yaml").string());
  return rig;
}

const RobotModel& robot_model(const Rig& rig, const std::string& name) {
  for (const RobotModel& robot : rig.robots) {
    if (robot.name == name) return robot;
  }
  throw std::runtime_error("no robot " + name + " in " + rig.source);
}

// Which LEDs a robot shows; the seed's layout: a front and a rear end, blinking, and the
// steady middle one.
struct Lights {
  bool front = true;
  bool steady = true;
  bool rear = true;
};

struct PlacedRobot {
  std::string name;
  PlanarPose pose;
  Lights lights = {};
};

// The lit LEDs of `robots`, in the world frame, on the LED plane.
std::vector<Eigen::Vector3d> lit_leds(const Rig& rig, const std::vector<PlacedRobot>& robots) {
  std::vector<Eigen::Vector3d> leds;
  for (const PlacedRobot& placed : robots) {
    const RobotModel& model = robot_model(rig, placed.name);
    double front_x = -1e9, rear_x = 1e9;
    for (const Led& led : model.leds) {
      front_x = std::max(front_x, led.position.x());
      rear_x = std::min(rear_x, led.position.x());
    }
    for (const Led& led : model.leds) {
      bool on = led.off_s <= 0                ? placed.lights.steady
                : led.position.x() == front_x ? placed.lights.front
                : led.position.x() == rear_x  ? placed.lights.rear
                                              : true;
      if (!on) continue;
      Eigen::Vector2d world = placed.pose.to_world(led.position);
      leds.emplace_back(world.x(), world.y(), rig.led_plane_height_m);
    }
  }
  return leds;
}

// What a PixArt sensor reports of `leds`: the whole pixels of those in its image, four at most.
std::vector<Eigen::Vector2d> sensor_pixels(const RigCamera& camera,
                                           const std::vector<Eigen::Vector3d>& leds) {
  std::vector<Eigen::Vector2d> pixels;
  for (const Eigen::Vector3d& led : leds) {
    auto pixel = camera.model->project(camera.world_from_camera.inverse() * led);
    if (!pixel) continue;
    Eigen::Vector2d rounded(std::round(pixel->x()), std::round(pixel->y()));
    if (camera.model->in_image(rounded) && pixels.size() < 4) pixels.push_back(rounded);
  }
  return pixels;
}

// Cameras that see `led` (to check that a scene is what a test says it is).
int cameras_seeing(const Rig& rig, const Eigen::Vector3d& led) {
  int count = 0;
  for (const RigCamera& camera : rig.cameras) count += sensor_pixels(camera, {led}).empty() ? 0 : 1;
  return count;
}

// One sample of every camera at about `stamp_ns`: cameras are sampled together, their
// samples arrive one after another (20 µs apart here). The cameras are where the localizer's
// rig has them, or where `mounted` has them.
void observe(RobotLocalizer& localizer, const std::vector<PlacedRobot>& robots, int64_t stamp_ns,
             const Rig* mounted = nullptr) {
  const Rig& cameras = mounted ? *mounted : localizer.rig();
  std::vector<Eigen::Vector3d> leds = lit_leds(cameras, robots);
  int64_t offset = 0;
  for (const RigCamera& camera : cameras.cameras) {
    ASSERT_EQ(localizer.add_sample(camera.name, stamp_ns + offset, sensor_pixels(camera, leds)),
              RobotLocalizer::SampleStatus::Used);
    offset += 20'000;
  }
}

std::optional<TrackedRobot> find_robot(const std::vector<TrackedRobot>& robots,
                                       const std::string& name) {
  for (const TrackedRobot& robot : robots) {
    if (robot.name == name) return robot;
  }
  return std::nullopt;
}

double heading_error(double measured, double truth) {
  return std::abs(wrap_angle(measured - truth));
}

// The robot is tracked at `truth` (position within kPositionToleranceM, heading within
// kHeadingToleranceRad).
void expect_pose(const std::vector<TrackedRobot>& robots, const std::string& name,
                 const PlanarPose& truth, std::optional<PoseEvidence> evidence = std::nullopt,
                 double heading_tolerance_rad = kHeadingToleranceRad) {
  auto robot = find_robot(robots, name);
  ASSERT_TRUE(robot) << name << " is not tracked";
  EXPECT_LT((robot->pose.position() - truth.position()).norm(), kPositionToleranceM)
      << name << " at " << robot->pose.x << ", " << robot->pose.y << "; truth " << truth.x << ", "
      << truth.y;
  EXPECT_LT(heading_error(robot->pose.theta, truth.theta), heading_tolerance_rad)
      << name << " heading " << robot->pose.theta / kDegree << " deg; truth "
      << truth.theta / kDegree;
  if (evidence) {
    EXPECT_EQ(robot->evidence, *evidence) << name << " read from " << to_string(robot->evidence)
                                          << ", expected from " << to_string(*evidence);
  }
}

// ---------------------------------------------------------------------------------------------
// Building blocks.

TEST(PlanarFit, RecoversARigidMotionAndNeverReflects) {
  std::vector<Eigen::Vector2d> layout{{0.12, 0}, {0, 0}, {-0.06, 0}, {0, 0.05}};
  PlanarPose truth{0.3, -0.7, 2.5};
  std::vector<Eigen::Vector2d> observed;
  for (const auto& p : layout) observed.push_back(truth.to_world(p));
  PlanarFit fit = fit_planar_pose(layout, observed);
  EXPECT_NEAR(fit.pose.x, 0.3, 1e-12);
  EXPECT_NEAR(fit.pose.y, -0.7, 1e-12);
  EXPECT_NEAR(fit.pose.theta, 2.5, 1e-12);
  EXPECT_LT(fit.max_residual_m, 1e-12);

  // The mirror image is fitted as well as a rotation can, leaving a residual.
  std::vector<Eigen::Vector2d> mirrored;
  for (const auto& p : layout) mirrored.emplace_back(p.x(), -p.y());
  EXPECT_GT(fit_planar_pose(layout, mirrored).max_residual_m, 0.02);

  // Two points: their directions aligned, their midpoints too.
  PlanarFit pair = fit_planar_pose({{0, 0}, {0.1, 0}}, {{1, 1}, {1, 1.1}});
  EXPECT_NEAR(pair.pose.theta, M_PI / 2, 1e-12);
  EXPECT_NEAR(pair.pose.x, 1, 1e-12);
  EXPECT_NEAR(pair.pose.y, 1, 1e-12);

  EXPECT_THROW(fit_planar_pose({{0, 0}}, {{0, 0}}), std::invalid_argument);
  EXPECT_THROW(fit_planar_pose({{0, 0}, {0, 0}}, {{0, 0}, {1, 0}}), std::invalid_argument);
  EXPECT_NEAR(wrap_angle(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(wrap_angle(-M_PI), M_PI, 1e-12);
}

TEST(PointMerging, MergesOneLedSeenByTwoCamerasAtAboutTheSameTime) {
  std::vector<CameraView> views(3);
  views[0] = {true, kStart, {{0, 0}, {0.006, 0}}};  // two LEDs 6 mm apart, one camera
  views[1] = {true, kStart + 1 * kMillisecond, {{0.004, 0.003}}};
  views[2] = {true, kStart + 2 * kMillisecond, {{1, 1}}};
  MergedPoints merged = merge_views(views);
  EXPECT_EQ(merged.stamp_ns, kStart + 2 * kMillisecond);
  EXPECT_EQ(merged.cameras, 3);
  ASSERT_EQ(merged.points.size(), 3u);  // one camera's two points stay two
  int merged_pairs = 0;
  for (const MergedPoint& point : merged.points) {
    if (point.views == 2) {
      ++merged_pairs;
      // The nearer of camera 0's points joined camera 1's, averaged.
      EXPECT_NEAR(point.position.x(), 0.005, 1e-12);
      EXPECT_NEAR(point.position.y(), 0.0015, 1e-12);
      EXPECT_EQ(point.cameras, CameraSet{0b011});
    } else {
      EXPECT_TRUE(point.cameras == CameraSet{0b001} || point.cameras == CameraSet{0b100});
    }
  }
  EXPECT_EQ(merged_pairs, 1);
}

TEST(PointMerging, KeepsApartWhatIsFarInSpaceOrTimeAndLeavesStaleCamerasOut) {
  MergeOptions options;  // 20 mm, 5 ms, stale after 20 ms
  std::vector<CameraView> views(4);
  views[0] = {true, kStart, {{0, 0}}};
  views[1] = {true, kStart, {{0.015, 0}}};  // 15 mm from camera 0's
  views[2] = {true, kStart, {{0.030, 0}}};  // 15 mm from camera 1's, 30 from camera 0's
  MergedPoints chain = merge_views(views, options);
  // Complete linkage: 0 and 2 are too far apart to be one LED, so the chain is not one point.
  EXPECT_EQ(chain.points.size(), 2u);

  views = std::vector<CameraView>(3);
  views[0] = {true, kStart, {{0, 0}}};
  views[1] = {true, kStart + 10 * kMillisecond, {{0.001, 0}}};  // outside the 5 ms window
  EXPECT_EQ(merge_views(views, options).points.size(), 2u);

  views[1] = {true, kStart + 30 * kMillisecond, {{0.5, 0}}};  // camera 0 is now stale
  MergedPoints fresh = merge_views(views, options);
  EXPECT_EQ(fresh.cameras, 1);
  ASSERT_EQ(fresh.points.size(), 1u);
  EXPECT_EQ(fresh.points[0].position.x(), 0.5);

  EXPECT_TRUE(merge_views(std::vector<CameraView>(2)).points.empty());  // nothing received
}

TEST(LatestCameraViews, KeepsTheNewestSampleOfEachCamera) {
  LatestCameraViews views(2);
  EXPECT_FALSE(views.newest_stamp_ns());
  EXPECT_TRUE(views.update(0, kStart + 10, {{1, 1}}));
  EXPECT_FALSE(views.update(0, kStart, {{2, 2}}));  // older: dropped
  EXPECT_EQ(views.views()[0].points[0].x(), 1);
  EXPECT_TRUE(views.update(1, kStart + 5, {}));
  EXPECT_EQ(views.newest_stamp_ns(), kStart + 10);
  EXPECT_THROW(views.update(2, kStart, {}), std::out_of_range);
}

TEST(RobotRecognizer, SetsAsideLayoutsItCannotTellApartAndNamesTheReason) {
  std::vector<RobotModel> robots{
      robot_model(seed_rig(), "robot_a"),
      {"board", {Led{{0, 0}}, Led{{0.1, 0}}, Led{{0, 0.1}}, Led{{0.1, 0.1}}}},
      {"symmetric", {Led{{0.1, 0}, 0.2, 0.2}, Led{{0, 0}}, Led{{-0.1, 0}, 0.2, 0.2}}},
      {"two_steady", {Led{{0.1, 0}}, Led{{0, 0}}, Led{{-0.05, 0}, 0.2, 0.2}}}};
  RobotRecognizer recognizer(robots);
  EXPECT_TRUE(recognizer.supported(0));
  ASSERT_EQ(recognizer.unsupported().size(), 3u);
  EXPECT_NE(recognizer.unsupported()[0].find("robot 'board': has 4 LEDs"), std::string::npos)
      << recognizer.unsupported()[0];
  EXPECT_NE(recognizer.unsupported()[1].find("'symmetric'"), std::string::npos);
  EXPECT_NE(recognizer.unsupported()[1].find("could not be told apart"), std::string::npos);
  EXPECT_NE(recognizer.unsupported()[2].find("2 always-on LEDs"), std::string::npos);
  EXPECT_NEAR(recognizer.smallest_led_distance_m(), 0.06, 1e-12);
}

TEST(RobotLocalizer, RejectsRigsAndOptionsItCannotWorkWith) {
  Rig no_robots = seed_rig();
  no_robots.robots.clear();
  try {
    RobotLocalizer localizer(no_robots);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("it has none"), std::string::npos) << e.what();
  }
  LocalizerOptions options;
  options.merging.merge_distance_m = 0.07;  // over robot_a's 0.06 m rear spacing
  try {
    RobotLocalizer localizer(seed_rig(), options);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("merge_distance_m (0.07 m) must be below"),
              std::string::npos)
        << e.what();
  }
  options = {};
  options.tracking.lost_after_s = 0;
  EXPECT_THROW(RobotLocalizer(seed_rig(), options), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Localization on the seed's rig.

// The nominal camera (41 degrees across 1024 x 768 square pixels) 2.05 m above the LED plane
// sees a 1.533 m x 1.150 m rectangle centred under it; camera3 is turned 90 degrees from camera2.
TEST(LedPlaneFootprint, IsTheRectangleUnderTheCameraTurnedWithIt) {
  const Rig& rig = seed_rig();
  std::map<std::string, std::array<Eigen::Vector2d, 4>> footprints;
  for (const RigCamera& camera : rig.cameras) {
    auto corners = led_plane_footprint(camera, rig.led_plane_height_m);
    ASSERT_TRUE(corners.has_value()) << camera.name;
    footprints[camera.name] = *corners;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& c : *corners) centre += c / 4;
    EXPECT_LT((centre - camera.world_from_camera.translation().head<2>()).norm(), 0.005)
        << camera.name;
    const double across = 2 * 2.05 * std::tan(20.5 * kDegree);
    EXPECT_NEAR(((*corners)[1] - (*corners)[0]).norm(), across, 0.01 * across) << camera.name;
    EXPECT_NEAR(((*corners)[2] - (*corners)[1]).norm(), across * 768 / 1024, 0.01 * across)
        << camera.name;
  }
  const Eigen::Vector2d x2 = (footprints["camera2"][1] - footprints["camera2"][0]).normalized();
  const Eigen::Vector2d x3 = (footprints["camera3"][1] - footprints["camera3"][0]).normalized();
  EXPECT_NEAR(x2.dot(x3), 0, 1e-6);
  EXPECT_NEAR(x2.x() * x3.y() - x2.y() * x3.x(), 1, 1e-6) << "counter-clockwise";
}

TEST(PixartLocalization, RobotUnderOneCameraWithinMillimetres) {
  RobotLocalizer localizer(seed_rig());
  PlanarPose truth{-0.8, -0.6, 30 * kDegree};
  for (const auto& led : lit_leds(seed_rig(), {{"robot_a", truth}})) {
    ASSERT_EQ(cameras_seeing(seed_rig(), led), 1);  // camera2 alone
  }
  observe(localizer, {{"robot_a", truth}}, kStart);
  ASSERT_EQ(localizer.last_points().points.size(), 3u);
  std::vector<TrackedRobot> robots = localizer.tracked_robots(kStart);
  ASSERT_EQ(robots.size(), 1u);
  expect_pose(robots, "robot_a", truth, PoseEvidence::AllLeds);
  EXPECT_EQ(robots[0].last_seen_ns, kStart + 3 * 20'000);  // the newest sample used
}

TEST(PixartLocalization, RobotInTheOverlapIsMergedNotDuplicated) {
  RobotLocalizer localizer(seed_rig());
  // Between camera2 and camera3, heading along world y.
  PlanarPose truth{0.1, -0.6, 90 * kDegree};
  for (const auto& led : lit_leds(seed_rig(), {{"robot_b", truth}})) {
    ASSERT_EQ(cameras_seeing(seed_rig(), led), 2);
  }
  observe(localizer, {{"robot_b", truth}}, kStart);
  ASSERT_EQ(localizer.last_points().points.size(), 3u);
  for (const MergedPoint& point : localizer.last_points().points) EXPECT_EQ(point.views, 2);
  std::vector<TrackedRobot> robots = localizer.tracked_robots(kStart);
  ASSERT_EQ(robots.size(), 1u);
  expect_pose(robots, "robot_b", truth, PoseEvidence::AllLeds);

  // In the middle of the square all four cameras see the steady LED: still one point.
  PlanarPose centre{0.0, -0.02, 90 * kDegree};
  ASSERT_EQ(cameras_seeing(seed_rig(), {0.0, -0.02, seed_rig().led_plane_height_m}), 4);
  observe(localizer, {{"robot_b", centre}}, kStart + kSamplePeriod);
  ASSERT_EQ(localizer.last_points().points.size(), 3u);
  int most_views = 0;
  for (const MergedPoint& point : localizer.last_points().points) {
    most_views = std::max(most_views, point.views);
  }
  EXPECT_EQ(most_views, 4);
  expect_pose(localizer.tracked_robots(kStart + kSamplePeriod), "robot_b", centre,
              PoseEvidence::AllLeds);
}

TEST(PixartLocalization, BothRobotsAtOnce) {
  RobotLocalizer localizer(seed_rig());
  // Under two different cameras.
  PlanarPose a{-0.8, -0.6, 30 * kDegree}, b{0.8, 0.7, -120 * kDegree};
  observe(localizer, {{"robot_a", a}, {"robot_b", b}}, kStart);
  std::vector<TrackedRobot> robots = localizer.tracked_robots(kStart);
  ASSERT_EQ(robots.size(), 2u);
  expect_pose(robots, "robot_a", a, PoseEvidence::AllLeds);
  expect_pose(robots, "robot_b", b, PoseEvidence::AllLeds);

  // Side by side in front of one camera (which reports four points at most): robot_b shows
  // its steady LED only, 0.10 m from robot_a's front LED, which is robot_b's own front
  // spacing. The three-LED reading of robot_a must keep its front LED from being paired
  // with robot_b's steady LED.
  a = {-0.8, -0.6, 0};
  Eigen::Vector2d a_front = a.to_world({0.12, 0});
  b = {a_front.x(), a_front.y() + 0.10, 45 * kDegree};
  observe(localizer, {{"robot_b", b}}, kStart + kSamplePeriod);  // robot_b alone first
  expect_pose(localizer.tracked_robots(kStart + kSamplePeriod), "robot_b", b);
  int64_t t = kStart + 2 * kSamplePeriod;
  observe(localizer, {{"robot_a", a}, {"robot_b", b, {false, true, false}}}, t);
  EXPECT_EQ(localizer.last_points().points.size(), 4u);
  robots = localizer.tracked_robots(t);
  ASSERT_EQ(robots.size(), 2u);
  expect_pose(robots, "robot_a", a, PoseEvidence::AllLeds);
  expect_pose(robots, "robot_b", b, PoseEvidence::OneLed);
  for (const TrackedRobot& robot : robots) EXPECT_EQ(robot.last_seen_ns, t + 3 * 20'000);
}

TEST(PixartLocalization, EachEndOffInTurnTwoLedsGiveTheHeading) {
  RobotLocalizer localizer(seed_rig());
  int64_t t = kStart;
  for (const char* name : {"robot_a", "robot_b"}) {
    SCOPED_TRACE(name);
    PlanarPose pose{-0.7, -0.5, 10 * kDegree};
    observe(localizer, {{name, pose}}, t);
    expect_pose(localizer.tracked_robots(t), name, pose, PoseEvidence::AllLeds);
    // Turning and driving on with one end dark, then the other: every spacing of the seed's
    // two robots is unique, so two LEDs name the robot and give its heading.
    for (Lights lights : {Lights{false, true, true}, Lights{true, true, false}}) {
      for (int step = 0; step < 20; ++step) {
        t += kSamplePeriod;
        pose.theta += 2 * kDegree;
        pose.x += 0.002;
        observe(localizer, {{name, pose, lights}}, t);
      }
      expect_pose(localizer.tracked_robots(t), name, pose, PoseEvidence::TwoLeds,
                  kTwoLedHeadingToleranceRad);
    }
    // Gone long enough for the next robot's turn.
    t += 2'000 * kMillisecond;
    EXPECT_TRUE(localizer.tracked_robots(t).empty());
  }
  EXPECT_EQ(localizer.stats().ambiguous_pairs, 0u);
}

TEST(PixartLocalization, AnAmbiguousPairMovesTheRobotAndKeepsItsHeading) {
  // robot_c's rear spacing (0.12 m) equals robot_a's front spacing: two LEDs 0.12 m apart
  // could be either robot, and their direction cannot be trusted.
  Rig rig = parse_rig(R"(
led_plane_height_m: 0.45
cameras:
  - {name: camera2, camera_id: 2, position: [-0.5, -0.5, 2.5], yaw_deg: 0}
robots:
  - name: robot_a
    leds:
      - {position: [0.12, 0.0], on_s: 0.2, off_s: 0.2}
      - {position: [0.0, 0.0]}
      - {position: [-0.06, 0.0], on_s: 0.3, off_s: 0.1}
  - name: robot_c
    leds:
      - {position: [0.09, 0.0], on_s: 0.2, off_s: 0.2}
      - {position: [0.0, 0.0]}
      - {position: [-0.12, 0.0], on_s: 0.3, off_s: 0.1}
)",
                      "ambiguous.yaml");
  RobotLocalizer localizer(rig);
  PlanarPose start{-0.6, -0.5, 20 * kDegree};
  observe(localizer, {{"robot_a", start}}, kStart);
  expect_pose(localizer.tracked_robots(kStart), "robot_a", start, PoseEvidence::AllLeds);

  // Rear dark: front and steady LED, 0.12 m apart. Moved 1 cm, turned 10 degrees.
  PlanarPose moved{-0.59, -0.5, 30 * kDegree};
  observe(localizer, {{"robot_a", moved, {true, true, false}}}, kStart + kSamplePeriod);
  EXPECT_GE(localizer.stats().ambiguous_pairs, 1u);
  expect_pose(localizer.tracked_robots(kStart + kSamplePeriod), "robot_a",
              {moved.x, moved.y, start.theta}, PoseEvidence::OneLed);

  // Front dark: rear and steady LED, 0.06 m apart, unique: the heading follows again.
  observe(localizer, {{"robot_a", moved, {false, true, true}}}, kStart + 2 * kSamplePeriod);
  expect_pose(localizer.tracked_robots(kStart + 2 * kSamplePeriod), "robot_a", moved,
              PoseEvidence::TwoLeds, kTwoLedHeadingToleranceRad);
}

TEST(PixartLocalization, OneLedAloneMovesTheTrackedRobotAndKeepsItsHeading) {
  RobotLocalizer localizer(seed_rig());
  PlanarPose a{-0.8, -0.6, 30 * kDegree}, b{0.8, 0.7, -120 * kDegree};
  observe(localizer, {{"robot_a", a}, {"robot_b", b}}, kStart);
  ASSERT_EQ(localizer.tracked_robots(kStart).size(), 2u);

  // Both ends of both robots dark; each moves 3 cm and turns (which the middle LED cannot
  // show).
  const Lights dark_ends{false, true, false};
  PlanarPose a_moved{a.x + 0.03, a.y, a.theta + 0.5}, b_moved{b.x, b.y - 0.03, b.theta - 0.5};
  int64_t t = kStart + kSamplePeriod;
  observe(localizer, {{"robot_a", a_moved, dark_ends}, {"robot_b", b_moved, dark_ends}}, t);
  std::vector<TrackedRobot> robots = localizer.tracked_robots(t);
  ASSERT_EQ(robots.size(), 2u);
  expect_pose(robots, "robot_a", {a_moved.x, a_moved.y, a.theta}, PoseEvidence::OneLed);
  expect_pose(robots, "robot_b", {b_moved.x, b_moved.y, b.theta}, PoseEvidence::OneLed);

  // The sensor reports 4 points: with another robot's LEDs in view the steady LED may be the
  // one dropped while a blinking end shows. The end LED moves the robot, not its middle.
  t += kSamplePeriod;
  PlanarPose a_on{a_moved.x - 0.02, a_moved.y, a.theta};
  observe(localizer, {{"robot_a", a_on, Lights{true, false, false}}}, t);
  expect_pose(localizer.tracked_robots(t), "robot_a", a_on, PoseEvidence::OneLed);

  // Beyond the 0.1 m gate of every LED of a robot, a lone LED is nobody's.
  t += kSamplePeriod;
  observe(localizer, {{"robot_a", {a_on.x + 0.35, a_on.y, 0}, dark_ends}}, t);
  EXPECT_EQ(localizer.last_recognition().unexplained_points.size(), 1u);
  expect_pose(localizer.tracked_robots(t), "robot_a", a_on);
}

TEST(PixartLocalization, RobotsNeverSeenWholeAreNotGuessed) {
  RobotLocalizer localizer(seed_rig());
  // An untracked robot's steady LED alone, or with one end, says nothing of which robot it is
  // or which point is its middle.
  observe(localizer, {{"robot_a", {-0.8, -0.6, 0}, {false, true, false}}}, kStart);
  observe(localizer, {{"robot_b", {0.8, 0.7, 0}, {true, true, false}}}, kStart + kSamplePeriod);
  EXPECT_TRUE(localizer.tracked_robots(kStart + kSamplePeriod).empty());
}

TEST(PixartLocalization, RobotStandingStillKeepsBeingPublished) {
  // Both robots parked for 3 s, their ends blinking as the rig says; a 50 Hz publisher asks
  // for the tracked robots between samples.
  RobotLocalizer localizer(seed_rig());
  PlanarPose a{-0.3, -0.4, 135 * kDegree}, b{0.4, 0.3, -60 * kDegree};
  const RobotModel& model_a = robot_model(seed_rig(), "robot_a");
  const RobotModel& model_b = robot_model(seed_rig(), "robot_b");
  auto lights = [](const RobotModel& model, double time_s) {
    return Lights{model.leds[0].is_on(time_s), true, model.leds[2].is_on(time_s)};
  };
  int64_t next_publish = kStart + 20 * kMillisecond;
  int publications = 0;
  for (int64_t t = kStart; t < kStart + 3'000 * kMillisecond; t += kSamplePeriod) {
    double time_s = static_cast<double>(t - kStart) * 1e-9;
    observe(localizer,
            {{"robot_a", a, lights(model_a, time_s)}, {"robot_b", b, lights(model_b, time_s)}}, t);
    if (t >= next_publish) {
      std::vector<TrackedRobot> robots = localizer.tracked_robots(t);
      ASSERT_EQ(robots.size(), 2u) << "at " << time_s << " s";
      expect_pose(robots, "robot_a", a);
      expect_pose(robots, "robot_b", b);
      ++publications;
      next_publish += 20 * kMillisecond;
    }
  }
  EXPECT_GE(publications, 140);
  // All three kinds of reading happened, and the robots were found once, never lost.
  const LocalizerStats& stats = localizer.stats();
  EXPECT_GT(stats.readings_all_leds, 0u);
  EXPECT_GT(stats.readings_two_leds, 0u);
  EXPECT_GT(stats.readings_one_led, 0u);
  EXPECT_EQ(localizer.take_events().size(), 2u);
}

TEST(PixartLocalization, RobotLeavingAllViewsIsDroppedAfterLostAfter) {
  LocalizerOptions options;
  options.tracking.lost_after_s = 1.0;
  RobotLocalizer localizer(seed_rig(), options);
  PlanarPose pose{-0.8, -0.6, 0};
  observe(localizer, {{"robot_a", pose}}, kStart);
  std::vector<TrackEvent> events = localizer.take_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, TrackEvent::Kind::Found);

  // Off the floor: the cameras keep sampling, seeing nothing.
  int64_t last_seen = localizer.tracked_robots(kStart)[0].last_seen_ns;
  int64_t t = kStart;
  while (t < kStart + 900 * kMillisecond) {
    t += kSamplePeriod;
    observe(localizer, {}, t);
  }
  EXPECT_EQ(localizer.tracked_robots(last_seen + 1'000 * kMillisecond).size(), 1u);
  EXPECT_TRUE(localizer.tracked_robots(last_seen + 1'001 * kMillisecond).empty());
  EXPECT_TRUE(localizer.tracked_robots(last_seen + 1'500 * kMillisecond).empty());
  events = localizer.take_events();
  ASSERT_EQ(events.size(), 1u);  // once
  EXPECT_EQ(events[0].kind, TrackEvent::Kind::Lost);
  EXPECT_EQ(events[0].robot, 0u);

  // Its steady LED back at the same place does not revive a lost robot; three LEDs do.
  t = last_seen + 1'600 * kMillisecond;
  observe(localizer, {{"robot_a", pose, {false, true, false}}}, t);
  EXPECT_TRUE(localizer.tracked_robots(t).empty());
  t += kSamplePeriod;
  observe(localizer, {{"robot_a", pose}}, t);
  expect_pose(localizer.tracked_robots(t), "robot_a", pose, PoseEvidence::AllLeds);
  events = localizer.take_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, TrackEvent::Kind::Found);
}

TEST(PixartLocalization, StaleAndUnsynchronisedCameras) {
  RobotLocalizer localizer(seed_rig());
  PlanarPose pose{0.1, -0.6, 90 * kDegree};  // seen by camera2 and camera3
  const Rig& rig = seed_rig();
  auto pixels_of = [&](const std::string& camera) {
    for (const RigCamera& c : rig.cameras) {
      if (c.name == camera) return sensor_pixels(c, lit_leds(rig, {{"robot_a", pose}}));
    }
    throw std::runtime_error("no camera " + camera);
  };
  // camera3 samples 10 ms after camera2 (a lost sample): too far apart to merge, so six
  // points; still one robot.
  localizer.add_sample("camera2", kStart, pixels_of("camera2"));
  localizer.add_sample("camera3", kStart + 10 * kMillisecond, pixels_of("camera3"));
  EXPECT_EQ(localizer.last_points().points.size(), 6u);
  std::vector<TrackedRobot> robots = localizer.tracked_robots(kStart + 10 * kMillisecond);
  ASSERT_EQ(robots.size(), 1u);
  expect_pose(robots, "robot_a", pose);

  // camera2 falls silent; 30 ms later its last view no longer counts.
  localizer.add_sample("camera3", kStart + 30 * kMillisecond, {});
  EXPECT_TRUE(localizer.last_points().points.empty());
  EXPECT_EQ(localizer.last_points().cameras, 1);
}

TEST(PixartLocalization, BadInputIsIgnoredAndCounted) {
  RobotLocalizer localizer(seed_rig());
  EXPECT_EQ(localizer.add_sample("camera9", kStart, {{500, 400}}),
            RobotLocalizer::SampleStatus::UnknownCamera);
  PlanarPose pose{-0.8, -0.6, 0};
  const RigCamera& camera2 = seed_rig().cameras[0];
  ASSERT_EQ(camera2.name, "camera2");
  std::vector<Eigen::Vector2d> pixels =
      sensor_pixels(camera2, lit_leds(seed_rig(), {{"robot_a", pose}}));
  pixels.emplace_back(std::numeric_limits<double>::quiet_NaN(), 10);
  EXPECT_EQ(localizer.add_sample("camera2", kStart, pixels), RobotLocalizer::SampleStatus::Used);
  expect_pose(localizer.tracked_robots(kStart), "robot_a", pose);
  EXPECT_EQ(localizer.add_sample("camera2", kStart - 1, {}),
            RobotLocalizer::SampleStatus::OutOfOrder);
  const LocalizerStats& stats = localizer.stats();
  EXPECT_EQ(stats.unknown_camera_samples, 1u);
  EXPECT_EQ(stats.non_finite_pixels, 1u);
  EXPECT_EQ(stats.out_of_order_samples, 1u);
  EXPECT_EQ(stats.samples, 1u);
}

// Whole-pixel error over the floor: a grid of poses, headings all round, each robot read
// from its three LEDs afresh, then (tracked) from two with either end dark. Prints the figures
// the closing note quotes.
TEST(PixartLocalization, AccuracyOverTheWholeFloor) {
  const Rig& rig = seed_rig();
  struct Errors {
    std::vector<double> position_mm, heading_deg;
    void add(const TrackedRobot& robot, const PlanarPose& truth) {
      position_mm.push_back((robot.pose.position() - truth.position()).norm() * 1000);
      heading_deg.push_back(heading_error(robot.pose.theta, truth.theta) / kDegree);
    }
  };
  Errors three_leds, three_leds_in_overlaps, two_leds;
  int64_t t = kStart;
  int poses = 0;
  for (double x = -1.0; x <= 1.0 + 1e-9; x += 0.1) {
    for (double y = -0.9; y <= 0.9 + 1e-9; y += 0.1) {
      for (const char* name : {"robot_a", "robot_b"}) {
        PlanarPose truth{x, y,
                         std::fmod(37.0 * (x * 10 + 11) + 23.0 * (y * 10 + 9), 360) * kDegree};
        bool in_view = true, overlap = true;
        for (const auto& led : lit_leds(rig, {{name, truth}})) {
          int cameras = cameras_seeing(rig, led);
          in_view = in_view && cameras > 0;
          overlap = overlap && cameras > 1;
        }
        if (!in_view) continue;
        ++poses;
        RobotLocalizer localizer(rig);  // no history: every pose read afresh
        t += kSamplePeriod;
        observe(localizer, {{name, truth}}, t);
        auto robot = find_robot(localizer.tracked_robots(t), name);
        ASSERT_TRUE(robot) << name << " not found at " << x << ", " << y;
        ASSERT_EQ(robot->evidence, PoseEvidence::AllLeds);
        three_leds.add(*robot, truth);
        if (overlap) three_leds_in_overlaps.add(*robot, truth);
        for (Lights lights : {Lights{false, true, true}, Lights{true, true, false}}) {
          t += kSamplePeriod;
          observe(localizer, {{name, truth, lights}}, t);
          robot = find_robot(localizer.tracked_robots(t), name);
          ASSERT_TRUE(robot);
          ASSERT_EQ(robot->evidence, PoseEvidence::TwoLeds);
          two_leds.add(*robot, truth);
        }
      }
    }
  }
  ASSERT_GT(poses, 400);
  ASSERT_GT(three_leds_in_overlaps.position_mm.size(), 40u);
  // Median, 95th percentile, maximum.
  auto summary = [](std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return std::array<double, 3>{values[values.size() / 2], values[values.size() * 95 / 100],
                                 values.back()};
  };
  auto print = [&](const char* what, const Errors& errors) {
    auto p = summary(errors.position_mm), h = summary(errors.heading_deg);
    std::printf(
        "[ accuracy ] %-24s %4zu readings: position mm median %.2f p95 %.2f max %.2f; heading "
        "deg median %.3f p95 %.3f max %.3f\n",
        what, errors.position_mm.size(), p[0], p[1], p[2], h[0], h[1], h[2]);
    return std::pair{p[2], h[2]};
  };
  auto [three_position, three_heading] = print("3 LEDs", three_leds);
  print("3 LEDs, in overlaps", three_leds_in_overlaps);
  auto [two_position, two_heading] = print("2 LEDs (tracked)", two_leds);
  EXPECT_LT(three_position, kPositionToleranceM * 1000);
  EXPECT_LT(three_heading, kHeadingToleranceRad / kDegree);
  EXPECT_LT(two_position, kPositionToleranceM * 1000);
  EXPECT_LT(two_heading, kTwoLedHeadingToleranceRad / kDegree);
}

// Cameras not yet calibrated: each 2 cm and 1 degree off the rig file's pose, so that two
// cameras put one LED 3 to 7 cm apart, more than the merge distance and about an LED spacing.
// Poses shift by that much, but a pair or triple mixing two cameras' points must never turn a
// robot round: the recognizer prefers what one camera saw, and tells the ends of a pair apart
// by both LEDs' tracked places.
Rig misplaced_seed_rig() {
  Rig mounted = seed_rig();
  for (size_t i = 0; i < mounted.cameras.size(); ++i) {
    RigCamera& camera = mounted.cameras[i];
    const double angle = (90.0 * static_cast<double>(i) + 30) * kDegree;
    const Eigen::Vector3d axis(std::cos(angle), std::sin(angle), 0.3);
    camera.world_from_camera.linear() =
        Eigen::AngleAxisd(1.0 * kDegree, axis.normalized()).toRotationMatrix() *
        camera.world_from_camera.linear();
    camera.world_from_camera.translation() +=
        0.02 * Eigen::Vector3d(-std::sin(angle), std::cos(angle), 0);
  }
  return mounted;
}

TEST(PixartLocalization, MisplacedCamerasShiftPosesButNeverTurnThem) {
  const Rig mounted = misplaced_seed_rig();
  RobotLocalizer localizer(seed_rig());
  // robot_a laps the middle of the floor, where all four cameras overlap, at 0.2 m/s, its
  // ends blinking in turn.
  const std::vector<Lights> blinking = {Lights{}, Lights{false, true, true}, Lights{},
                                        Lights{true, true, false}};
  double worst_position = 0, worst_heading = 0;
  int readings = 0;
  for (int k = 0; k < 2000; ++k) {
    const int64_t t = kStart + k * kSamplePeriod;
    const double around = 2 * M_PI * k / 1700.0;
    const PlanarPose truth{0.3 * std::cos(around), 0.3 * std::sin(around), around + M_PI / 2};
    observe(localizer, {{"robot_a", truth, blinking[(k / 40) % 4]}}, t, &mounted);
    auto robot = find_robot(localizer.tracked_robots(t), "robot_a");
    if (!robot) continue;
    ++readings;
    worst_position = std::max(worst_position, (robot->pose.position() - truth.position()).norm());
    worst_heading = std::max(worst_heading, heading_error(robot->pose.theta, truth.theta));
  }
  EXPECT_EQ(readings, 2000);
  EXPECT_LT(worst_position, 0.06);
  EXPECT_LT(worst_heading, 10 * kDegree) << "worst heading error " << worst_heading / kDegree;
}

// The same cameras, calibrated: each one's camera file gives its lens (EUCM, a little barrel
// distortion, principal point off centre) and where it really hangs. The rig read from those
// files has the cameras where they are, and localizes within millimetres again.
TEST(PixartLocalization, CalibratedCameraFilesPlaceTheCamerasAndRestoreMillimetres) {
  test::TempDir dir;
  Rig mounted = misplaced_seed_rig();
  std::string rig_text = "led_plane_height_m: 0.45\ncameras:\n";
  for (size_t i = 0; i < mounted.cameras.size(); ++i) {
    RigCamera& camera = mounted.cameras[i];
    const double offset = 3.0 * static_cast<double>(i);
    camera.model = std::make_shared<calibration::EucmCamera>(
        1024, 768, std::array<double, 6>{0.15, 1.08, 1372, 1365, 509 + offset, 386 - offset});
    calibration::CameraFile file;
    file.name = file.frame_id = camera.name;
    file.model = camera.model;
    file.world_from_camera = camera.world_from_camera;
    calibration::save_camera_file((dir / (camera.name + ".yaml")).string(), file);
    rig_text += "  - {name: " + camera.name + ", camera_id: " + std::to_string(camera.camera_id) +
                ", camera_file: " + camera.name + ".yaml}\n";
  }
  test::write_file(dir / "rig.yaml", rig_text);
  Rig rig = load_rig((dir / "rig.yaml").string());
  rig.robots = seed_rig().robots;
  ASSERT_EQ(rig.cameras.size(), mounted.cameras.size());
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const RigCamera& loaded = rig.cameras[i];
    const RigCamera& truth = mounted.cameras[i];
    EXPECT_EQ(loaded.name, truth.name);
    EXPECT_EQ(loaded.model->type(), "eucm");
    EXPECT_LT((loaded.world_from_camera.matrix() - truth.world_from_camera.matrix())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-15)
        << loaded.name;
    // Not where the rig's nominal layout would have put it.
    EXPECT_GT((loaded.world_from_camera.translation() -
               seed_rig().cameras[i].world_from_camera.translation())
                  .norm(),
              0.019);
  }
  int64_t t = kStart;
  for (const PlanarPose& truth :
       {PlanarPose{-0.8, -0.6, 30 * kDegree}, PlanarPose{0.1, -0.6, 90 * kDegree},
        PlanarPose{0.02, 0.03, -100 * kDegree}, PlanarPose{0.7, 0.45, 170 * kDegree}}) {
    RobotLocalizer localizer(rig);  // no history: every pose read afresh
    t += kSamplePeriod;
    observe(localizer, {{"robot_a", truth}}, t, &mounted);
    expect_pose(localizer.tracked_robots(t), "robot_a", truth, PoseEvidence::AllLeds);
  }
}

TEST(PixartRig, ACameraFilesPoseAndARigPositionCannotBothBeGiven) {
  test::TempDir dir;
  calibration::CameraFile file;
  file.name = file.frame_id = "c";
  file.model = nominal_pixart_camera();
  save_camera_file((dir / "unplaced.yaml").string(), file);
  file.world_from_camera = downward_camera_pose({0.2, 0.1, 2.4}, 33);
  save_camera_file((dir / "placed.yaml").string(), file);
  auto error = [&](const std::string& camera) {
    try {
      parse_rig("cameras:\n  - name: c\n    camera_id: 0\n" + camera, "rig.yaml", dir.path());
    } catch (const RigError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  std::string message = error("    camera_file: placed.yaml\n    position: [0, 0, 2.5]\n");
  EXPECT_TRUE(
      message.starts_with("rig.yaml:5: camera 'c': its camera file gives its pose, so "
                          "'position' must not be given too"))
      << message;
  message = error("    yaw_deg: 90\n    camera_file: placed.yaml\n");
  EXPECT_TRUE(
      message.starts_with("rig.yaml:4: camera 'c': its camera file gives its pose, so "
                          "'yaw_deg' must not be given too"))
      << message;
  message = error("    camera_file: unplaced.yaml\n");
  EXPECT_TRUE(
      message.starts_with("rig.yaml:2: a camera without a calibrated pose needs "
                          "'position'"))
      << message;
  EXPECT_EQ(error("    camera_file: placed.yaml\n"), "(no error)");
  Rig rig = parse_rig("cameras:\n  - {name: c, camera_id: 0, camera_file: placed.yaml}\n",
                      "rig.yaml", dir.path());
  EXPECT_LT((rig.cameras[0].world_from_camera.matrix() -
             downward_camera_pose({0.2, 0.1, 2.4}, 33).matrix())
                .norm(),
            1e-15);
  // Without a pose, a camera file gives the lens and the rig places the camera.
  rig = parse_rig(
      "cameras:\n  - {name: c, camera_id: 0, camera_file: unplaced.yaml, position: [1, 2, 3], "
      "yaw_deg: 90}\n",
      "rig.yaml", dir.path());
  EXPECT_EQ(rig.cameras[0].world_from_camera.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_LT((rig.cameras[0].world_from_camera.linear() * Eigen::Vector3d::UnitX() -
             Eigen::Vector3d::UnitY())
                .norm(),
            1e-12);
}

// ---------------------------------------------------------------------------------------------
// The plugin through the runtime.

using Fiducials = mocap_msgs::msg::FiducialArray;
using RobotPoses = mocap_msgs::msg::RobotPoseArray;

const PlanarPose kPluginTruth{0.1, -0.6, 90 * kDegree};  // between camera2 and camera3

// Plays what camera2 and camera3 see of robot_a standing in their overlap: one array per
// camera every 4 ms, 100 times; first a stray array of a camera the rig lacks and a point
// that is not a number.
class CameraPlayer final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.publishes<Fiducials>("/pixart/{camera}/fiducials", Qos::reliable(), "");
  }
  explicit CameraPlayer(Context& context) : Component(context) {
    for (const RigCamera& camera : seed_rig().cameras) {
      if (camera.name != "camera2" && camera.name != "camera3") continue;
      cameras_.push_back(&camera);
      publishers_.push_back(create_publisher<Fiducials>("/pixart/" + camera.name + "/fiducials"));
    }
    create_timer(std::chrono::milliseconds(4), [this] { play(); });
  }

  std::mutex mutex;
  std::set<int64_t> stamps;  // of the arrays sent

 private:
  void play() {
    if (sent_ == 100 || publishers_[0].matched_subscribers() == 0 ||
        publishers_[1].matched_subscribers() == 0) {
      return;
    }
    auto stamp = to_time_msg(now());
    {
      std::lock_guard lock(mutex);
      stamps.insert(to_nanoseconds(stamp));
    }
    if (sent_ == 0) {
      Fiducials stray;
      stray.header().stamp(stamp);
      stray.header().frame_id("camera9");
      publishers_[0].publish(stray);
    }
    std::vector<Eigen::Vector3d> leds = lit_leds(seed_rig(), {{"robot_a", kPluginTruth}});
    for (size_t c = 0; c < cameras_.size(); ++c) {
      Fiducials array;
      array.header().stamp(stamp);
      array.header().frame_id(cameras_[c]->name);
      for (const Eigen::Vector2d& pixel : sensor_pixels(*cameras_[c], leds)) {
        mocap_msgs::msg::Fiducial fiducial;
        fiducial.x(static_cast<float>(pixel.x()));
        fiducial.y(static_cast<float>(pixel.y()));
        array.fiducials().push_back(fiducial);
      }
      if (sent_ == 0 && c == 0) {
        mocap_msgs::msg::Fiducial broken;
        broken.x(std::numeric_limits<float>::quiet_NaN());
        array.fiducials().push_back(broken);
      }
      publishers_[c].publish(array);
    }
    ++sent_;
  }

  std::vector<const RigCamera*> cameras_;
  std::vector<Publisher<Fiducials>> publishers_;
  int sent_ = 0;
};

class PoseCollector final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<RobotPoses>("/pixart/robots", Qos::reliable(), "");
  }
  explicit PoseCollector(Context& context) : Component(context) {
    create_subscription<RobotPoses>("/pixart/robots", [this](const RobotPoses& poses) {
      std::lock_guard lock(mutex);
      received.push_back(poses);
      arrived.notify_all();
    });
  }
  // Waits until an array satisfies `predicate`; returns it.
  template <class Predicate>
  std::optional<RobotPoses> wait_for(Predicate predicate, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    std::optional<RobotPoses> found;
    arrived.wait_for(lock, timeout, [&] {
      for (; checked_ < received.size(); ++checked_) {
        if (predicate(received[checked_])) {
          found = received[checked_];
          return true;
        }
      }
      return false;
    });
    return found;
  }
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<RobotPoses> received;

 private:
  size_t checked_ = 0;
};

TEST(PixartLocalizerPlugin, PublishesRobotPosesFromFiducialArrays) {
  static PluginLoader loader;
  const ComponentFactory& factory = *loader.load("pixart_localizer").factory;

  testing::internal::CaptureStderr();
  auto host = std::make_unique<ComponentHost>(
      HostOptions{.name = "test", .threads = 2, .dds = {.enabled = false}});
  host->add(factory, {.name = "localizer",
                      .parameters = {{"lost_after_s", 0.3}, {"publish_rate_hz", 100.0}}});
  auto& player = static_cast<CameraPlayer&>(
      host->add(make_component_factory<CameraPlayer>("player"), {.name = "player"}));
  auto& collector = static_cast<PoseCollector&>(
      host->add(make_component_factory<PoseCollector>("collector"), {.name = "collector"}));
  host->start();

  auto seen = collector.wait_for([](const RobotPoses& poses) { return !poses.robots().empty(); },
                                 std::chrono::seconds(10));
  ASSERT_TRUE(seen) << "no robot published";
  EXPECT_EQ(seen->header().frame_id(), "world");
  ASSERT_EQ(seen->robots().size(), 1u);
  const auto& robot = seen->robots()[0];
  EXPECT_EQ(robot.name(), "robot_a");
  EXPECT_LT(std::hypot(robot.x() - kPluginTruth.x, robot.y() - kPluginTruth.y),
            kPositionToleranceM);
  EXPECT_LT(heading_error(robot.theta(), kPluginTruth.theta), kHeadingToleranceRad);
  {
    // Stamped with a sample's time.
    std::lock_guard lock(player.mutex);
    EXPECT_TRUE(player.stamps.count(to_nanoseconds(seen->header().stamp())));
  }
  // The player stops after 100 samples; the robot standing there is published until 0.3 s
  // after the last one, then dropped.
  auto dropped = collector.wait_for([](const RobotPoses& poses) { return poses.robots().empty(); },
                                    std::chrono::seconds(20));
  ASSERT_TRUE(dropped) << "robot_a never dropped";
  host->stop();
  size_t with_robot = 0;
  {
    std::lock_guard lock(collector.mutex);
    for (const RobotPoses& poses : collector.received) with_robot += poses.robots().size();
  }
  EXPECT_GT(with_robot, 10u);  // 0.4 s of samples and 0.3 s more, at 100 Hz
  host.reset();
  std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("robot_a found at"), std::string::npos) << log;
  EXPECT_NE(log.find("robot_a lost"), std::string::npos) << log;
  EXPECT_NE(log.find("arrays of camera 'camera9' are ignored"), std::string::npos) << log;
  EXPECT_NE(log.find("1 arrays from cameras not in the rig, 1 non-finite points"),
            std::string::npos)
      << log;
}

// publish_rate_hz 0: one array per sample used, none from a timer.
TEST(PixartLocalizerPlugin, RateZeroPublishesAfterEverySampleUsed) {
  static PluginLoader loader;
  const ComponentFactory& factory = *loader.load("pixart_localizer").factory;

  testing::internal::CaptureStderr();
  auto host = std::make_unique<ComponentHost>(
      HostOptions{.name = "test", .threads = 2, .dds = {.enabled = false}});
  host->add(factory, {.name = "localizer", .parameters = {{"publish_rate_hz", 0.0}}});
  auto& player = static_cast<CameraPlayer&>(
      host->add(make_component_factory<CameraPlayer>("player"), {.name = "player"}));
  auto& collector = static_cast<PoseCollector&>(
      host->add(make_component_factory<PoseCollector>("collector"), {.name = "collector"}));
  host->start();

  // 100 samples of each of two cameras; the stray camera9 array is not used.
  int arrays = 0;
  ASSERT_TRUE(collector.wait_for([&](const RobotPoses&) { return ++arrays == 200; },
                                 std::chrono::seconds(10)))
      << arrays << " arrays";
  // Without a timer nothing follows the last sample, not even the drop of robot_a (lost_after_s
  // is 1 s): an extra array would be a timer's.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  host->stop();
  std::lock_guard collected(collector.mutex);
  std::lock_guard played(player.mutex);
  ASSERT_EQ(collector.received.size(), 200u);
  int64_t previous = 0;
  for (const RobotPoses& poses : collector.received) {
    const int64_t stamp = to_nanoseconds(poses.header().stamp());
    EXPECT_TRUE(player.stamps.count(stamp)) << stamp;
    EXPECT_GE(stamp, previous);
    previous = stamp;
  }
  const RobotPoses& last = collector.received.back();
  ASSERT_EQ(last.robots().size(), 1u);
  EXPECT_EQ(last.robots()[0].name(), "robot_a");
  EXPECT_LT(
      std::hypot(last.robots()[0].x() - kPluginTruth.x, last.robots()[0].y() - kPluginTruth.y),
      kPositionToleranceM);
  host.reset();
  std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("200 samples used, 200 pose arrays published"), std::string::npos) << log;
}

TEST(PixartLocalizerPlugin, ABadRigIsAClearError) {
  static PluginLoader loader;
  const ComponentFactory& factory = *loader.load("pixart_localizer").factory;
  test::TempDir dir;
  test::write_file(dir / "rig.yaml", "cameras:\n  - {name: c, camera_id: 0, position: [0, 0]}\n");
  ComponentHost host(HostOptions{.name = "test", .threads = 1, .dds = {.enabled = false}});
  try {
    host.add(factory, {.name = "localizer", .parameters = {{"rig", (dir / "rig.yaml").string()}}});
    ADD_FAILURE() << "no error";
  } catch (const ComponentError& e) {
    EXPECT_NE(std::string(e.what()).find("rig.yaml:2"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Options built in code get the checks a launch file's parameters get from the plugin's ranges.

TEST(LocalizerOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(LocalizerOptions{}.problem(), std::nullopt);
  EXPECT_EQ(MergeOptions{.merge_window_s = -0.001}.problem(), "merge_window_s: -0.001 is below 0");
  EXPECT_EQ(MergeOptions{.merge_window_s = 0}.problem(), std::nullopt);  // same instant only
  EXPECT_EQ(RecognitionOptions{.tracking_gate_m = 0}.problem(),
            "tracking_gate_m: 0 is not above 0");
  EXPECT_EQ(TrackingOptions{.lost_after_s = std::numeric_limits<double>::infinity()}.problem(),
            "lost_after_s: inf is not finite");
  LocalizerOptions options;
  options.merging.stale_after_s = -1;
  EXPECT_EQ(options.problem(), "merging.stale_after_s: -1 is not above 0");
  options = {};
  options.recognition.pattern_tolerance_m = 0;
  EXPECT_EQ(options.problem(), "recognition.pattern_tolerance_m: 0 is not above 0");
  options = {};
  options.tracking.lost_after_s = 0;
  try {
    RobotLocalizer localizer(seed_rig(), options);
    ADD_FAILURE() << "lost_after_s 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "LocalizerOptions::tracking.lost_after_s: 0 is not above 0");
  }
  // Each step checks its own, named by its own struct.
  try {
    merge_views({}, {.merge_distance_m = 0});
    ADD_FAILURE() << "merge_distance_m 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "MergeOptions::merge_distance_m: 0 is not above 0");
  }
  EXPECT_THROW(RobotTracker({"robot_a"}, {.lost_after_s = -1}), std::invalid_argument);
  EXPECT_THROW(RobotRecognizer(seed_rig().robots, {.pattern_tolerance_m = 0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::pixart::localization
