// From raw PixArt points to the calibration's data file (board_recording.hpp): blinks averaged
// from noisy samples, each camera's cycles of the 4-LED board grouped into shots with a dropped
// LED dropping its cycle, cameras of one cycle in one frame; and end to end, the simulated box's
// candump log, and its SLCAN adaptor on a pseudo-terminal, through mocap_calibration_record to
// a data file that matches the board's true projections.
#include <gtest/gtest.h>

#include <csignal>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <mocap/calibration/board_recording.hpp>
#include <mocap/calibration/calibration_config.hpp>
#include <mocap/component_host.hpp>

#include "host/plugin_loader.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"
#include "sim/pixart_box_sim/candump_recording.hpp"
#include "sim/pixart_box_sim/pixart_box_simulator.hpp"
#include "sim/pixart_box_sim/pixart_scene.hpp"
#include "test/test_support.hpp"

namespace mocap::calibration {
namespace {

constexpr int64_t kSecond_ns = 1'000'000'000;
constexpr int64_t kStart_ns = 1'700'000'000 * kSecond_ns;
constexpr double kRate_hz = 270;  // the box's sample rate

int64_t at(double seconds) { return kStart_ns + std::llround(seconds * 1e9); }

// `count` samples of one LED from `start_s` at the box's rate, as the sensor reports it: the
// true pixel plus noise, rounded.
void light(std::vector<RawPoint>& points, int camera, const Eigen::Vector2d& pixel, double start_s,
           int count, std::mt19937& random, double sigma_px = 0.5) {
  std::normal_distribution<double> noise(0, sigma_px);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d measured = pixel + Eigen::Vector2d{noise(random), noise(random)};
    points.push_back({at(start_s + i / kRate_hz), camera,
                      Eigen::Vector2d(std::round(measured.x()), std::round(measured.y()))});
  }
}

void in_time_order(std::vector<RawPoint>& points) {
  std::stable_sort(points.begin(), points.end(),
                   [](const RawPoint& a, const RawPoint& b) { return a.stamp_ns < b.stamp_ns; });
}

TEST(AverageBlinks, EachLitSpellIsOneBlinkAtItsMeanPixel) {
  std::mt19937 random(3);
  std::vector<RawPoint> points;
  const Eigen::Vector2d a(100.3, 200.7), b(400.2, 300.9), c(50.6, 60.1);
  light(points, 0, a, 0.0, 27, random);
  light(points, 1, c, 0.5 / kRate_hz, 27, random);  // another camera, interleaved
  light(points, 0, b, 0.2, 27, random);
  light(points, 0, Eigen::Vector2d(700, 50), 0.5, 3, random);  // a flicker
  light(points, 0, a, 0.8, 27, random);                        // the same LED, its next turn
  in_time_order(points);

  BlinkStats stats;
  const std::vector<Blink> blinks = average_blinks(points, {}, &stats);
  EXPECT_EQ(stats.points, 27u * 4 + 3);
  EXPECT_EQ(stats.blinks, 4u);
  EXPECT_EQ(stats.glitches, 1u);
  ASSERT_EQ(blinks.size(), 4u);
  struct Expected {
    int camera;
    Eigen::Vector2d pixel;
    double start_s;
  };
  const Expected expected[] = {{0, a, 0.0}, {1, c, 0.5 / kRate_hz}, {0, b, 0.2}, {0, a, 0.8}};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(blinks[i].camera_id, expected[i].camera) << i;
    EXPECT_EQ(blinks[i].samples, 27) << i;
    EXPECT_EQ(blinks[i].start_ns, at(expected[i].start_s)) << i;
    EXPECT_EQ(blinks[i].end_ns, at(expected[i].start_s + 26 / kRate_hz)) << i;
    // 27 samples of noise 0.5 px, rounded: the mean's error has a standard deviation of
    // 0.11 px per coordinate; a whole pixel's rounding would be off by up to 0.7 px.
    EXPECT_LT((blinks[i].pixel - expected[i].pixel).norm(), 0.4)
        << i << ": " << blinks[i].pixel.transpose();
  }
}

TEST(AverageBlinks, AGapAJumpOrASecondLedInTheSampleStartsANewBlink) {
  std::mt19937 random(5);
  std::vector<RawPoint> points;
  light(points, 0, {10, 10}, 0.0, 10, random, 0);
  light(points, 0, {10, 10}, 0.0 + 9 / kRate_hz + 0.04, 10, random, 0);  // after 40 ms dark
  light(points, 0, {14, 10}, 1.0, 10, random, 0);
  light(points, 0, {10, 10}, 1.0 + 10 / kRate_hz, 10, random, 0);  // 4 px away at once
  // Two LEDs 1 px apart in the same samples.
  light(points, 2, {300, 300}, 2.0, 10, random, 0);
  light(points, 2, {301, 300}, 2.0, 10, random, 0);
  in_time_order(points);
  const std::vector<Blink> blinks = average_blinks(points);
  ASSERT_EQ(blinks.size(), 6u);
  for (const Blink& blink : blinks) EXPECT_EQ(blink.samples, 10);
  EXPECT_EQ(blinks[2].pixel, Eigen::Vector2d(14, 10));
  EXPECT_EQ(blinks[3].pixel, Eigen::Vector2d(10, 10));
  EXPECT_EQ(blinks[4].pixel.y(), 300);
  EXPECT_EQ(blinks[4].pixel.x() + blinks[5].pixel.x(), 601);
  // Looser options join what the defaults split.
  EXPECT_EQ(average_blinks(points, {.pixel_tolerance = 5, .max_gap_s = 0.05}).size(), 4u);
  EXPECT_EQ(average_blinks(points, {.min_samples = 11}).size(), 0u);
  EXPECT_THROW(average_blinks(points, {.pixel_tolerance = 0}), std::invalid_argument);
}

// The board's pattern (0.2 s from LED to LED, 0.3 s more dark after LED 3: 1.1 s a cycle), as
// blinks of one camera that sees the LEDs at `corners`.
constexpr double kCycle_s = 4 * 0.2 + 0.3;

Blink blink_of(int camera, const Eigen::Vector2d& pixel, double start_s) {
  return {camera, pixel, at(start_s), at(start_s + 0.1), 27};
}

std::array<Eigen::Vector2d, 4> corners_of(double u, double v) {
  return {Eigen::Vector2d(u, v), Eigen::Vector2d(u + 40, v), Eigen::Vector2d(u + 40, v + 40),
          Eigen::Vector2d(u, v + 40)};
}

TEST(GroupShots, EachCameraCycleOfFourLedsIsAShotInLedOrder) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);  // blink starts, seconds
  std::vector<Blink> blinks;
  // camera2 sees cycles 0..3; camera3 comes in at LED 2 of the cycle before (a partial
  // cycle) and misses LED 1 of cycle 2. The board moves between cycles.
  for (int cycle = -1; cycle < 4; ++cycle) {
    const auto corners = corners_of(100 + 50 * cycle, 200);
    const auto corners3 = corners_of(600 - 50 * cycle, 300);
    for (int led = 0; led < 4; ++led) {
      // camera3's box samples 4 ms after camera2's: LED 0 sets the shots' order in time.
      const double start = cycle * kCycle_s + led * 0.2;
      const double start2 = start + (led == 0 ? 0 : jitter(random));
      const double start3 = start + (led == 0 ? 0.004 : jitter(random));
      if (cycle >= 0) blinks.push_back(blink_of(2, corners[led], start2));
      if (cycle == -1 && led < 2) continue;
      if (cycle == 2 && led == 1) continue;
      blinks.push_back(blink_of(3, corners3[led], start3));
    }
  }
  std::shuffle(blinks.begin(), blinks.end(), random);  // any order in

  ShotStats stats;
  const std::vector<BoardShot> shots = group_shots(blinks, {}, &stats);
  EXPECT_EQ(stats.shots, 7u);
  EXPECT_EQ(stats.dropped_cycles, 2u);
  EXPECT_EQ(stats.overlong_runs, 0u);
  EXPECT_EQ(stats.shots_per_camera, (std::map<int, size_t>{{2, 4}, {3, 3}}));
  ASSERT_EQ(shots.size(), 7u);
  // Ordered by time, then camera: cycles 0 and 1 (both), 2 (camera2 only), 3 (both).
  const int cameras[] = {2, 3, 2, 3, 2, 2, 3};
  const int cycles[] = {0, 0, 1, 1, 2, 3, 3};
  for (size_t i = 0; i < shots.size(); ++i) {
    EXPECT_EQ(shots[i].camera_id, cameras[i]) << i;
    EXPECT_NEAR(static_cast<double>(shots[i].stamp_ns - at(cycles[i] * kCycle_s)) * 1e-9, 0, 0.011)
        << i;
    const auto expected = cameras[i] == 2 ? corners_of(100 + 50 * cycles[i], 200)
                                          : corners_of(600 - 50 * cycles[i], 300);
    for (size_t led = 0; led < 4; ++led) EXPECT_EQ(shots[i].points[led], expected[led]) << i;
  }

  // Shots of one cycle share a frame: that is what ties the two cameras together.
  const auto frames = group_frames(shots);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].size(), 2u);
  EXPECT_EQ(frames[1].size(), 2u);
  ASSERT_EQ(frames[2].size(), 1u);
  EXPECT_EQ(frames[2][0].camera_id, 2);
  ASSERT_EQ(frames[3].size(), 2u);
  EXPECT_EQ(frames[3][0].camera_id, 2);
  EXPECT_EQ(frames[3][1].camera_id, 3);
}

TEST(GroupShots, ABoardWithoutThePauseGivesNoShots) {
  std::vector<Blink> blinks;
  const auto corners = corners_of(100, 100);
  for (int cycle = 0; cycle < 5; ++cycle) {
    for (int led = 0; led < 4; ++led)
      blinks.push_back(blink_of(0, corners[led], cycle * 0.8 + led * 0.2));
  }
  ShotStats stats;
  EXPECT_TRUE(group_shots(blinks, {}, &stats).empty());
  EXPECT_EQ(stats.overlong_runs, 1u);
  EXPECT_EQ(stats.dropped_cycles, 0u);
  // Told that the board does not pause, it still could not tell LED 0: the options refuse.
  EXPECT_THROW(group_shots(blinks, {.pause_s = 0}), std::invalid_argument);
  EXPECT_THROW(group_shots(blinks, {.pause_s = 0.2}), std::invalid_argument);
  EXPECT_THROW(group_shots(blinks, {.pause_s = 0.25}), std::invalid_argument);  // 0.05 off
  EXPECT_THROW(group_shots(blinks, {.tolerance_s = 0.05}), std::invalid_argument);
  EXPECT_NO_THROW(group_shots(blinks, {.pause_s = 0.5}));
}

TEST(WriteDataFile, TheConfigReadsBackEveryShotInItsFrame) {
  test::TempDir dir;
  std::vector<BoardShot> shots;
  for (int cycle = 0; cycle < 3; ++cycle) {
    for (int camera : {2, 3}) {
      if (cycle == 1 && camera == 3) continue;
      BoardShot shot;
      shot.camera_id = camera;
      shot.stamp_ns = at(cycle * kCycle_s + (camera == 3 ? 0.004 : 0));
      const auto corners = corners_of(100.12345 * camera + cycle, 50.5);
      std::copy(corners.begin(), corners.end(), shot.points.begin());
      shots.push_back(shot);
    }
  }
  write_data_file((dir / "board.json").string(), shots, {{2, "left"}});
  const std::string text = test::read_file(dir / "board.json");
  EXPECT_NE(
      text.find(R"({"camera":"left","stamp_ns":1700000000000000000,"points":[[200.247,50.5],)"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find(R"("camera":"camera3")"), std::string::npos) << text;

  const std::string config = R"({
    "transformations": [{"name": "board"}, {"name": "left_right", "global": true}],
    "cameras": [{"name": "left", "type": "pinhole", "value": [900, 900, 512, 384]},
                {"name": "camera3", "type": "pinhole", "value": [900, 900, 512, 384]}],
    "data": [
      {"type": "ir_data", "camera": "left", "transform_chain": [{"name": "board"}],
       "data_file": "board.json",
       "object": {"points": [[0, 0, 0], [0.25, 0, 0], [0.25, 0.25, 0], [0, 0.25, 0]]}},
      {"type": "ir_data", "camera": "camera3",
       "transform_chain": [{"name": "left_right"}, {"name": "board"}],
       "data_file": "board.json",
       "object": {"points": [[0, 0, 0], [0.25, 0, 0], [0.25, 0.25, 0], [0, 0.25, 0]]}}]})";
  const CalibrationConfig read =
      parse_calibration_config(config, "calib.json", dir.path().string());
  ASSERT_EQ(read.data[0].shots.size(), 3u);
  ASSERT_EQ(read.data[1].shots.size(), 2u);
  EXPECT_EQ(read.data[1].shots[0].frame, 0u);
  EXPECT_EQ(read.data[1].shots[1].frame, 2u);  // frame 1 is camera2's alone
  for (const Shot& shot : read.data[0].shots) {
    const auto corners = corners_of(200.2469 + static_cast<double>(shot.frame), 50.5);
    for (size_t i = 0; i < 4; ++i) EXPECT_NEAR((shot.points[i] - corners[i]).norm(), 0, 6e-4);
  }
  EXPECT_THROW(write_data_file((dir / "absent" / "board.json").string(), shots, {}),
               std::runtime_error);
}

// --- end to end: the simulated box, its candump log, the tool ----------------------------------

std::string tool() { return (test::bin_dir() / "mocap_calibration_record").string(); }

// Writes `duration_s` of the box seeing `scene` as a candump log.
void record_log(const std::string& path, pixart::PixartBoxSimulator& simulator, double duration_s) {
  std::ofstream log(path);
  pixart::CandumpRecordingOptions options;
  options.duration_s = duration_s;
  options.start_ns = kStart_ns;
  pixart::write_candump_recording(simulator, log, options);
}

pixart::Rig ceiling_rig() {
  return pixart::load_rig((test::source_dir() / "config/pixart/rig.yaml").string());
}

// The scene of config/pixart/scenes/calibration_board.yaml: a static board that camera2 and
// camera3 both see.
const char* const kBoardScene = "config/pixart/scenes/calibration_board.yaml";

// What a data file holds, read through the calibration's own reader as the solver will.
struct RecordedShots {
  std::map<std::string, std::vector<size_t>> frames;  // camera -> the frame of each of its shots
  std::vector<double> errors;  // of every point from the board's true projection, pixels
};

// Reads `dir`/board.json for camera2 and camera3 and checks every point against the true
// projection of the board of `simulator` (static: its pose at time 0) through the rig's
// cameras: within `tolerance_px`.
void check_projections(const test::TempDir& dir, const pixart::Rig& rig,
                       const pixart::PixartBoxSimulator& simulator, RecordedShots& recorded,
                       double tolerance_px = 0.5) {
  const std::string config = R"({
    "transformations": [{"name": "board"}, {"name": "camera2_camera3", "global": true}],
    "cameras": [{"name": "camera2", "type": "pinhole", "value": [1300, 1300, 511.5, 383.5]},
                {"name": "camera3", "type": "pinhole", "value": [1300, 1300, 511.5, 383.5]}],
    "data": [
      {"type": "ir_data", "camera": "camera2", "transform_chain": [{"name": "board"}],
       "data_file": "board.json",
       "object": {"points": [[-0.125, -0.125, 0], [0.125, -0.125, 0], [0.125, 0.125, 0],
                             [-0.125, 0.125, 0]]}},
      {"type": "ir_data", "camera": "camera3",
       "transform_chain": [{"name": "camera2_camera3"}, {"name": "board"}],
       "data_file": "board.json",
       "object": {"points": [[-0.125, -0.125, 0], [0.125, -0.125, 0], [0.125, 0.125, 0],
                             [-0.125, 0.125, 0]]}}]})";
  const CalibrationConfig read =
      parse_calibration_config(config, "calib.json", dir.path().string());
  for (const DataSpec& data : read.data) {
    const auto camera =
        std::find_if(rig.cameras.begin(), rig.cameras.end(),
                     [&](const pixart::RigCamera& c) { return c.name == data.camera; });
    ASSERT_NE(camera, rig.cameras.end());
    const Eigen::Isometry3d camera_from_world = camera->world_from_camera.inverse();
    std::vector<size_t>& frames = recorded.frames[data.camera];
    for (const Shot& shot : data.shots) {
      frames.push_back(shot.frame);
      for (size_t led = 0; led < 4; ++led) {
        const auto truth =
            camera->model->project(camera_from_world * simulator.led_position(0, led, 0));
        ASSERT_TRUE(truth);
        const double error = (shot.points[led] - *truth).norm();
        EXPECT_LT(error, tolerance_px)
            << data.camera << " frame " << shot.frame << " LED " << led << ": "
            << shot.points[led].transpose() << " vs " << truth->transpose();
        recorded.errors.push_back(error);
      }
    }
  }
}

double mean(const std::vector<double>& values) {
  double sum = 0;
  for (double value : values) sum += value;
  return sum / static_cast<double>(values.size());
}

TEST(CalibrationRecordTool, SimulatedBoardGivesItsTrueProjections) {
  test::TempDir dir;
  const pixart::Rig rig = ceiling_rig();
  pixart::PixartScene scene =
      pixart::load_pixart_scene((test::source_dir() / kBoardScene).string(), rig);
  pixart::PixartBoxSimulator simulator(rig, scene, {.noise_px = 0.5, .seed = 7});
  // Cycles start at 0, 1.1, 2.2, 3.3 and 4.4 s: four whole ones, and LED 0 of the fifth.
  record_log((dir / "board.log").string(), simulator, 4.5);

  const auto [code, output] = test::run_command(
      {tool(), "--candump", (dir / "board.log").string(), "--output", (dir / "board.json").string(),
       "--camera-names", "camera0,camera1,camera2,camera3"});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("8 shots (camera2 4, camera3 4), 2 incomplete cycles dropped, 0 runs "
                        "without the board's pause"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("4 frames -> " + (dir / "board.json").string()), std::string::npos)
      << output;

  RecordedShots recorded;
  ASSERT_NO_FATAL_FAILURE(check_projections(dir, rig, simulator, recorded));
  // Every cycle is a shot of both cameras, in one frame each.
  const std::vector<size_t> frames = {0, 1, 2, 3};
  EXPECT_EQ(recorded.frames,
            (std::map<std::string, std::vector<size_t>>{{"camera2", frames}, {"camera3", frames}}));
  ASSERT_EQ(recorded.errors.size(), 32u);
  // Averaging ~27 samples beats the sensor's whole pixels by far.
  EXPECT_LT(mean(recorded.errors), 0.2);
}

// --- live: the simulated box's SLCAN adaptor on a pseudo-terminal, the tool on the bus --------

using Steady = std::chrono::steady_clock;

// Starts pixart_box_sim in `host` as an SLCAN adaptor at `link`, with the board and the
// noise of the candump test. Returns (about) when its scene time began: the board's LED 0 of
// cycle k lights 1.1 k s later.
Steady::time_point start_box(ComponentHost& host, PluginLoader& loader, const std::string& link) {
  const std::string config = (test::source_dir() / "config" / "pixart").string();
  const Steady::time_point start = Steady::now();
  host.add(*loader.load("pixart_box_sim").factory,
           {.name = "box",
            .parameters = {{"rig", config + "/rig.yaml"},
                           {"scene", (test::source_dir() / kBoardScene).string()},
                           {"output", std::string("pty")},
                           {"device_link", link},
                           {"noise_px", 0.5},
                           {"seed", int64_t{7}}}});
  host.start();
  return start;
}

// The tool starts 0.3 s into the scene, when cycle 0's LED 0 is over (LED 0, 1, 2, 3 light
// 0.2 s apart, 0.1 s each; a cycle takes 1.1 s): cycle 0 is incomplete, and up to 0.7 s late
// the recording still starts before cycle 1 and never stops while an LED 3 is lit.
constexpr auto kToolStart = std::chrono::milliseconds(300);

// The data file of a live recording against the board's true projections: 1 to `max_shots`
// shots per camera. Live frames carry the adaptor's timestamps, so a tool descheduled for tens
// of milliseconds splits no blink; a box descheduled for longer than it catches up on (0.1 s)
// still can: a cycle lost, or a short blink's mean a little off. The log test above holds the
// points to 0.5 px; here a point in the wrong LED's place (tens of pixels) is what must fail.
void check_live_recording(const test::TempDir& dir, const std::string& output, size_t max_shots,
                          RecordedShots& recorded) {
  const pixart::Rig rig = ceiling_rig();
  const pixart::PixartBoxSimulator truth(
      rig, pixart::load_pixart_scene((test::source_dir() / kBoardScene).string(), rig));
  ASSERT_NO_FATAL_FAILURE(check_projections(dir, rig, truth, recorded, 2.0));
  ASSERT_EQ(recorded.frames.size(), 2u) << output;
  for (const auto& [camera, frames] : recorded.frames) {
    EXPECT_GE(frames.size(), 1u) << camera << "\n" << output;
    EXPECT_LE(frames.size(), max_shots) << camera << "\n" << output;
  }
}

TEST(CalibrationRecordTool, RecordsTheSimulatedBoxLiveOverSlcan) {
  test::TempDir dir;
  PluginLoader loader;
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  const std::string link = (dir / "adaptor").string();
  const Steady::time_point scene_start = start_box(host, loader, link);
  std::this_thread::sleep_until(scene_start + kToolStart);

  // 0.3 to 4.3 s: cycles 1, 2 and 3 (1.1 to 1.8, 2.2 to 2.9, 3.3 to 4.0 s).
  const auto [code, output] = test::run_command(
      {tool(), "--slcan", link, "--duration", "4", "--output", (dir / "board.json").string(),
       "--camera-names", "camera0,camera1,camera2,camera3"});
  host.stop();
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("recording slcan " + link + " at 1000000 bit/s for 4 s"), std::string::npos)
      << output;
  EXPECT_NE(output.find(link + ": "), std::string::npos) << output;
  EXPECT_NE(output.find(" frames -> " + (dir / "board.json").string()), std::string::npos)
      << output;

  RecordedShots recorded;
  ASSERT_NO_FATAL_FAILURE(check_live_recording(dir, output, 3, recorded));  // one per cycle
  EXPECT_LT(mean(recorded.errors), 0.3);
}

TEST(CalibrationRecordTool, CtrlCStopsTheLiveRecordingAndKeepsWhatItHolds) {
  test::TempDir dir;
  PluginLoader loader;
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  const std::string link = (dir / "adaptor").string();
  const Steady::time_point scene_start = start_box(host, loader, link);
  std::this_thread::sleep_until(scene_start + kToolStart);

  test::ChildProcess child(
      {tool(), "--slcan", link, "--duration", "60", "--output", (dir / "board.json").string()}, {},
      dir / "tool.out");
  ASSERT_TRUE(child.wait_for_output("recording slcan", std::chrono::seconds(10))) << child.output();
  // Ctrl-C at 3.45 s: after cycles 1 and 2 (1.1 to 1.8, 2.2 to 2.9 s), in cycle 3 (LED 3
  // lights at 3.9 s).
  std::this_thread::sleep_until(scene_start + std::chrono::milliseconds(3450));
  child.signal(SIGINT);
  ASSERT_EQ(child.wait(std::chrono::seconds(10)), 0) << child.output();
  host.stop();
  const std::string output = child.output();
  EXPECT_NE(output.find("stopped after "), std::string::npos) << output;
  EXPECT_NE(output.find(" frames -> " + (dir / "board.json").string()), std::string::npos)
      << output;

  RecordedShots recorded;
  ASSERT_NO_FATAL_FAILURE(check_live_recording(dir, output, 2, recorded));  // cycles 1 and 2
}

TEST(CalibrationRecordTool, SaysWhatIsWrongInOneLine) {
  test::TempDir dir;
  const std::string log = (dir / "board.log").string(), out = (dir / "board.json").string();
  {
    auto [code, output] = test::run_command({tool(), "--candump", log});
    EXPECT_EQ(code, 2);
    EXPECT_EQ(output.substr(0, output.find('\n')),
              "mocap_calibration_record: --output DATA.json is required");
  }
  {
    auto [code, output] =
        test::run_command({tool(), "--candump", log, "--output", out, "--base-id", "0x800"});
    EXPECT_EQ(code, 2);
    EXPECT_EQ(output.substr(0, output.find('\n')),
              "mocap_calibration_record: --base-id 0x800: expected a CAN ID, 0 to 0x7FF");
  }
  {
    auto [code, output] =
        test::run_command({tool(), "--candump", log, "--output", out, "--pause", "0.4"});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("--period 0.2 --pause 0.4: pause_s must lie more than two tolerances "
                          "from every whole number of periods"),
              std::string::npos)
        << output;
  }
  {
    auto [code, output] = test::run_command({tool(), "--candump", log, "--output", out});
    EXPECT_EQ(code, 1);
    EXPECT_EQ(output, "mocap_calibration_record: " + log +
                          ": cannot read the candump log: No such file or directory\n");
  }
  {
    test::write_file(log, "(1700000000.000000) can0 100#00\nnot a frame\n");
    auto [code, output] = test::run_command({tool(), "--candump", log, "--output", out});
    EXPECT_EQ(code, 1);
    EXPECT_EQ(output.find("mocap_calibration_record: " + log + ":2: "), 0u) << output;
  }
  {
    // The seed's board, without the pause: no cycle can be told apart, nothing is written.
    const pixart::Rig rig =
        pixart::load_rig((test::source_dir() / "config/pixart/rig.yaml").string());
    pixart::PixartScene scene = pixart::parse_pixart_scene(
        "calibration_boards:\n  - {name: board, trajectory: {type: static, x: 0.1, y: -0.5}}\n",
        "scene.yaml", rig);
    pixart::PixartBoxSimulator simulator(rig, scene);
    record_log(log, simulator, 3.3);
    auto [code, output] = test::run_command({tool(), "--candump", log, "--output", out});
    EXPECT_EQ(code, 1);
    EXPECT_NE(output.find("0 shots, 0 incomplete cycles dropped, 2 runs without the board's "
                          "pause"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("mocap_calibration_record: " + log +
                          ": no complete cycle of the board's four LEDs (does the board pause "
                          "0.3 s after LED 3? see --pause); nothing written"),
              std::string::npos)
        << output;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

TEST(CalibrationRecordTool, SaysWhatIsWrongWithASourceInOneLine) {
  test::TempDir dir;
  const std::string log = (dir / "board.log").string(), out = (dir / "board.json").string();
  auto first_line = [](const std::string& output) { return output.substr(0, output.find('\n')); };
  struct Case {
    std::vector<std::string> arguments;
    std::string message;
  };
  const Case cases[] = {
      {{"--output", out},
       "a source is required: --candump LOG, --slcan DEVICE or --socketcan IFACE"},
      {{"--candump", log, "--slcan", "/dev/ttyACM0", "--output", out},
       "--candump and --slcan: give exactly one of --candump, --slcan, --socketcan"},
      {{"--slcan", "/dev/ttyACM0", "--output", out}, "--slcan needs --duration SECONDS"},
      {{"--socketcan", "can0", "--output", out}, "--socketcan needs --duration SECONDS"},
      {{"--candump", log, "--duration", "4", "--output", out},
       "--duration is for --slcan and --socketcan; a log is read to its end"},
      {{"--socketcan", "can0", "--duration", "4", "--bitrate", "500000", "--output", out},
       "--bitrate is for --slcan only"},
      {{"--slcan", "/dev/ttyACM0", "--duration", "0", "--output", out},
       "--duration 0: expected a positive number of seconds"},
      {{"--slcan", "/dev/ttyACM0", "--duration", "4", "--bitrate", "300000", "--output", out},
       "--bitrate 300000: unsupported SLCAN bitrate 300000 bit/s; supported: 10000, 20000, "
       "50000, 100000, 125000, 250000, 500000, 800000, 1000000"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> argv = {tool()};
    argv.insert(argv.end(), c.arguments.begin(), c.arguments.end());
    auto [code, output] = test::run_command(argv);
    EXPECT_EQ(code, 2) << output;
    EXPECT_EQ(first_line(output), "mocap_calibration_record: " + c.message);
  }
  {
    const std::string device = (dir / "no_adaptor").string();
    auto [code, output] =
        test::run_command({tool(), "--slcan", device, "--duration", "4", "--output", out});
    EXPECT_EQ(code, 1);
    EXPECT_EQ(output, "mocap_calibration_record: cannot open serial device " + device +
                          ": No such file or directory\n");
  }
  {
    auto [code, output] = test::run_command(
        {tool(), "--socketcan", "nosuchcan0", "--duration", "4", "--output", out});
    EXPECT_EQ(code, 1);
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    EXPECT_EQ(output.find("mocap_calibration_record: "), 0u) << output;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace mocap::calibration
