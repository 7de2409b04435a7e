// From raw PixArt points to the calibration's data file (board_recording.hpp): blinks averaged
// from noisy samples, each camera's cycles of the 4-LED board grouped into shots with a dropped
// LED dropping its cycle, cameras of one cycle in one frame; and end to end, the simulated box's
// candump log through mocap_calibration_record to a data file that matches the board's true
// projections.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <mocap/calibration/board_recording.hpp>
#include <mocap/calibration/calibration_config.hpp>

#include "candump_recording.hpp"
#include "pixart_box_simulator.hpp"
#include "pixart_rig.hpp"
#include "pixart_scene.hpp"
#include "test_support.hpp"

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
    const Eigen::Vector2d measured = pixel + Eigen::Vector2d(noise(random), noise(random));
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

TEST(CalibrationRecordTool, SimulatedBoardGivesItsTrueProjections) {
  test::TempDir dir;
  const pixart::Rig rig =
      pixart::load_rig((test::source_dir() / "config/pixart/rig.yaml").string());
  pixart::PixartScene scene = pixart::load_pixart_scene(
      (test::source_dir() / "config/pixart/scenes/calibration_board.yaml").string(), rig);
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

  // Read through the calibration's own reader, as the solver will.
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
  double sum = 0;
  int count = 0;
  for (const DataSpec& data : read.data) {
    const auto camera =
        std::find_if(rig.cameras.begin(), rig.cameras.end(),
                     [&](const pixart::RigCamera& c) { return c.name == data.camera; });
    ASSERT_NE(camera, rig.cameras.end());
    const Eigen::Isometry3d camera_from_world = camera->world_from_camera.inverse();
    // Every cycle is a shot of both cameras, in one frame each.
    ASSERT_EQ(data.shots.size(), 4u) << data.camera;
    for (size_t s = 0; s < data.shots.size(); ++s) {
      const Shot& shot = data.shots[s];
      EXPECT_EQ(shot.frame, s) << data.camera;
      for (size_t led = 0; led < 4; ++led) {
        const auto truth =
            camera->model->project(camera_from_world * simulator.led_position(0, led, 0));
        ASSERT_TRUE(truth);
        const double error = (shot.points[led] - *truth).norm();
        EXPECT_LT(error, 0.5) << data.camera << " frame " << shot.frame << " LED " << led << ": "
                              << shot.points[led].transpose() << " vs " << truth->transpose();
        sum += error;
        ++count;
      }
    }
  }
  ASSERT_EQ(count, 32);
  // Averaging ~27 samples beats the sensor's whole pixels by far.
  EXPECT_LT(sum / count, 0.2);
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

}  // namespace
}  // namespace mocap::calibration
