// The tracking volume as launch_yaml/volume_demo.yaml ships it: four camera processes (synthetic
// camera and fiducial tracker each, capturing together) and the compute process fusing them,
// evaluated against the simulator's truth; then the faults: a camera process killed and
// started again, and a camera bumped after calibration. Every run is held to the design's
// figures: no false identification ever (a pose more than 5 cm or 5 degrees off is a wrong
// answer handed to a robot: a frame the fusion cannot pose goes without), and 99.5 % of the
// body-frames tracked, or, for the part of a run with a camera away, the 98 % the design gives
// for one camera away (docs/targets.md). Real time: CI runs these two at a time, with nothing
// beside them but what it compiles in the scheduler's idle class (test/CMakeLists.txt, the
// realtime part).
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_file.hpp>

#include "test/test_support.hpp"

namespace mocap {
namespace {

std::string launch_file() {
  return (test::source_dir() / "launch_yaml" / "volume_demo.yaml").string();
}

std::map<std::string, std::string> environment(int slot) {
  return {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(slot))}};
}

// The evaluator's summary: tracked share, position error, frames without poses.
struct Figures {
  YAML::Node node;
  double tracked_share() const {
    return node["tracked"].as<double>() / std::max(1.0, node["expected"].as<double>());
  }
  // Frames fused without a live camera's data (late past the fusion's wait).
  double incomplete_share() const {
    return node["incomplete_frames"].as<double>() / std::max(1.0, node["frames"].as<double>());
  }
  // Poses more than 5 cm or 5 degrees off: a wrong answer handed to a robot.
  int false_identifications() const { return node["false_identifications"].as<int>(); }
};

// Also holds the frames fused without a late camera's data to a tenth: more is a deployment that
// does not keep up, or an assembly that waits too little.
Figures read_figures(const std::filesystem::path& summary) {
  SCOPED_TRACE(test::read_file(summary));
  Figures figures{YAML::LoadFile(summary.string())};
  EXPECT_LE(figures.incomplete_share(), 0.1) << test::read_file(summary);
  return figures;
}

// 20 s of the demo: the four boards posed in the world within a millimetre (median) in nearly
// every frame after the first second, no false identification, the cameras' residuals at the
// noise. In the first second the boards are identified as the camera processes come up (93 to
// 99 % of its body-frames on a quiet machine, every one after, eleven runs; in one CI run the
// processes came up slower and it alone took the run under 99.5 %); MultiHostFormSurvivesA-
// CrashAndALostLink counts it.
TEST(VolumeDemo, FourCameraProcessesFusedIntoAccuratePoses) {
  test::TempDir dir;
  const auto summary = dir / "summary.yaml";
  // What any DDS subscriber reads: each pose says how many cameras it rests on.
  test::ChildProcess echo(
      {(test::bin_dir() / "mocap_topic").string(), "echo", "/mocap/poses", "--count", "30"},
      environment(76), dir / "echo.log");
  // And every process's statuses: from the tenth second (each publishes once a second), fifteen
  // arrays, from every component of the launch file, all OK.
  test::ChildProcess diagnostics({"bash", "-c",
                                  fmt::format("sleep 10 && exec {} echo /diagnostics --count 15",
                                              (test::bin_dir() / "mocap_topic").string())},
                                 environment(76), dir / "diagnostics.log");
  // And the doctor, on the same seconds: all well.
  test::ChildProcess doctor(
      {"bash", "-c",
       fmt::format("sleep 10 && exec {} doctor {} --seconds 4",
                   (test::bin_dir() / "mocap_topic").string(), launch_file())},
      environment(76), dir / "doctor.log");
  auto [code, output] =
      test::run_command({(test::bin_dir() / "mocap_launch").string(), launch_file(), "--duration",
                         "20", "--set", "evaluator.summary_file=" + summary.string(), "--set",
                         "viewer.port=0", "--set", "evaluator.skip_first_s=1"},
                        environment(76), std::chrono::seconds(90));
  ASSERT_EQ(code, 0) << output;
  ASSERT_EQ(echo.wait(std::chrono::seconds(30)), 0) << echo.output();
  const std::string echoed = echo.output();
  const std::regex cameras_used(R"(cameras_used: (\d+))");
  int fused = 0, poses = 0;
  for (std::sregex_iterator it(echoed.begin(), echoed.end(), cameras_used), end; it != end; ++it) {
    ++poses;
    if (std::stoi((*it)[1]) >= 2) ++fused;
  }
  EXPECT_GE(poses, 30) << echoed;
  EXPECT_GE(fused, poses * 9 / 10) << echoed;
  ASSERT_EQ(diagnostics.wait(std::chrono::seconds(30)), 0) << diagnostics.output();
  std::map<std::string, int> levels;  // by status name: the worst seen
  for (const YAML::Node& array : YAML::LoadAll(diagnostics.output())) {
    for (const YAML::Node& status : array["status"]) {
      int& level = levels[status["name"].as<std::string>()];
      level = std::max(level, status["level"].as<int>());
      EXPECT_EQ(status["level"].as<int>(), 0) << YAML::Dump(status);
    }
  }
  std::vector<std::string> expected = {
      "compute",           "compute/fusion", "compute/ros_outputs",
      "compute/evaluator", "compute/viewer", "compute/diagnostics"};
  for (int c = 0; c < 4; ++c) {
    for (const std::string name :
         {"cam_{0}", "cam_{0}/cam_{0}", "cam_{0}/cam_{0}_fiducials", "cam_{0}/diagnostics"}) {
      expected.push_back(fmt::format(fmt::runtime(name), c));
    }
  }
  for (const std::string& name : expected) EXPECT_TRUE(levels.count(name)) << name;
  EXPECT_EQ(levels.size(), expected.size());
  EXPECT_EQ(doctor.wait(std::chrono::seconds(30)), 0) << doctor.output();
  EXPECT_NE(doctor.output().find("ok:      all well: "), std::string::npos) << doctor.output();
  const Figures figures = read_figures(summary);
  std::printf("%s", test::read_file(summary).c_str());
  EXPECT_GT(figures.node["frames"].as<int>(), 450) << output;  // 30 Hz, less the start
  EXPECT_GE(figures.tracked_share(), 0.995) << test::read_file(summary) << output;
  EXPECT_LT(figures.node["position_error_median_m"].as<double>(), 1e-3);
  EXPECT_LT(figures.node["orientation_error_median_deg"].as<double>(), 0.1);
  EXPECT_EQ(figures.false_identifications(), 0) << output;
  EXPECT_GT(figures.node["velocity_errors"].as<int>(), 1000);
  EXPECT_LT(figures.node["velocity_error_median_mps"].as<double>(), 0.05);
  EXPECT_EQ(output.find("DRIFTED"), std::string::npos) << output;
  EXPECT_EQ(output.find("has moved"), std::string::npos) << output;
  // Every board is in two cameras' views or more nearly all the time: none rests on one for
  // the 0.5 s that makes it news.
  EXPECT_EQ(output.find("seen by one camera only"), std::string::npos) << output;
}

// Camera cam_1's process is killed: the compute process says so and goes on fusing the other
// three, a pose array for every frame; started again, the camera is taken back. Tracked over
// the run: the design's figures, 98 % while cam_1 is away (from the kill until it is taken back,
// about 4 s) and 99.5 % the rest, each for its share of the run (about 11 s).
TEST(VolumeDemo, AKilledCameraIsReportedAndTakenBackWhenItReturns) {
  test::TempDir dir;
  const auto summary = dir / "summary.yaml";
  auto group = [&](const std::string& name, const std::string& log,
                   std::vector<std::string> more = {}) {
    std::vector<std::string> argv = {(test::bin_dir() / "mocap_launch").string(), launch_file(),
                                     "--group", name};
    argv.insert(argv.end(), more.begin(), more.end());
    return std::make_unique<test::ChildProcess>(argv, environment(77), dir / log);
  };
  auto compute = group("compute", "compute.log",
                       {"--set", "evaluator.summary_file=" + summary.string(), "--set",
                        "viewer.port=0", "--set", "evaluator.skip_first_s=1"});
  std::vector<std::unique_ptr<test::ChildProcess>> cameras;
  for (int c = 0; c < 4; ++c) {
    cameras.push_back(group("cam_" + std::to_string(c), "cam_" + std::to_string(c) + ".log"));
  }
  ASSERT_TRUE(compute->wait_for_output("camera cam_1: first fiducials", std::chrono::seconds(30)))
      << compute->output();
  const auto first_fiducials = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::seconds(4));

  const auto killed = std::chrono::steady_clock::now();
  cameras[1]->signal(SIGKILL);
  ASSERT_TRUE(compute->wait_for_output("camera cam_1 is silent", std::chrono::seconds(10)))
      << compute->output();
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const auto restarted = std::chrono::steady_clock::now();
  cameras[1] = group("cam_1", "cam_1_again.log");
  ASSERT_TRUE(compute->wait_for_output("camera cam_1 is back", std::chrono::seconds(20)))
      << compute->output();
  const auto back = std::chrono::steady_clock::now();
  const double back_after_s = std::chrono::duration<double>(back - restarted).count();
  std::printf("cam_1 taken back %.2f s after its process was started again\n", back_after_s);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const auto stopped = std::chrono::steady_clock::now();
  compute->signal(SIGTERM);
  // The evaluator counts from the second second on (the first is acquisition, as in the
  // calibrated test).
  const double away_share =
      std::chrono::duration<double>(back - killed).count() /
      (std::chrono::duration<double>(stopped - first_fiducials).count() - 1.0);
  const double tracked_bound = 0.98 * away_share + 0.995 * (1 - away_share);
  std::printf("cam_1 away %.0f %% of the run: %.2f %% tracked at least\n", 100 * away_share,
              100 * tracked_bound);
  ASSERT_EQ(compute->wait(std::chrono::seconds(20)), 0) << compute->output();

  const Figures figures = read_figures(summary);
  std::printf("%s", test::read_file(summary).c_str());
  // A pose array for every frame of the truth camera (cam_0), through the kill and the return.
  EXPECT_EQ(figures.node["frames_lost"].as<int>(), 0) << compute->output();
  EXPECT_GE(figures.tracked_share(), tracked_bound)
      << test::read_file(summary) << compute->output();
  EXPECT_EQ(figures.false_identifications(), 0) << compute->output();
  EXPECT_LT(figures.node["position_error_median_m"].as<double>(), 1e-3);
  EXPECT_EQ(compute->output().find("camera cam_0 is silent"), std::string::npos);
}

// The one-machine form as the README runs it: cam_1's process killed (SIGKILL), as a crash ends
// it. The launcher starts it again while the compute process fuses the other three, a pose
// array for every frame; the camera is fused again soon after its death. Tracked from the second
// second, as in FourCameraProcessesFusedIntoAccuratePoses: before, the boards are found as the
// camera processes come up, which under CI's load took a run under 99.5 % by itself (13
// body-frames of 2287 missed). By hand under the same load (a compiler in the idle class on each
// core), three runs lost 4, 5 and 0 body-frames, all in the first second, none across the kill.
TEST(VolumeDemo, ACameraKilledUnderTheLauncherIsRestartedAndFusedAgain) {
  test::TempDir dir;
  const auto summary = dir / "summary.yaml";
  test::ChildProcess launch(
      {(test::bin_dir() / "mocap_launch").string(), launch_file(), "--duration", "20", "--set",
       "evaluator.summary_file=" + summary.string(), "--set", "viewer.port=0", "--set",
       "evaluator.skip_first_s=1"},
      environment(22), dir / "launch.log");
  ASSERT_TRUE(launch.wait_for_output("camera cam_1: first fiducials", std::chrono::seconds(30)))
      << launch.output();
  std::this_thread::sleep_for(std::chrono::seconds(4));
  std::smatch pid;
  const std::string started = launch.output();
  ASSERT_TRUE(std::regex_search(started, pid, std::regex(R"(group 'cam_1' started \(pid (\d+)\))")))
      << started;
  const auto killed = std::chrono::steady_clock::now();
  ASSERT_EQ(::kill(std::stoi(pid[1]), SIGKILL), 0);
  ASSERT_TRUE(
      launch.wait_for_output("camera cam_1: fiducials again after", std::chrono::seconds(20)))
      << launch.output();
  const double back_after_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  std::printf("cam_1 fused again %.2f s after its process was killed\n", back_after_s);
  // Its diagnostics say it was restarted, once, and how the last process ended.
  auto [echo_code, echoed] = test::run_command(
      {(test::bin_dir() / "mocap_topic").string(), "echo", "/diagnostics", "--count", "15"},
      environment(22), std::chrono::seconds(30));
  ASSERT_EQ(echo_code, 0) << echoed;
  bool restart_seen = false;
  for (const YAML::Node& array : YAML::LoadAll(echoed)) {
    for (const YAML::Node& status : array["status"]) {
      if (status["name"].as<std::string>() != "cam_1") continue;
      for (const YAML::Node& pair : status["values"]) {
        if (pair["key"].as<std::string>() == "restarts") {
          EXPECT_EQ(pair["value"].as<std::string>(), "1") << echoed;
          restart_seen = true;
        }
      }
      EXPECT_EQ(status["level"].as<int>(), 1) << echoed;  // WARN, for a minute
      EXPECT_NE(status["message"].as<std::string>().find("the last process was killed by signal 9"),
                std::string::npos)
          << echoed;
    }
  }
  EXPECT_TRUE(restart_seen) << echoed;
  ASSERT_EQ(launch.wait(std::chrono::seconds(60)), 0) << launch.output();
  const std::string output = launch.output();
  EXPECT_NE(output.find("group 'cam_1' was killed by signal 9"), std::string::npos) << output;
  EXPECT_NE(output.find("group 'cam_1' is running again"), std::string::npos) << output;
  EXPECT_LE(back_after_s, 2.0) << output;
  const Figures figures = read_figures(summary);
  std::printf("%s", test::read_file(summary).c_str());
  EXPECT_EQ(figures.node["frames_lost"].as<int>(), 0) << output;
  EXPECT_GE(figures.tracked_share(), 0.995) << test::read_file(summary) << output;
  EXPECT_EQ(figures.false_identifications(), 0) << output;
}

// cam_1 knocked by half a degree after calibration: the simulator renders it from where it now
// points, the fusion still has its calibrated pose. It is named as moved, and poses stay right.
// Tracked: 98 %, the figure of a camera away, which cam_1 is once named. Until then, a board that
// cam_1 and one other camera see (their views disagree by 4 px, each agrees with itself) is posed
// from the other camera once cam_1's residuals, or the board's track that other cameras fused,
// mark cam_1 out; the other camera's view is then fitted without its far-off points, as a whole
// fit is. Without that, such a board went unposed for up to 2 s (97.2 % tracked in a CI run).
// Counted from the second second, as the other volume tests are: the first is the camera
// processes coming up (81 % in a CI run that then missed the bound with 97.7 % over the run,
// 99.1 % without it).
TEST(VolumeDemo, ABumpedCameraIsNamed) {
  test::TempDir dir;
  calibration::CameraFile bumped = calibration::load_camera_file(
      (test::source_dir() / "config" / "volume" / "cameras" / "cam_1.yaml").string());
  *bumped.world_from_camera =
      *bumped.world_from_camera * Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d::UnitY());
  const auto bumped_file = dir / "cam_1_bumped.yaml";
  calibration::save_camera_file(bumped_file.string(), bumped);
  const auto summary = dir / "summary.yaml";
  auto [code, output] =
      test::run_command({(test::bin_dir() / "mocap_launch").string(), launch_file(), "--duration",
                         "12", "--set", "cam_1.camera=" + bumped_file.string(), "--set",
                         "evaluator.summary_file=" + summary.string(), "--set", "viewer.port=0",
                         "--set", "evaluator.skip_first_s=1"},
                        environment(78), std::chrono::seconds(90));
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("camera cam_1 has moved since calibration"), std::string::npos) << output;
  for (const char* other : {"cam_0", "cam_2", "cam_3"}) {
    EXPECT_EQ(output.find(std::string("camera ") + other + " has moved"), std::string::npos)
        << output;
  }
  const Figures figures = read_figures(summary);
  std::printf("%s", test::read_file(summary).c_str());
  EXPECT_GE(figures.tracked_share(), 0.98) << test::read_file(summary) << output;
  EXPECT_EQ(figures.false_identifications(), 0) << output;
  EXPECT_LT(figures.node["position_error_median_m"].as<double>(), 1e-3);
}

// cam_3's host's clock set ahead by `shift` (Debian's faketime, preloaded into cam_3's process
// alone; never cam_0, whose stamps the evaluator's truth carries): the fusion measures the offset
// within 0.1 ms inside a second of cam_3's first message, refuses the camera by name, and keeps
// the volume with the other three as a run without cam_3 does: the 98 % the design gives for a
// camera away, and no false identification. Without the check, cam_3's stamps paired with other
// capture times (a 0.5 s shift: 5.9 % tracked, 2 false identifications).
void expect_a_shifted_camera_refused(double shift_s, int slot) {
  const std::filesystem::path faketime = "/usr/lib/x86_64-linux-gnu/faketime/libfaketimeMT.so.1";
  ASSERT_TRUE(std::filesystem::exists(faketime))
      << faketime << " is missing: scripts/install_deps.sh test installs faketime";
  test::TempDir dir;
  const auto summary = dir / "summary.yaml";
  auto group = [&](const std::string& name, std::vector<std::string> more,
                   std::map<std::string, std::string> env) {
    std::vector<std::string> argv = {(test::bin_dir() / "mocap_launch").string(), launch_file(),
                                     "--group", name};
    argv.insert(argv.end(), more.begin(), more.end());
    return std::make_unique<test::ChildProcess>(argv, env, dir / (name + ".log"));
  };
  std::map<std::string, std::string> shifted = environment(slot);
  shifted["LD_PRELOAD"] = faketime.string();
  shifted["FAKETIME"] = fmt::format("{:+.3f}", shift_s);
  shifted["FAKETIME_DONT_FAKE_MONOTONIC"] = "1";
  // Counted from the fifth second: with three cameras a board is found only once two of them
  // see five of its markers, later than with four (with another demo beside: 90 to 97 % of
  // the first two seconds' board-frames, and in one run 75 % and 83 % of the fourth and fifth
  // seconds', every one after).
  auto compute = group("compute",
                       {"--set", "evaluator.summary_file=" + summary.string(), "--set",
                        "viewer.port=0", "--set", "evaluator.skip_first_s=5"},
                       environment(slot));
  std::vector<std::unique_ptr<test::ChildProcess>> cameras;
  for (int c = 0; c < 3; ++c)
    cameras.push_back(group(fmt::format("cam_{}", c), {}, environment(slot)));
  cameras.push_back(group("cam_3", {}, shifted));
  ASSERT_TRUE(compute->wait_for_output("camera cam_3 refused", std::chrono::seconds(30)))
      << compute->output() << cameras[3]->output();
  std::this_thread::sleep_for(std::chrono::seconds(15));
  compute->signal(SIGTERM);
  ASSERT_EQ(compute->wait(std::chrono::seconds(20)), 0) << compute->output();
  const std::string output = compute->output();
  std::smatch measured;
  ASSERT_TRUE(std::regex_search(
      output, measured,
      std::regex(
          R"(camera cam_3: the clock of cam_3 on \S+ is ([-+0-9.]+) ms against this host's \(round trip ([0-9.]+) ms\), known ([0-9.]+) s after its first message)")))
      << output;
  std::printf("cam_3's clock measured %s ms (round trip %s ms), %s s after its first message\n",
              measured[1].str().c_str(), measured[2].str().c_str(), measured[3].str().c_str());
  EXPECT_NEAR(std::stod(measured[1]), shift_s * 1e3, 0.1) << output;
  EXPECT_LE(std::stod(measured[3]), 1.0) << output;
  EXPECT_NE(output.find(fmt::format("camera cam_3 refused: the clock of cam_3")), std::string::npos)
      << output;
  // The others measured and fused; cam_3 never.
  for (const char* other : {"cam_0", "cam_1", "cam_2"}) {
    EXPECT_NE(output.find(fmt::format("camera {}: first fiducials", other)), std::string::npos)
        << output;
    EXPECT_EQ(output.find(fmt::format("camera {} refused", other)), std::string::npos) << output;
  }
  EXPECT_EQ(output.find("camera cam_3: first fiducials"), std::string::npos) << output;
  const Figures figures = read_figures(summary);
  std::printf("%s", test::read_file(summary).c_str());
  EXPECT_GE(figures.tracked_share(), 0.98) << test::read_file(summary) << output;
  EXPECT_EQ(figures.false_identifications(), 0) << output;
  EXPECT_LT(figures.node["position_error_median_m"].as<double>(), 1e-3);
}

TEST(VolumeDemo, ACameraHostsClockFiveMillisecondsAheadIsRefusedByName) {
  expect_a_shifted_camera_refused(0.005, 85);
}

TEST(VolumeDemo, ACameraHostsClockHalfASecondAheadIsRefusedByName) {
  expect_a_shifted_camera_refused(0.5, 86);
}

// The occlusion target in the deployment: each camera's view of every board is cut by 40 % from
// a side of its own (left, right, top, bottom: a hand, a pole), so that no camera sees any board
// whole, yet once found (identification needs five of a board's markers in two cameras each,
// which takes up to a few seconds here) the boards are posed in nearly every frame.
TEST(VolumeDemo, BoardsNoCameraSeesWholeAreTracked) {
  test::TempDir dir;
  const std::string scene =
      test::read_file(test::source_dir() / "config" / "volume" / "scene.yaml");
  const char* const sides[] = {"left", "right", "top", "bottom"};
  std::vector<std::string> argv = {(test::bin_dir() / "mocap_launch").string(), launch_file(),
                                   "--duration", "20"};
  for (int c = 0; c < 4; ++c) {
    std::string occluded = scene;
    for (size_t at = occluded.find("  - constellation: "); at != std::string::npos;
         at = occluded.find("  - constellation: ", at + 1)) {
      const size_t line_end = occluded.find('\n', at) + 1;
      occluded.insert(line_end,
                      std::string("    occlusion: {fraction: 0.4, side: ") + sides[c] + "}\n");
    }
    const auto file = dir / ("scene_cam_" + std::to_string(c) + ".yaml");
    test::write_file(file, occluded);
    argv.insert(argv.end(), {"--set", "cam_" + std::to_string(c) + ".scene=" + file.string()});
  }
  const auto summary = dir / "summary.yaml";
  argv.insert(argv.end(),
              {"--set", "evaluator.summary_file=" + summary.string(), "--set", "viewer.port=0",
               "--set", "evaluator.min_visible_markers=0", "--set", "evaluator.skip_first_s=5"});
  auto [code, output] = test::run_command(argv, environment(79), std::chrono::seconds(90));
  ASSERT_EQ(code, 0) << output;
  const Figures figures = read_figures(summary);
  std::printf("%s", test::read_file(summary).c_str());
  EXPECT_GE(figures.tracked_share(), 0.995) << test::read_file(summary) << output;
  EXPECT_LT(figures.node["position_error_median_m"].as<double>(), 1e-3);
  EXPECT_EQ(figures.false_identifications(), 0) << output;
}

// The multi-host form: each camera on a network-namespace host of its own, the fusion on a
// fifth (scripts/netns_volume.sh). Poses reach the compute host; a camera host killed and one
// whose link goes down are reported silent while poses keep coming from the others, and are
// taken back when they return; over the run the boards are tracked: a camera is away for about
// 5 s of the 20 (98 % then, 99.5 % the rest): 99 %.
TEST(VolumeDemo, MultiHostFormSurvivesACrashAndALostLink) {
  auto [code, output] =
      test::run_command({(test::source_dir() / "scripts" / "netns_volume.sh").string(), "--faults",
                         "--duration", "20"},
                        environment(75), std::chrono::seconds(120));
  if (code == 77) GTEST_SKIP() << output;
  std::printf("%s", output.c_str());
  EXPECT_EQ(code, 0) << output;
  for (const char* phase : {"phase start: PASS", "phase kill_cam_1: PASS", "phase link_cam_2: PASS",
                            "phase measure: PASS", "result: PASS 4 of 4 phases"}) {
    EXPECT_NE(output.find(phase), std::string::npos) << phase << "\n" << output;
  }
  // The evaluator's row: | frames | lost | tracked % | position | orientation | velocity |
  // false ids | latency | robots | swaps | frames short of a camera | tracked in the others |
  // (those short of a late camera bounded to a tenth, as read_figures does).
  std::smatch row;
  ASSERT_TRUE(std::regex_search(
      output, row,
      std::regex(R"(measure: \| (\d+) \| (\d+) \| ([0-9.]+) % \|[^|]*\|[^|]*\|[^|]*\| (\d+) \|)"
                 R"([^|]*\|[^|]*\|[^|]*\| (\d+) \| ([0-9.]+) % \|)")))
      << output;
  EXPECT_GT(std::stoi(row[1]), 400) << output;
  EXPECT_EQ(std::stoi(row[2]), 0) << output;
  EXPECT_GE(std::stod(row[3]), 99.0) << output;
  EXPECT_LE(std::stod(row[5]), 0.1 * std::stod(row[1])) << output;
  EXPECT_EQ(std::stoi(row[4]), 0) << output;
}

// Calibrated from data (scripts/calibrate_volume.sh): the board carried through the volume for
// 30 s and laid on the floor at five marks, twice at each, for 2 s, recorded into bags and
// solved; every camera within 0.5 mm and 0.01 degrees of where the simulator put it (the
// issue's bound is 2 mm and 0.05 degrees), each board's centre within 0.3 mm of its mark. The
// page shows the solve and its report, and mocap_volume_calibrate on the same recordings prints
// the same figures as the script and the page (test/viewer/browser_check.mjs reads them). The
// demo then runs on the files it wrote: poses within 0.15 mm (median; 0.03 mm on the true
// cameras). Live, the wave's 30 s fall anywhere on its 120 s path, and how well they tie the
// cameras together varies from run to run (0.07 mm measured once); the issue's 20 % is asserted
// on rendered sessions (VolumeAccuracy.CamerasCalibratedFromRenderedImagesFuseWithin...).
TEST(VolumeDemo, CalibratedFromARecordedSessionAndTrackedThroughIt) {
  test::TempDir dir;
  // A user's own files in the output folder, named as the script's bags begin: left alone.
  test::write_file(dir / "floor_plan.txt", "the lab's floor\n");
  std::filesystem::create_directories(dir / "floor_notes");
  test::write_file(dir / "floor_notes" / "marks.txt", "taped on Monday\n");
  const int port = test::free_port();
  test::ChildProcess session(
      {(test::source_dir() / "scripts" / "calibrate_volume.sh").string(), dir.path().string(),
       "--wave", "30", "--floor", "2", "--marks", "0,0 1,0 0,1 -1,0 0,-1", "--viewer-port",
       std::to_string(port), "--hold", "300"},
      environment(74), dir / "session.log");
  ASSERT_TRUE(session.wait_for_output("calibrate_volume: solving", std::chrono::seconds(150)))
      << session.output();
  // The page, from the solve's start: its progress, then the report; each figure printed as the
  // tool prints it (PAGE lines).
  std::filesystem::path screenshot = dir / "calibration.png";
  if (const char* wanted = std::getenv("MOCAP_VIEWER_SCREENSHOT")) screenshot = wanted;
  auto [page_code, page] = test::run_command(
      {"node", (test::source_dir() / "test" / "viewer" / "browser_check.mjs").string(),
       fmt::format("http://127.0.0.1:{}/", port), screenshot.string(), "--calibration-result", "4"},
      {}, std::chrono::seconds(200));
  session.signal(SIGTERM);  // ends the hold: the page has what it needs
  ASSERT_EQ(session.wait(std::chrono::seconds(60)), 0) << session.output();
  const std::string output = session.output();
  std::printf("%s%s", output.c_str(), page.c_str());
  EXPECT_EQ(page_code, 0) << page;
  EXPECT_NE(page.find("PASS calibration result: 4 cameras"), std::string::npos) << page;
  // Each camera's coverage of the wave, as the coverage component saw it live and as the solver
  // reads it from the bag.
  for (const char* camera : {"cam_0", "cam_1", "cam_2", "cam_3"}) {
    EXPECT_NE(output.find(fmt::format("calibrate_volume: coverage {} [", camera)),
              std::string::npos)
        << output;
    EXPECT_NE(output.find(fmt::format("waved coverage: {} [", camera)), std::string::npos)
        << output;
  }
  EXPECT_NE(output.find("calibrate_volume: solve [====================] 100 % done"),
            std::string::npos)
      << output;
  const std::regex line(R"((cam_\d): at .* m; ([0-9.]+) mm and ([0-9.]+) deg from the input)");
  int cameras = 0;
  for (std::sregex_iterator it(output.begin(), output.end(), line), end; it != end; ++it) {
    ++cameras;
    EXPECT_LT(std::stod((*it)[2]), 0.5) << (*it)[0];
    EXPECT_LT(std::stod((*it)[3]), 0.01) << (*it)[0];
  }
  EXPECT_EQ(cameras, 4) << output;
  const std::regex mark(R"(floor at \(.*\): the board seen by (\d) cameras.*; ([0-9.]+) mm from)");
  int marks = 0;
  for (std::sregex_iterator it(output.begin(), output.end(), mark), end; it != end; ++it) {
    ++marks;
    EXPECT_GE(std::stoi((*it)[1]), 2) << (*it)[0];
    EXPECT_LT(std::stod((*it)[2]), 0.3) << (*it)[0];
  }
  EXPECT_EQ(marks, 10) << output;  // each laid twice, the second time turned

  // mocap_volume_calibrate on the same recordings: its report is the script's (the solve
  // component's) and the page's, figure for figure.
  std::vector<std::string> tool = {(test::bin_dir() / "mocap_volume_calibrate").string(), "--waved",
                                   (dir / "waved").string()};
  for (const char* at : {"0_0", "1_0", "0_1", "-1_0", "0_-1"}) {
    std::string xy = at;
    std::replace(xy.begin(), xy.end(), '_', ',');
    for (const char* turned : {"", "_turned"}) {
      tool.insert(tool.end(),
                  {"--floor", (dir / fmt::format("floor_{}{}", at, turned)).string() + ":" + xy});
    }
  }
  tool.insert(tool.end(), {"--output", (dir / "by_the_tool").string()});
  for (int c = 0; c < 4; ++c) {
    tool.push_back(
        (test::source_dir() / "config" / "volume" / "cameras" / fmt::format("cam_{}.yaml", c))
            .string());
  }
  auto [tool_code, printed] = test::run_command(tool, {}, std::chrono::seconds(120));
  ASSERT_EQ(tool_code, 0) << printed;
  std::istringstream lines(printed);
  int compared = 0;
  for (std::string tool_line; std::getline(lines, tool_line);) {
    const bool camera = tool_line.starts_with("cam_"), floor = tool_line.starts_with("floor at");
    if (!camera && !floor && !tool_line.starts_with("waved") &&
        !tool_line.starts_with(dir.path().string())) {
      continue;  // its progress lines
    }
    ++compared;
    // The files written differ (the tool's into by_the_tool/): the rest is the script's line.
    const std::string figures = tool_line.substr(0, tool_line.find(" -> "));
    EXPECT_NE(output.find(figures), std::string::npos) << figures << "\n" << output;
    if (camera || floor) {
      EXPECT_NE(page.find("PAGE " + figures + "\n"), std::string::npos) << figures << "\n" << page;
    }
  }
  // Each bag's sightings, the wave's coverage a camera, the solve, each placement, each camera.
  EXPECT_EQ(compared, 11 + 4 + 1 + 10 + 4) << printed;
  std::smatch solve;
  ASSERT_TRUE(std::regex_search(printed, solve,
                                std::regex(R"(waved: (\d+) capture times .*; RMS reprojection )"
                                           R"(error ([0-9.]+) px over (\d+) points \((\d+) iter)")))
      << printed;
  EXPECT_NE(page.find(fmt::format("PAGE waved: {} capture times; RMS {} px over {} points ({} "
                                  "iterations)",
                                  solve[1].str(), solve[2].str(), solve[3].str(), solve[4].str())),
            std::string::npos)
      << page;

  EXPECT_EQ(test::read_file(dir / "floor_plan.txt"), "the lab's floor\n");
  EXPECT_EQ(test::read_file(dir / "floor_notes" / "marks.txt"), "taped on Monday\n");

  std::string files = "[";
  for (int c = 0; c < 4; ++c) {
    files += (c ? ", " : "") + (dir / "cameras" / ("cam_" + std::to_string(c) + ".yaml")).string();
  }
  files += "]";
  const auto summary = dir / "summary.yaml";
  auto [demo_code, demo] = test::run_command(
      {(test::bin_dir() / "mocap_launch").string(), launch_file(), "--duration", "12", "--set",
       "fusion.cameras=" + files, "--set", "evaluator.summary_file=" + summary.string(), "--set",
       "viewer.port=0", "--set", "evaluator.skip_first_s=1"},
      environment(74), std::chrono::seconds(90));
  ASSERT_EQ(demo_code, 0) << demo;
  const Figures figures = read_figures(summary);
  std::printf("on the calibrated cameras:\n%s", test::read_file(summary).c_str());
  // Tracked from the second second on: in the first, boards are identified as they come into
  // two cameras' views (90 % of that second's body-frames; every one after), which in a 12 s
  // run alone weighs 0.8 %. MultiHostFormSurvivesACrashAndALostLink counts it.
  EXPECT_GE(figures.tracked_share(), 0.995) << test::read_file(summary) << demo;
  EXPECT_EQ(figures.false_identifications(), 0) << demo;
  EXPECT_LT(figures.node["position_error_median_m"].as<double>(), 0.15e-3);
  EXPECT_LT(figures.node["orientation_error_median_deg"].as<double>(), 0.1);
}

// The swarm demo as the README runs it (launch_yaml/swarm_demo.yaml: 100 robots, 50 of them
// identical quadrotors, 8 camera processes sending centroids at 240 Hz, pairs crossing 5 cm
// apart every 2 s and two exchanging places every 4 s), 20 s of it: every robot under its own
// name (no identity swap, no false identification), each where it is to a tenth of a millimetre
// and a fifth of a degree (the issue's figures). Tracked: 99.93 % and 99.97 % in 60 s runs on a
// quiet machine; here beside another real-time test, at least 99 % (swarm_bench holds the
// scenes to 99.9 % with no clock in the way).
TEST(VolumeDemo, TheSwarmDemosHundredRobotsKeepTheirNames) {
  test::TempDir dir;
  const auto summary = dir / "summary.yaml";
  auto [code, output] =
      test::run_command({(test::bin_dir() / "mocap_launch").string(),
                         (test::source_dir() / "launch_yaml" / "swarm_demo.yaml").string(),
                         "--duration", "20", "--set", "evaluator.summary_file=" + summary.string(),
                         "--set", "viewer.port=0", "--set", "evaluator.skip_first_s=1"},
                        environment(84), std::chrono::seconds(90));
  ASSERT_EQ(code, 0) << output;
  const Figures figures = read_figures(summary);
  std::printf("%s", test::read_file(summary).c_str());
  EXPECT_EQ(figures.node["robots"].as<int>(), 100);
  EXPECT_GT(figures.node["frames"].as<int>(), 4000) << output;  // 240 Hz, less the start
  EXPECT_EQ(figures.node["identity_swaps"].as<int>(), 0) << output;
  EXPECT_EQ(figures.false_identifications(), 0) << output;
  EXPECT_GE(figures.tracked_share(), 0.99) << test::read_file(summary) << output;
  EXPECT_LE(figures.node["position_error_median_m"].as<double>(), 1e-4);
  EXPECT_LE(figures.node["orientation_error_median_deg"].as<double>(), 0.2);
}

// Eight seconds of the demo recorded as a user would (mocap_bag record /mocap/poses
// /mocap/markers) and exported in every format: each export read back by a reader written from
// its format's description holds every pose and marker of the bag, read by MCAP's and Foxglove's
// own readers, at its frame, to 1 µm or the float, and gaps exactly where the bag has nothing
// (test/bag/export_compare.mjs).
TEST(VolumeDemo, ARecordingsExportsHoldEveryPoseAndMarkerOfIt) {
  test::TempDir dir;
  test::ChildProcess graph({(test::bin_dir() / "mocap_launch").string(), launch_file(),
                            "--duration", "14", "--set", "viewer.port=0"},
                           environment(63), dir / "graph.log");
  ASSERT_TRUE(graph.wait_for_output("[evaluator]", std::chrono::seconds(60))) << graph.output();
  const std::string mocap_bag = (test::bin_dir() / "mocap_bag").string();
  const auto bag = dir / "demo";
  auto [code, output] = test::run_command({mocap_bag, "record", "-o", bag.string(), "/mocap/poses",
                                           "/mocap/markers", "--duration", "8"},
                                          environment(63), std::chrono::seconds(60));
  ASSERT_EQ(code, 0) << output;
  const std::string bodies = (test::source_dir() / "config" / "volume" / "bodies.yaml").string();
  for (const std::string format : {"c3d", "trc", "csv", "tum"}) {
    const bool tum = format == "tum";
    std::vector<std::string> arguments = {mocap_bag,
                                          "export",
                                          bag.string(),
                                          "--format",
                                          format,
                                          "-o",
                                          (dir / (tum ? "demo_tum" : "demo." + format)).string()};
    if (!tum) arguments.insert(arguments.end(), {"--markers", "--bodies-file", bodies});
    std::tie(code, output) = test::run_command(arguments, {}, std::chrono::seconds(60));
    ASSERT_EQ(code, 0) << format << ": " << output;
  }
  std::filesystem::path mcap;
  for (const auto& entry : std::filesystem::directory_iterator(bag)) {
    if (entry.path().extension() == ".mcap") mcap = entry.path();
  }
  std::tie(code, output) = test::run_command(
      {"node", (test::source_dir() / "test" / "bag" / "export_compare.mjs").string(), mcap.string(),
       "board_1,board_2,board_3,board_4", (dir / "demo").string()},
      {}, std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  std::printf("%s", output.c_str());
  // A row per format, each of the recording's 8 s at 30 frames/s.
  const std::regex row(R"(\| (c3d|trc|csv|tum) \| (\d+) \| (\d+) \|)");
  int rows = 0;
  for (auto it = std::sregex_iterator(output.begin(), output.end(), row);
       it != std::sregex_iterator(); ++it, ++rows) {
    EXPECT_GE(std::stoi((*it)[2]), 200) << output;
    EXPECT_GE(std::stoi((*it)[3]), 200 * 4) << output;
  }
  EXPECT_EQ(rows, 4) << output;
}

}  // namespace
}  // namespace mocap
