// The simulated PixArt box: floor trajectories, the scene file, LEDs projected into the rig's
// cameras and packed into CAN frames that the bridge's decoder reads back, the sample schedule,
// the simulated SLCAN adaptor, candump logs, and the plugin talking SLCAN over a pty.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/robot_pose_array.hpp>

#include "common/can_io/candump_log.hpp"
#include "common/can_io/slcan.hpp"
#include "common/serial_io/serial_port.hpp"
#include "host/plugin_loader.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"
#include "sim/pixart_box_sim/candump_recording.hpp"
#include "sim/pixart_box_sim/floor_trajectory.hpp"
#include "sim/pixart_box_sim/pixart_box_simulator.hpp"
#include "sim/pixart_box_sim/pixart_scene.hpp"
#include "sim/pixart_box_sim/sample_schedule.hpp"
#include "sim/pixart_box_sim/simulated_slcan_adaptor.hpp"
#include "test/test_support.hpp"

namespace mocap::pixart {
namespace {

using Truths = mocap_msgs::msg::RobotPoseArray;
using Pixel = std::array<uint16_t, 2>;

constexpr double kPi = 3.14159265358979323846;

// The seed's four cameras (as config/pixart/rig.yaml) and test robots with steady LEDs.
constexpr const char* kTestRig = R"(
led_plane_height_m: 0.45
cameras:
  - {name: camera2, camera_id: 2, position: [-0.5, -0.5, 2.5], yaw_deg: 0}
  - {name: camera3, camera_id: 3, position: [0.5, -0.5, 2.5], yaw_deg: 90}
  - {name: camera0, camera_id: 0, position: [0.5, 0.5, 2.5], yaw_deg: 180}
  - {name: camera1, camera_id: 1, position: [-0.5, 0.5, 2.5], yaw_deg: 270}
robots:
  - name: dot
    leds: [{position: [0, 0]}]
  - name: blinker
    leds: [{position: [0, 0], on_s: 0.2, off_s: 0.2}]
  - name: line
    leds: [{position: [0.12, 0]}, {position: [0, 0]}, {position: [-0.06, 0]}]
  - name: cluster
    leds: [{position: [0, 0]}, {position: [0.02, 0]}, {position: [0.04, 0]},
           {position: [0, 0.02]}, {position: [0.02, 0.02]}, {position: [0.04, 0.02]}]
)";

Rig test_rig() { return parse_rig(kTestRig, "test_rig.yaml"); }

Rig shipped_rig() { return load_rig((test::source_dir() / "config/pixart/rig.yaml").string()); }

PixartScene scene_of(const std::string& text, const Rig& rig) {
  return parse_pixart_scene(text, "scene.yaml", rig);
}

// Where the sensor reports a world point, worked out here rather than by the simulator.
std::optional<Pixel> sensor_pixel(const RigCamera& camera, const Eigen::Vector3d& world) {
  auto pixel = camera.model->project(camera.world_from_camera.inverse() * world);
  if (!pixel) return std::nullopt;
  const double x = std::round(pixel->x()), y = std::round(pixel->y());
  if (x < 0 || x > 1022 || y < 0 || y > 767) return std::nullopt;
  return Pixel{static_cast<uint16_t>(x), static_cast<uint16_t>(y)};
}

Eigen::Vector3d world_of_led(const SceneObject& object, const Led& led, double time_s) {
  const FloorPose pose = pose_at(object.trajectory, time_s);
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  return {pose.x + c * led.position.x() - s * led.position.y(),
          pose.y + s * led.position.x() + c * led.position.y(), object.height_m};
}

// What each camera (by id) should report at `time_s`: the lit LEDs on its sensor, in scene
// order, at most four.
std::map<uint16_t, std::vector<Pixel>> expected_points(const Rig& rig, const PixartScene& scene,
                                                       double time_s) {
  std::map<uint16_t, std::vector<Pixel>> expected;
  for (const RigCamera& camera : rig.cameras) {
    auto& points = expected[static_cast<uint16_t>(camera.camera_id)];
    for (const SceneObject& object : scene.objects) {
      for (const Led& led : object.leds) {
        if (!led.is_on(time_s)) continue;
        auto pixel = sensor_pixel(camera, world_of_led(object, led, time_s));
        if (pixel && points.size() < 4) points.push_back(*pixel);
      }
    }
  }
  return expected;
}

// Decodes frames into each camera's points in slot order; every frame must be well formed.
std::map<uint16_t, std::vector<Pixel>> decode_all(const std::vector<can::CanFrame>& frames) {
  PixartDecoder decoder;
  std::map<uint16_t, std::vector<Pixel>> decoded;
  std::vector<PixartPoint> points;
  for (const can::CanFrame& frame : frames) {
    points.clear();
    auto camera = decoder.decode(frame, points);
    EXPECT_TRUE(camera.has_value()) << can::to_string(frame);
    if (!camera) continue;
    auto& list = decoded[*camera];
    for (const PixartPoint& p : points) list.push_back({p.x, p.y});
  }
  EXPECT_EQ(decoder.stats().invalid_points, 0u);
  return decoded;
}

// --- trajectories ----------------------------------------------------------------------------

TEST(FloorTrajectory, CircleRunsCounterClockwiseFacingAlongIt) {
  CircleFloorTrajectory circle{.centre = {1, 2}, .radius_m = 0.5, .period_s = 8, .phase_deg = 90};
  FloorPose start = pose_at(circle, 0);
  EXPECT_NEAR(start.x, 1, 1e-12);
  EXPECT_NEAR(start.y, 2.5, 1e-12);
  EXPECT_NEAR(std::abs(start.theta), kPi, 1e-12);  // at the top, heading -x
  FloorPose quarter = pose_at(circle, 2);          // a quarter lap later: the -x side
  EXPECT_NEAR(quarter.x, 0.5, 1e-12);
  EXPECT_NEAR(quarter.y, 2, 1e-12);
  EXPECT_NEAR(quarter.theta, -kPi / 2, 1e-12);  // heading -y
  FloorPose lap = pose_at(circle, 8 * 1000);    // many laps later: where it started
  EXPECT_NEAR(lap.x, 1, 1e-9);
  EXPECT_NEAR(lap.y, 2.5, 1e-9);

  circle.clockwise = true;
  FloorPose clockwise = pose_at(circle, 2);  // a quarter lap the other way: the +x side
  EXPECT_NEAR(clockwise.x, 1.5, 1e-12);
  EXPECT_NEAR(clockwise.y, 2, 1e-12);
  EXPECT_NEAR(clockwise.theta, -kPi / 2, 1e-12);  // heading -y as well, on the other side
}

TEST(FloorTrajectory, WaypointsFaceAlongThePathAndStopAtTheEnd) {
  WaypointFloorTrajectory path{.points = {{0, 0}, {1, 0}, {1, 0}, {1, 1}}, .speed_mps = 0.5};
  FloorPose before = pose_at(path, -3);
  EXPECT_NEAR(before.x, 0, 1e-12);
  EXPECT_NEAR(before.y, 0, 1e-12);
  FloorPose first = pose_at(path, 1);
  EXPECT_NEAR(first.x, 0.5, 1e-12);
  EXPECT_NEAR(first.y, 0, 1e-12);
  EXPECT_NEAR(first.theta, 0, 1e-12);
  FloorPose second = pose_at(path, 3);  // the repeated point has no segment of its own
  EXPECT_NEAR(second.x, 1, 1e-12);
  EXPECT_NEAR(second.y, 0.5, 1e-12);
  EXPECT_NEAR(second.theta, kPi / 2, 1e-12);
  for (double t : {4.0, 10.0, 1e5}) {  // at and after the end: stopped, same heading
    FloorPose end = pose_at(path, t);
    EXPECT_NEAR(end.x, 1, 1e-12) << t;
    EXPECT_NEAR(end.y, 1, 1e-12) << t;
    EXPECT_NEAR(end.theta, kPi / 2, 1e-12) << t;
  }
  path.loop = true;  // back along the diagonal to the start, then round again
  const double lap_s = (2 + std::sqrt(2.0)) / 0.5;
  FloorPose back = pose_at(path, 4 + std::sqrt(2.0));  // half-way along the diagonal
  EXPECT_NEAR(back.x, 0.5, 1e-9);
  EXPECT_NEAR(back.y, 0.5, 1e-9);
  EXPECT_NEAR(back.theta, -3 * kPi / 4, 1e-9);
  FloorPose again = pose_at(path, lap_s + 1);
  EXPECT_NEAR(again.x, 0.5, 1e-9);
  EXPECT_NEAR(again.y, 0, 1e-9);
}

TEST(FloorTrajectory, StaticPoseIsWrapped) {
  FloorPose pose = pose_at(StaticFloorTrajectory{{0.2, -0.3, 3 * kPi / 2}}, 12.5);
  EXPECT_EQ(pose.x, 0.2);
  EXPECT_EQ(pose.y, -0.3);
  EXPECT_NEAR(pose.theta, -kPi / 2, 1e-12);
  EXPECT_NEAR(wrap_angle(-kPi), kPi, 1e-12);
}

// --- the scene file --------------------------------------------------------------------------

TEST(PixartScene, ReadsRobotsAndBoards) {
  Rig rig = test_rig();
  PixartScene scene = scene_of(R"(
robots:
  - name: line
    trajectory: {type: circle, centre: [0.1, 0.2], radius_m: 0.4, period_s: 12, phase_deg: 45,
                 clockwise: true}
  - name: dot
    trajectory: {type: waypoints, points: [[0, 0], [1, 0]], speed_mps: 0.3, loop: true}
calibration_boards:
  - name: board
    size_m: 0.2
    height_m: 0.1
    trajectory: {type: static, x: 0.5, y: -0.5, theta_deg: 90}
)",
                               rig);
  ASSERT_EQ(scene.objects.size(), 3u);
  const SceneObject& line = scene.objects[0];
  EXPECT_EQ(line.name, "line");
  EXPECT_EQ(line.kind, SceneObject::Kind::Robot);
  EXPECT_EQ(line.leds.size(), 3u);
  EXPECT_EQ(line.height_m, 0.45);
  const auto& circle = std::get<CircleFloorTrajectory>(line.trajectory);
  EXPECT_EQ(circle.centre, Eigen::Vector2d(0.1, 0.2));
  EXPECT_EQ(circle.radius_m, 0.4);
  EXPECT_EQ(circle.period_s, 12);
  EXPECT_EQ(circle.phase_deg, 45);
  EXPECT_TRUE(circle.clockwise);
  const auto& path = std::get<WaypointFloorTrajectory>(scene.objects[1].trajectory);
  EXPECT_EQ(path.points.size(), 2u);
  EXPECT_EQ(path.speed_mps, 0.3);
  EXPECT_TRUE(path.loop);
  const SceneObject& board = scene.objects[2];
  EXPECT_EQ(board.kind, SceneObject::Kind::CalibrationBoard);
  EXPECT_EQ(board.height_m, 0.1);
  ASSERT_EQ(board.leds.size(), 4u);
  EXPECT_EQ(board.leds[2].position, Eigen::Vector2d(0.1, 0.1));
  const auto& still = std::get<StaticFloorTrajectory>(board.trajectory);
  EXPECT_EQ(still.pose.x, 0.5);
  EXPECT_NEAR(still.pose.theta, kPi / 2, 1e-12);
}

TEST(PixartScene, ShippedScenesLoadWithTheShippedRig) {
  Rig rig = shipped_rig();
  PixartScene two = load_pixart_scene(
      (test::source_dir() / "config/pixart/scenes/two_robots.yaml").string(), rig);
  ASSERT_EQ(two.objects.size(), 2u);
  EXPECT_EQ(two.objects[0].name, "robot_a");
  EXPECT_EQ(two.objects[1].name, "robot_b");
  // robot_b's tour ends: it stands still afterwards.
  FloorPose parked = pose_at(two.objects[1].trajectory, 1000);
  FloorPose later = pose_at(two.objects[1].trajectory, 2000);
  EXPECT_EQ(parked.x, later.x);
  EXPECT_EQ(parked.y, later.y);
  EXPECT_EQ(parked.theta, later.theta);
  PixartScene board = load_pixart_scene(
      (test::source_dir() / "config/pixart/scenes/calibration_board.yaml").string(), rig);
  ASSERT_EQ(board.objects.size(), 1u);
  EXPECT_EQ(board.objects[0].kind, SceneObject::Kind::CalibrationBoard);
}

TEST(PixartScene, ErrorsNameFileAndLine) {
  Rig rig = test_rig();
  struct Case {
    const char* text;
    const char* expected;
  };
  const Case cases[] = {
      {"robots:\n  - name: dot\n    trajectroy: {type: static, x: 0, y: 0}\n",
       "scene.yaml:3: unknown key 'trajectroy' in a robot (did you mean 'trajectory'?)"},
      {"robots:\n  - name: dot\n    trajectory: {type: static, x: 0, y: 0}\n"
       "  - name: rover\n    trajectory: {type: static, x: 0, y: 0}\n",
       "scene.yaml:4: robot 'rover' is not in the rig test_rig.yaml"},
      {"robots:\n  - name: dot\n    trajectory: {type: static, x: 0, y: 0}\n"
       "  - name: dot\n    trajectory: {type: static, x: 1, y: 0}\n",
       "scene.yaml:4: 'dot' appears twice"},
      {"robots:\n  - name: dot\n    trajectory: {type: spiral}\n",
       "scene.yaml:3: trajectory type is 'spiral', must be one of: static, circle, waypoints"},
      {"robots:\n  - name: dot\n    trajectory:\n      type: waypoints\n"
       "      points: [[1, 1], [1, 1]]\n",
       "scene.yaml:5: 'points' are all the same point"},
      {"robots:\n  - name: dot\n    trajectory: {type: circle, centre: [0, 0], period_s: 0}\n",
       "scene.yaml:3: 'period_s' is 0, must be positive"},
      {"robots:\n  - name: dot\n    trajectory: {type: circle, centre: [0]}\n",
       "scene.yaml:3: 'centre' needs [x, y] in metres, not a list of 1"},
      {"robots:\n  - name: dot\n", "scene.yaml:2: a robot needs 'trajectory'"},
      {"calibration_boards:\n  - name: b\n    size_m: -1\n"
       "    trajectory: {type: static, x: 0, y: 0}\n",
       "scene.yaml:3: 'size_m' is -1, must be positive"},
      {"robots: [\n", "scene.yaml:2:"},
      {"lights: []\n", "scene.yaml:1: unknown key 'lights' in the scene"},
  };
  for (const Case& c : cases) {
    try {
      scene_of(c.text, rig);
      ADD_FAILURE() << "no error for:\n" << c.text;
    } catch (const PixartSceneError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos)
          << e.what() << "\nexpected: " << c.expected;
    }
  }
  try {
    load_pixart_scene("/nonexistent/scene.yaml", rig);
    ADD_FAILURE() << "no error";
  } catch (const PixartSceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.yaml: cannot read the scene"),
              std::string::npos)
        << e.what();
  }
}

TEST(PixartScene, CalibrationBoardLightsOneLedAtATime) {
  std::vector<Led> leds = calibration_board_leds(0.25);
  ASSERT_EQ(leds.size(), 4u);
  EXPECT_EQ(leds[0].position, Eigen::Vector2d(-0.125, -0.125));
  EXPECT_EQ(leds[1].position, Eigen::Vector2d(0.125, -0.125));
  EXPECT_EQ(leds[3].position, Eigen::Vector2d(-0.125, 0.125));
  // LED i is on during [0.2 i, 0.2 i + 0.1) of each 0.8 s cycle, all dark in between.
  for (int step = 0; step < 32; ++step) {
    const double t = 0.05 + 0.1 * step;  // the middle of each 100 ms
    const int slot = step % 8;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(leds[i].is_on(t), slot == 2 * i) << "LED " << i << " at " << t;
    }
  }
}

// --- projection and frames -------------------------------------------------------------------

TEST(PixartBoxSimulator, LedStraightUnderACameraIsAtThePrincipalPoint) {
  Rig rig = test_rig();
  // One steady LED under each camera; each is outside the other cameras' views.
  PixartScene scene = scene_of(R"(
robots:
  - {name: dot, trajectory: {type: static, x: 0.5, y: 0.5}}
)",
                               rig);
  for (const RigCamera& camera : rig.cameras) {
    const Eigen::Vector3d above = camera.world_from_camera.translation();
    scene.objects[0].trajectory = StaticFloorTrajectory{{above.x(), above.y(), 0.3}};
    PixartBoxSimulator simulator(rig, scene);
    std::vector<CameraView> views = simulator.views_at(0);
    ASSERT_EQ(views.size(), 4u);
    for (const CameraView& view : views) {
      if (view.camera_id == camera.camera_id) {
        ASSERT_EQ(view.points.size(), 1u) << camera.name;
        // The principal point (511.5, 383.5), rounded as the sensor reports it.
        EXPECT_EQ(view.points[0].x, 512) << camera.name;
        EXPECT_EQ(view.points[0].y, 384) << camera.name;
        EXPECT_EQ(view.points[0].object, 0u);
        EXPECT_EQ(view.points[0].led, 0u);
      } else {
        EXPECT_TRUE(view.points.empty()) << camera.name << " sees the LED under another camera";
      }
    }
  }
}

TEST(PixartBoxSimulator, ImageAxesFollowTheCameraYaw) {
  Rig rig = test_rig();
  // 0.1 m towards world +x from under camera2, whose image x axis is world x (yaw 0): to the
  // right of the principal point by f · 0.1 / 2.05 pixels, f = 512 / tan(20.5°).
  PixartScene scene =
      scene_of("robots: [{name: dot, trajectory: {type: static, x: -0.4, y: -0.5}}]", rig);
  PixartBoxSimulator simulator(rig, scene);
  std::vector<CameraView> views = simulator.views_at(0);
  ASSERT_EQ(views[0].camera_id, 2);
  ASSERT_EQ(views[0].points.size(), 1u);
  const double offset = 512 / std::tan(20.5 * kPi / 180) * 0.1 / 2.05;
  EXPECT_EQ(views[0].points[0].x, static_cast<uint16_t>(std::round(511.5 + offset)));
  EXPECT_EQ(views[0].points[0].y, 384);
  // Camera3 is turned 90 degrees: its image x axis is world +y and its y axis (optical z x
  // image x) world +x, so 0.1 m towards world +x from under it moves the LED down the image.
  PixartBoxSimulator turned(
      rig, scene_of("robots: [{name: dot, trajectory: {type: static, x: 0.6, y: -0.5}}]", rig));
  views = turned.views_at(0);
  ASSERT_EQ(views[1].camera_id, 3);
  ASSERT_EQ(views[1].points.size(), 1u);
  EXPECT_EQ(views[1].points[0].x, 512);
  EXPECT_EQ(views[1].points[0].y, static_cast<uint16_t>(std::round(383.5 + offset)));
}

TEST(PixartBoxSimulator, DecodedFramesGiveBackEveryCamerasProjections) {
  Rig rig = shipped_rig();
  PixartScene scene = load_pixart_scene(
      (test::source_dir() / "config/pixart/scenes/two_robots.yaml").string(), rig);
  PixartBoxSimulator simulator(rig, scene);
  size_t points = 0;
  std::set<uint16_t> cameras_with_points;
  for (double t : {0.0, 0.05, 0.33, 1.7, 4.2, 7.5, 12.25, 19.9, 26.0, 31.0, 60.0}) {
    std::vector<can::CanFrame> frames = simulator.frames_at(t, 42);
    ASSERT_EQ(frames.size(), 8u);
    for (size_t i = 0; i < frames.size(); ++i) {
      // Rig order, two frames per camera, slots 0-1 first.
      const uint16_t camera = static_cast<uint16_t>(rig.cameras[i / 2].camera_id);
      EXPECT_EQ(frames[i].id, 0x100u + 2u * camera + i % 2);
      EXPECT_EQ(frames[i].length, 8);
      EXPECT_EQ(frames[i].stamp_ns, 42);
    }
    auto decoded = decode_all(frames);
    auto expected = expected_points(rig, scene, t);
    for (const auto& [camera, pixels] : expected) {
      EXPECT_EQ(decoded[camera], pixels) << "camera " << camera << " at " << t << " s";
      points += pixels.size();
      if (!pixels.empty()) cameras_with_points.insert(camera);
    }
  }
  // The scene is not empty: the robots are seen, and by more than one camera.
  EXPECT_GT(points, 20u);
  EXPECT_GE(cameras_with_points.size(), 3u);
}

TEST(PixartBoxSimulator, LedsOutsideTheViewAreAbsent) {
  Rig rig = test_rig();
  PixartScene scene = scene_of(R"(
robots:
  - {name: dot, trajectory: {type: static, x: 5, y: 5}}
  - {name: line, trajectory: {type: static, x: -0.5, y: -0.5}}
)",
                               rig);
  PixartBoxSimulator simulator(rig, scene);
  auto decoded = decode_all(simulator.frames_at(0));
  EXPECT_EQ(decoded[2].size(), 3u);  // camera2 sees the line robot's three LEDs
  EXPECT_TRUE(decoded[3].empty());
  EXPECT_TRUE(decoded[0].empty());
  EXPECT_TRUE(decoded[1].empty());
  for (const CameraView& view : simulator.views_at(0)) {
    for (const SimulatedPoint& p : view.points) EXPECT_EQ(p.object, 1u);  // never the far dot
  }
}

TEST(PixartBoxSimulator, BlinkingLedsAppearOnlyWhenOn) {
  Rig rig = test_rig();
  PixartScene scene =
      scene_of("robots: [{name: blinker, trajectory: {type: static, x: -0.5, y: -0.5}}]", rig);
  PixartBoxSimulator simulator(rig, scene);
  for (int step = 0; step < 20; ++step) {
    const double t = 0.05 + 0.1 * step;
    const bool on = std::fmod(t, 0.4) < 0.2;  // 0.2 s on, 0.2 s off
    EXPECT_EQ(decode_all(simulator.frames_at(t))[2].size(), on ? 1u : 0u) << t;
  }
}

TEST(PixartBoxSimulator, ReportsFourLedsAndCountsTheRest) {
  Rig rig = test_rig();
  PixartScene scene =
      scene_of("robots: [{name: cluster, trajectory: {type: static, x: -0.5, y: -0.5}}]", rig);
  PixartBoxSimulator simulator(rig, scene);
  std::vector<CameraView> views = simulator.views_at(0);
  ASSERT_EQ(views[0].points.size(), 4u);
  EXPECT_EQ(views[0].excess, 2);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(views[0].points[i].led, i);  // the first four
  EXPECT_EQ(simulator.stats().excess_points, 2u);
  EXPECT_EQ(simulator.stats().points, 4u);
  auto decoded = decode_all(simulator.frames_at(0));
  ASSERT_EQ(decoded[2].size(), 4u);
  EXPECT_EQ(decoded[2], expected_points(rig, scene, 0)[2]);
  EXPECT_EQ(simulator.stats().excess_points, 4u);
  EXPECT_EQ(simulator.stats().samples, 2u);
}

TEST(PixartBoxSimulator, NoiseIsSeededAndSmall) {
  Rig rig = test_rig();
  PixartScene scene =
      scene_of("robots: [{name: line, trajectory: {type: static, x: -0.5, y: -0.5}}]", rig);
  PixartBoxSimulator exact(rig, scene);
  PixartBoxSimulator noisy(rig, scene, {.noise_px = 1.0, .seed = 7});
  PixartBoxSimulator same_seed(rig, scene, {.noise_px = 1.0, .seed = 7});
  EXPECT_EQ(noisy.frames_at(0), same_seed.frames_at(0));
  const std::vector<CameraView> truth = exact.views_at(0);
  ASSERT_EQ(truth[0].points.size(), 3u);
  int moved = 0;
  for (int i = 0; i < 50; ++i) {
    std::vector<CameraView> views = noisy.views_at(0);
    std::vector<CameraView> same = same_seed.views_at(0);
    ASSERT_EQ(views[0].points.size(), 3u);
    ASSERT_EQ(same[0].points.size(), 3u);
    for (size_t p = 0; p < 3; ++p) {
      EXPECT_EQ(views[0].points[p].x, same[0].points[p].x);
      EXPECT_EQ(views[0].points[p].y, same[0].points[p].y);
      const int dx = views[0].points[p].x - truth[0].points[p].x;
      const int dy = views[0].points[p].y - truth[0].points[p].y;
      EXPECT_LE(std::abs(dx), 6);  // 6 sigma
      EXPECT_LE(std::abs(dy), 6);
      moved += dx != 0 || dy != 0;
    }
  }
  // With a sigma of 1 px, rounding leaves a coordinate unchanged about 4 times in 10.
  EXPECT_GT(moved, 50);
}

TEST(PixartBoxSimulator, GroundTruthListsRobotsNotBoards) {
  Rig rig = test_rig();
  PixartScene scene = scene_of(R"(
robots:
  - {name: dot, trajectory: {type: static, x: 0.1, y: 0.2, theta_deg: 30}}
  - {name: line, trajectory: {type: circle, centre: [0, 0], radius_m: 1, period_s: 4}}
calibration_boards:
  - {name: board, trajectory: {type: static, x: 0, y: 0}}
)",
                               rig);
  PixartBoxSimulator simulator(rig, scene);
  std::vector<RobotTruth> truth = simulator.ground_truth(1);
  ASSERT_EQ(truth.size(), 2u);
  EXPECT_EQ(truth[0].name, "dot");
  EXPECT_NEAR(truth[0].pose.theta, kPi / 6, 1e-12);
  EXPECT_EQ(truth[1].name, "line");
  EXPECT_NEAR(truth[1].pose.x, 0, 1e-12);
  EXPECT_NEAR(truth[1].pose.y, 1, 1e-12);
  EXPECT_NEAR(std::abs(truth[1].pose.theta), kPi, 1e-12);
  // An LED's world position: robot pose plus the offset turned by its heading, at the plane.
  Eigen::Vector3d front = simulator.led_position(1, 0, 1);  // line's LED 0.12 m ahead
  EXPECT_NEAR(front.x(), -0.12, 1e-12);
  EXPECT_NEAR(front.y(), 1, 1e-12);
  EXPECT_EQ(front.z(), 0.45);
}

TEST(PixartBoxSimulator, CalibrationBoardIsSeenOneLedAtATimeByTwoCameras) {
  Rig rig = shipped_rig();
  PixartScene scene = load_pixart_scene(
      (test::source_dir() / "config/pixart/scenes/calibration_board.yaml").string(), rig);
  PixartBoxSimulator simulator(rig, scene);
  for (int i = 0; i < 4; ++i) {
    auto decoded = decode_all(simulator.frames_at(0.05 + 0.2 * i));
    EXPECT_EQ(decoded[2].size(), 1u) << "LED " << i;  // camera2
    EXPECT_EQ(decoded[3].size(), 1u) << "LED " << i;  // camera3
    EXPECT_TRUE(decoded[0].empty());
    EXPECT_TRUE(decoded[1].empty());
    auto dark = decode_all(simulator.frames_at(0.15 + 0.2 * i));
    for (const auto& [camera, pixels] : dark) EXPECT_TRUE(pixels.empty()) << camera;
  }
}

TEST(PixartBoxSimulator, RefusesCanIdsBeyondElevenBits) {
  Rig rig = test_rig();
  PixartScene scene = scene_of("robots: []", rig);
  EXPECT_THROW(PixartBoxSimulator(rig, scene, {.base_id = 0x7FA}), std::invalid_argument);
  EXPECT_NO_THROW(PixartBoxSimulator(rig, scene, {.base_id = 0x7F8}));
  EXPECT_THROW(PixartBoxSimulator(rig, scene, {.noise_px = -1}), std::invalid_argument);
}

// --- timing ----------------------------------------------------------------------------------

TEST(SampleSchedule, SamplesAtTheRateAndSkipsWhenLate) {
  SampleSchedule schedule(270);
  EXPECT_EQ(schedule.samples_before(0.1), 27u);
  EXPECT_EQ(schedule.samples_before(1), 270u);
  EXPECT_EQ(schedule.samples_before(0), 0u);
  EXPECT_DOUBLE_EQ(schedule.time_of(27), 0.1);
  auto first = schedule.due(0, 0);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->index, 0u);
  EXPECT_EQ(first->skipped, 0u);
  EXPECT_FALSE(schedule.due(0.001, 1));  // sample 1 is at 3.7 ms
  auto exact = schedule.due(schedule.time_of(5), 5);
  ASSERT_TRUE(exact);
  EXPECT_EQ(exact->index, 5u);
  // 10 periods in, with sample 3 next: 3..9 are stale, sample 10 goes out.
  auto late = schedule.due(schedule.time_of(10) + 0.0001, 3);
  ASSERT_TRUE(late);
  EXPECT_EQ(late->index, 10u);
  EXPECT_EQ(late->skipped, 7u);
  EXPECT_THROW(SampleSchedule(0), std::invalid_argument);
}

// --- the simulated adaptor -------------------------------------------------------------------

TEST(SimulatedSlcanAdaptor, AnswersTheBridgesCommands) {
  SimulatedSlcanAdaptor adaptor;
  EXPECT_FALSE(adaptor.is_open());
  // What the bridge sends (slcan_open_commands), split at an awkward place.
  std::string commands;
  for (const std::string& c : can::slcan_open_commands(1000000)) commands += c;
  EXPECT_EQ(adaptor.feed(commands.substr(0, 3)), "\r");
  EXPECT_EQ(adaptor.feed(commands.substr(3)), "\r\r\r");
  EXPECT_TRUE(adaptor.timestamps());
  EXPECT_TRUE(adaptor.is_open());
  EXPECT_EQ(adaptor.bitrate(), 1000000);
  EXPECT_EQ(adaptor.feed("S6\r"), "\a");  // not while open
  EXPECT_EQ(adaptor.last_refusal(), "S while the channel is open");
  EXPECT_EQ(adaptor.feed("O\r"), "\a");
  EXPECT_EQ(adaptor.feed("t1232AABB\r"), "z\r");
  EXPECT_EQ(adaptor.feed("T123456780\r"), "Z\r");
  EXPECT_EQ(adaptor.feed("t12"), "");
  EXPECT_EQ(adaptor.feed("39AABB\r"), "\a");  // DLC 9
  EXPECT_EQ(adaptor.feed("V\rN\rF\r"), "V1013\rNPXSM\rF00\r");
  EXPECT_EQ(adaptor.feed(can::slcan_close_command()), "\r");
  EXPECT_FALSE(adaptor.is_open());
  EXPECT_EQ(adaptor.feed("C\r"), "\r");  // closing a closed channel is fine
  EXPECT_EQ(adaptor.feed("t1230\r"), "\a");
  EXPECT_EQ(adaptor.feed("S6\r\nL\r"), "\r\r");  // '\n' ignored; listen-only opens too
  EXPECT_EQ(adaptor.bitrate(), 500000);
  EXPECT_TRUE(adaptor.is_open());
  EXPECT_EQ(adaptor.feed("X\r\r" + std::string(100, 'x') + "\r"), "\a\a");
  EXPECT_EQ(adaptor.stats().transmitted, 2u);
  EXPECT_EQ(adaptor.stats().refused, 6u);
  SimulatedSlcanAdaptor fresh;
  EXPECT_EQ(fresh.feed("O\r"), "\a");  // no bitrate yet
  EXPECT_EQ(fresh.last_refusal(), "O before a bitrate was set");
}

TEST(SimulatedSlcanAdaptor, FramesCarryTimestampsWhenAsked) {
  SimulatedSlcanAdaptor adaptor;
  can::CanFrame frame = encode_pixart_frame(0x100, 1, 0, {Pixel{100, 200}, {}});
  EXPECT_EQ(adaptor.frame_message(frame, 0), can::encode_slcan(frame));
  EXPECT_EQ(adaptor.feed("Z1\r"), "\r");
  // 61.234 s: 1234 ms into the minute = 0x04D2.
  std::string message = adaptor.frame_message(frame, 61'234'000'000);
  const std::string plain = can::encode_slcan(frame);
  EXPECT_EQ(message, plain.substr(0, plain.size() - 1) + "04D2\r");
  can::SlcanParser parser;
  parser.feed(message);
  auto frames = parser.take_frames();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].data, frame.data);
}

// --- candump logs ----------------------------------------------------------------------------

TEST(CandumpRecording, WritesEverySampleOfEveryCamera) {
  Rig rig = shipped_rig();
  PixartScene scene = load_pixart_scene(
      (test::source_dir() / "config/pixart/scenes/two_robots.yaml").string(), rig);
  PixartBoxSimulator simulator(rig, scene);
  test::TempDir dir;
  std::ostringstream out;
  const int64_t start = 1'700'000'000'000'000'000;
  uint64_t written = write_candump_recording(
      simulator, out, {.duration_s = 0.1, .rate_hz = 270, .start_ns = start});
  EXPECT_EQ(written, 4u * 2u * 27u);
  test::write_file(dir / "box.log", out.str());
  std::vector<can::CandumpRecord> records = can::read_candump_file((dir / "box.log").string());
  ASSERT_EQ(records.size(), 4u * 2u * 27u);
  EXPECT_EQ(records.front().stamp_ns, start);
  EXPECT_EQ(records.front().interface, "can0");
  for (size_t i = 1; i < records.size(); ++i) {
    EXPECT_GT(records[i].stamp_ns, records[i - 1].stamp_ns) << i;
  }
  // Sample 10: the frames a fresh simulator computes for its time, stamps apart.
  PixartBoxSimulator again(rig, scene);
  std::vector<can::CanFrame> expected = again.frames_at(10 / 270.0);
  for (size_t i = 0; i < expected.size(); ++i) {
    can::CanFrame frame = records[10 * 8 + i].frame;
    frame.stamp_ns = 0;
    EXPECT_EQ(frame, expected[i]) << i;
  }
}

// --- the plugin --------------------------------------------------------------------------------

// Collects /pixart/ground_truth.
class TruthCollector final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<Truths>("/pixart/ground_truth", Qos::reliable(), "");
  }
  explicit TruthCollector(Context& context) : Component(context) {
    create_subscription<Truths>("/pixart/ground_truth", [this](const Truths& truths) {
      std::lock_guard lock(mutex);
      received.push_back(truths);
      arrived.notify_all();
    });
  }
  bool wait_for(size_t count, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    return arrived.wait_for(lock, timeout, [&] { return received.size() >= count; });
  }
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<Truths> received;
};

const ComponentFactory& box_factory() {
  static PluginLoader loader;
  return *loader.load("pixart_box_sim").factory;
}

HostOptions in_process() { return {.name = "test", .threads = 2, .dds = {.enabled = false}}; }

TEST(PixartBoxSimPlugin, PlaysAnSlcanAdaptorOnAPseudoTerminal) {
  test::TempDir dir;
  test::write_file(dir / "rig.yaml", kTestRig);
  const std::string scene_text = R"(
robots:
  - {name: dot, trajectory: {type: static, x: -0.5, y: -0.5}}
  - {name: line, trajectory: {type: static, x: 0.05, y: 0.02, theta_deg: 30}}
)";
  test::write_file(dir / "scene.yaml", scene_text);
  const std::filesystem::path link = dir / "adaptor";
  std::filesystem::create_symlink("/dev/null", link);  // a previous run's link: replaced
  {
    ComponentHost host(in_process());
    host.add(box_factory(), {.name = "box",
                             .parameters = {{"rig", (dir / "rig.yaml").string()},
                                            {"scene", (dir / "scene.yaml").string()},
                                            {"device_link", link.string()}}});
    auto& collector = static_cast<TruthCollector&>(
        host.add(make_component_factory<TruthCollector>("collector"), {.name = "collector"}));
    host.start();
    ASSERT_NE(std::filesystem::read_symlink(link), "/dev/null");

    // The host's side, as the bridge does it: open the device, open the channel at 1 Mbit/s.
    serial::SerialPort port(link.string());
    port.write_all("C\rS8\rO\r");
    std::string received;
    can::SlcanParser parser;
    std::vector<can::CanFrame> frames;
    char buffer[4096];
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (frames.size() < 8 * 20 && std::chrono::steady_clock::now() < deadline) {
      size_t n = port.read(buffer, sizeof buffer, std::chrono::milliseconds(100));
      received.append(buffer, n);
      parser.feed(std::string_view(buffer, n));
      for (const can::CanFrame& frame : parser.take_frames()) frames.push_back(frame);
    }
    // Three acknowledgements, then nothing but frames.
    ASSERT_GE(received.size(), 3u);
    EXPECT_EQ(received.substr(0, 3), "\r\r\r");
    EXPECT_EQ(parser.stats().replies, 3u);
    EXPECT_EQ(parser.stats().errors, 0u) << parser.last_error();
    EXPECT_EQ(parser.stats().bells, 0u);
    ASSERT_GE(frames.size(), 8u * 20u);

    // Every sample (8 frames, in the rig's camera order) decodes to the simulator's own
    // projection of the steady scene.
    Rig rig = test_rig();
    PixartScene scene = scene_of(scene_text, rig);
    PixartBoxSimulator simulator(rig, scene);
    const std::vector<can::CanFrame> expected = simulator.frames_at(0);
    auto expected_pixels = expected_points(rig, scene, 0);
    size_t seen = 0;
    for (const auto& [camera, pixels] : expected_pixels) seen += pixels.size();
    EXPECT_GE(seen, 4u);
    ASSERT_EQ(frames[0].id, expected[0].id);  // the stream starts at a sample's first frame
    for (size_t sample = 0; sample + 8 <= frames.size(); sample += 8) {
      std::vector<can::CanFrame> one(frames.begin() + static_cast<long>(sample),
                                     frames.begin() + static_cast<long>(sample + 8));
      EXPECT_EQ(decode_all(one), decode_all(expected)) << "sample " << sample / 8;
      for (auto& [camera, pixels] : decode_all(one)) {
        EXPECT_EQ(pixels, expected_pixels[camera]) << "camera " << camera;
      }
    }

    // Closing the channel is acknowledged too (after the frames already on their way).
    port.write_all("C\r");
    while (parser.stats().replies < 4 && std::chrono::steady_clock::now() < deadline) {
      size_t n = port.read(buffer, sizeof buffer, std::chrono::milliseconds(100));
      parser.feed(std::string_view(buffer, n));
    }
    EXPECT_EQ(parser.stats().replies, 4u);
    // Ground truth: the robots where the scene puts them.
    ASSERT_TRUE(collector.wait_for(1, std::chrono::seconds(30)));
    {
      std::lock_guard lock(collector.mutex);
      const Truths& truth = collector.received.front();
      EXPECT_EQ(truth.header().frame_id(), "world");
      EXPECT_GT(truth.header().stamp().sec(), 0);
      ASSERT_EQ(truth.robots().size(), 2u);
      EXPECT_EQ(truth.robots()[0].name(), "dot");
      EXPECT_EQ(truth.robots()[0].x(), -0.5);
      EXPECT_EQ(truth.robots()[1].name(), "line");
      EXPECT_NEAR(truth.robots()[1].theta(), kPi / 6, 1e-12);
    }
    host.stop();
  }
  // The link goes with the component.
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(link)));
}

TEST(PixartBoxSimPlugin, WritesACandumpLog) {
  test::TempDir dir;
  const std::filesystem::path file = dir / "box.log";
  ComponentHost host(in_process());
  host.add(box_factory(), {.name = "box",
                           .parameters = {{"output", std::string("candump")},
                                          {"file", file.string()},
                                          {"duration_s", 0.5},
                                          {"start_stamp_s", 1700000000.0}}});
  host.start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!std::filesystem::exists(file) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  host.stop();
  ASSERT_TRUE(std::filesystem::exists(file));
  std::vector<can::CandumpRecord> records = can::read_candump_file(file.string());
  // The shipped rig's 4 cameras, 2 frames each, 135 samples in 0.5 s at 270 Hz.
  ASSERT_EQ(records.size(), 4u * 2u * 135u);
  EXPECT_EQ(records.front().stamp_ns, 1'700'000'000'000'000'000);
  // Ground truth beside it: both robots every 20 ms of scene time, on the log's time scale.
  std::ifstream truth(file.string() + ".truth.csv");
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(truth, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 1u + 2u * 25u);
  EXPECT_EQ(rows[0], kTruthCsvHeader);
  EXPECT_EQ(rows[1].rfind("1700000000000000000,robot_a,", 0), 0u) << rows[1];
  EXPECT_EQ(rows[3].rfind("1700000000020000000,robot_a,", 0), 0u) << rows[3];
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".truth.csv.partial"));
  // The default scene (two robots, shipped rig): the same frames as the library's.
  Rig rig = shipped_rig();
  PixartBoxSimulator simulator(
      rig, load_pixart_scene((test::source_dir() / "config/pixart/scenes/two_robots.yaml").string(),
                             rig));
  for (size_t k : {0u, 77u, 134u}) {
    std::vector<can::CanFrame> expected = simulator.frames_at(k / 270.0);
    for (size_t i = 0; i < expected.size(); ++i) {
      can::CanFrame frame = records[k * 8 + i].frame;
      frame.stamp_ns = 0;
      EXPECT_EQ(frame, expected[i]) << "sample " << k << " frame " << i;
    }
  }
}

TEST(PixartBoxSimPlugin, BadParametersAreClearErrors) {
  test::TempDir dir;
  test::write_file(dir / "scene.yaml", "robots:\n  - name: robot_z\n    trajectory: {}\n");
  test::write_file(dir / "plain_file", "");
  ComponentHost host(in_process());
  struct Case {
    std::map<std::string, ParameterValue> parameters;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{{"output", std::string("usb")}}, "expected pty or candump"},
      {{{"output", std::string("candump")}}, "parameter 'file' is empty"},
      {{{"scene", (dir / "scene.yaml").string()}}, "scene.yaml:2: robot 'robot_z' is not in"},
      {{{"device_link", (dir / "plain_file").string()}}, "is not a symbolic link"},
      {{{"bitrate", 300000}}, "unsupported SLCAN bitrate 300000"},
  };
  int index = 0;
  for (const Case& c : cases) {
    try {
      host.add(box_factory(),
               {.name = "box" + std::to_string(index++), .parameters = c.parameters});
      ADD_FAILURE() << "no error, expected " << c.expected;
    } catch (const ComponentError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
}

// --- options ----------------------------------------------------------------------------------
// Options built in code get the checks a launch file's parameters get from the plugin's ranges:
// what takes them refuses them first, naming the field.

TEST(PixartBoxSimulatorOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(PixartBoxSimulatorOptions{}.problem(), std::nullopt);
  EXPECT_EQ(PixartBoxSimulatorOptions{.noise_px = -1}.problem(), "noise_px: -1 is below 0");
  EXPECT_EQ(
      PixartBoxSimulatorOptions{.noise_px = std::numeric_limits<double>::infinity()}.problem(),
      "noise_px: inf is not finite");
  EXPECT_EQ(PixartBoxSimulatorOptions{.base_id = 0x7FF}.problem(),
            "base_id: 0x7ff leaves no room for camera 0's second frame (IDs end at 0x7ff)");
  // A base beyond 32 bits' reach of the 11-bit range does not wrap around into it.
  EXPECT_EQ(PixartBoxSimulatorOptions{.base_id = 0xFFFFFFFF}.problem(),
            "base_id: 0xffffffff leaves no room for camera 0's second frame (IDs end at 0x7ff)");
  const Rig rig = test_rig();
  try {
    PixartBoxSimulator simulator(rig, scene_of("robots: []", rig), {.noise_px = -1});
    ADD_FAILURE() << "negative noise accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "PixartBoxSimulatorOptions::noise_px: -1 is below 0");
  }
}

TEST(CandumpRecordingOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(CandumpRecordingOptions{}.problem(), std::nullopt);
  EXPECT_EQ(CandumpRecordingOptions{.duration_s = -1}.problem(), "duration_s: -1 is below 0");
  EXPECT_EQ(CandumpRecordingOptions{.rate_hz = 0}.problem(), "rate_hz: 0 is not above 0");
  EXPECT_EQ(CandumpRecordingOptions{.rate_hz = 2e5}.problem(), "rate_hz: 200000 is above 100000");
  EXPECT_EQ(CandumpRecordingOptions{.start_ns = -1}.problem(),
            "start_ns: -1 is below 0 (candump stamps from 1970)");
  EXPECT_EQ(CandumpRecordingOptions{.interface = "can 0"}.problem(),
            "interface: 'can 0' is empty or holds blanks");
  // The truth's rate counts only with a stream to write the truth to.
  std::ostringstream truth;
  EXPECT_EQ(CandumpRecordingOptions{.truth_rate_hz = 0}.problem(), std::nullopt);
  EXPECT_EQ((CandumpRecordingOptions{.truth = &truth, .truth_rate_hz = 0}.problem()),
            "truth_rate_hz: 0 is not above 0 (a truth stream is given)");
  const Rig rig = test_rig();
  PixartBoxSimulator simulator(rig, scene_of("robots: []", rig));
  std::ostringstream log;
  try {
    write_candump_recording(simulator, log, {.rate_hz = 0});
    ADD_FAILURE() << "rate 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "CandumpRecordingOptions::rate_hz: 0 is not above 0");
  }
  EXPECT_TRUE(log.str().empty());
}

}  // namespace
}  // namespace mocap::pixart
