// The whole tracking pipeline through the runtime: synthetic camera -> fiducial tracker ->
// constellation tracker -> evaluator, in one process and across two over DDS; the per-frame
// stages (identifier -> pose estimator) that anyone may still run; and the components'
// handling of bad input.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fmt/format.h>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "test/test_support.hpp"

namespace mocap {
namespace {

std::string launcher() { return (test::bin_dir() / "mocap_launch").string(); }

std::string config(const std::string& file) {
  return (test::source_dir() / "config" / file).string();
}

// config/scenes/demo.yaml; the evaluator stops the run after `frames` frames. The camera keeps
// publishing until then, so frames sent before the other process's readers were discovered
// (lost, as with any volatile DDS topic) do not matter. A pipeline slower than the camera (a
// sanitized build on a busy machine) falls behind, its image queue growing: the evaluator waits
// for its estimates however late, so that only a frame the pipeline drops counts as lost.
// The stage that turns fiducials into poses: the constellation tracker, or the per-frame
// identifier and pose estimator.
enum class Stages { Tracker, PerFrame };

std::string pose_stages(Stages stages, const std::string& parameters) {
  if (stages == Stages::Tracker) {
    return R"(
      - plugin: constellation_tracker
        name: boards
        parameters:)" +
           parameters;
  }
  return R"(
      - plugin: constellation_identifier
        name: identifier
        parameters:)" +
         parameters + R"(
      - plugin: pose_estimator
        name: pose
        parameters:)" +
         parameters;
}

std::string pipeline_launch_file(
    const std::filesystem::path& summary, int frames, bool two_processes, int domain,
    const std::string& camera_file = config("cameras/synthetic_ir_1280x720.yaml"),
    Stages stages = Stages::Tracker) {
  std::string camera = fmt::format(R"(
      - plugin: synthetic_ir_camera
        name: camera
        parameters:
          scene: {}
          camera: {}
          rate_hz: 60.0
        qos:
          /camera/ir/image_raw: {{profile: reliable, depth: 1000}})",
                                   config("scenes/demo.yaml"), camera_file);
  std::string tracking = fmt::format(R"(
      - plugin: fiducial_tracker
        name: tracker
        qos:
          /camera/ir/image_raw: {{profile: reliable, depth: 1000}}{3}
      - plugin: pose_evaluator
        name: evaluator
        parameters:
          stop_after_frames: {1}
          max_lag_frames: 1000000
          summary_file: {2})",
                                     camera_file, frames, summary.string(),
                                     pose_stages(stages, "\n          camera: " + camera_file));
  std::string dds = fmt::format("dds:\n  enabled: {}\n  domain_id: {}\n",
                                two_processes ? "true" : "false", domain);
  if (two_processes) {
    return dds + "groups:\n  - name: camera\n    components:" + camera +
           "\n  - name: tracking\n    components:" + tracking + "\n";
  }
  return dds + "groups:\n  - name: mocap\n    components:" + camera + tracking + "\n";
}

void expect_accurate(const std::filesystem::path& summary_file, int frames,
                     bool with_velocities = true) {
  YAML::Node summary = YAML::LoadFile(summary_file.string());
  // The tracker's velocities reach the evaluator (their accuracy depends on the camera keeping
  // its rate, so tracking_accuracy_bench measures it offline); the per-frame stages have none.
  if (with_velocities) {
    EXPECT_GT(summary["velocity_errors"].as<int>(), frames);
  } else {
    EXPECT_EQ(summary["velocity_errors"].as<int>(), 0);
  }
  EXPECT_EQ(summary["frames"].as<int>(), frames);
  EXPECT_EQ(summary["frames_lost"].as<int>(), 0);
  // demo.yaml keeps both boards in view: two per frame.
  EXPECT_EQ(summary["expected"].as<int>(), 2 * frames);
  EXPECT_GE(summary["tracked"].as<double>(), 0.98 * 2 * frames);
  EXPECT_EQ(summary["false_identifications"].as<int>(), 0);
  EXPECT_LT(summary["position_error_median_m"].as<double>(), 0.002);
  EXPECT_LT(summary["orientation_error_median_deg"].as<double>(), 0.2);
}

// The pipeline through a wide EUCM lens (camera file as mocap_calibrate writes it): the
// synthetic camera renders through it, the identifier and the pose estimator unproject through
// it, all by the camera-model interface.
TEST(TrackingPipeline, ThroughAWideEucmLens) {
  test::TempDir dir;
  constexpr int kFrames = 40;
  calibration::CameraFile eucm;
  eucm.name = eucm.frame_id = "camera_ir_optical";
  eucm.model = calibration::make_camera_model("eucm", 1280, 720,
                                              std::vector<double>{0.6, 1.1, 760, 760, 641, 357});
  calibration::save_camera_file((dir / "eucm.yaml").string(), eucm);
  test::write_file(dir / "pipeline.yaml", pipeline_launch_file(dir / "summary.yaml", kFrames, false,
                                                               0, (dir / "eucm.yaml").string()));
  auto [code, output] = test::run_command({launcher(), (dir / "pipeline.yaml").string()}, {},
                                          std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  expect_accurate(dir / "summary.yaml", kFrames);
}

TEST(TrackingPipeline, InOneProcess) {
  test::TempDir dir;
  constexpr int kFrames = 60;
  // With the overlay saving a snapshot every frame.
  std::string overlay = fmt::format(R"(
      - plugin: overlay
        name: overlay
        parameters:
          snapshot_directory: {}
          snapshot_period_s: 0.01
)",
                                    (dir / "snapshots").string());
  test::write_file(dir / "pipeline.yaml",
                   pipeline_launch_file(dir / "summary.yaml", kFrames, false, 0) + overlay);
  auto [code, output] = test::run_command({launcher(), (dir / "pipeline.yaml").string()}, {},
                                          std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  expect_accurate(dir / "summary.yaml", kFrames);
  // The evaluator's final table.
  EXPECT_NE(output.find("| frames | lost | tracked |"), std::string::npos) << output;
  // The overlay's pictures: colour frames of the camera's size with the boards drawn on them.
  cv::Mat picture = cv::imread((dir / "snapshots" / "overlay_00000.png").string());
  ASSERT_FALSE(picture.empty()) << output;
  EXPECT_EQ(picture.cols, 1280);
  EXPECT_EQ(picture.rows, 720);
  cv::Mat green;
  cv::inRange(picture, cv::Scalar(0, 150, 0), cv::Scalar(60, 255, 60), green);
  EXPECT_GT(cv::countNonZero(green), 200);  // identified lines and their names
}

// The per-frame stages, for constellations from elsewhere or a comparison: each frame
// identified from scratch by constellation_identifier, posed by pose_estimator.
TEST(TrackingPipeline, PerFrameIdentifierAndPoseEstimator) {
  test::TempDir dir;
  constexpr int kFrames = 40;
  test::write_file(
      dir / "pipeline.yaml",
      pipeline_launch_file(dir / "summary.yaml", kFrames, false, 0,
                           config("cameras/synthetic_ir_1280x720.yaml"), Stages::PerFrame));
  auto [code, output] = test::run_command({launcher(), (dir / "pipeline.yaml").string()}, {},
                                          std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  expect_accurate(dir / "summary.yaml", kFrames, false);
}

TEST(TrackingPipeline, CameraAndTrackingInTwoProcesses) {
  test::TempDir dir;
  constexpr int kFrames = 60;
  test::write_file(dir / "pipeline.yaml", pipeline_launch_file(dir / "summary.yaml", kFrames, true,
                                                               test::test_domain(20)));
  auto [code, output] = test::run_command({launcher(), (dir / "pipeline.yaml").string()}, {},
                                          std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("[camera] "), std::string::npos) << output;
  EXPECT_NE(output.find("[tracking] "), std::string::npos) << output;
  expect_accurate(dir / "summary.yaml", kFrames);
}

// The seed's own board (Table 12) from its two CSV files, spinning in its plane at 1.2 m:
// every component reads the CSV database, the tracker tells its lines apart at 3 %.
TEST(TrackingPipeline, TheSeedBoardFromItsCsvFiles) {
  test::TempDir dir;
  test::write_file(dir / "scene.yaml", R"(
objects:
  - constellation: "4"
    trajectory: {type: spin, position: [0.05, 0.02, 1.2], rate_deg_s: 40, rpy_deg: [0, 20, -15]}
)");
  constexpr int kFrames = 40;
  std::string database =
      fmt::format("          database: {}\n          sub_constellations: {}\n",
                  config("seed_constellation.csv"), config("seed_sub_constellations.csv"));
  std::string file = fmt::format(R"(dds: {{enabled: false}}
groups:
  - name: mocap
    components:
      - plugin: synthetic_ir_camera
        name: camera
        parameters:
          scene: {0}
          rate_hz: 60.0
{1}        qos:
          /camera/ir/image_raw: {{profile: reliable, depth: 1000}}
      - plugin: fiducial_tracker
        name: tracker
        qos:
          /camera/ir/image_raw: {{profile: reliable, depth: 1000}}
      - plugin: constellation_tracker
        name: boards
        parameters:
{1}      - plugin: pose_evaluator
        name: evaluator
        parameters:
          stop_after_frames: {2}
          max_lag_frames: 1000000
          summary_file: {3}
)",
                                 (dir / "scene.yaml").string(), database, kFrames,
                                 (dir / "summary.yaml").string());
  test::write_file(dir / "seed.yaml", file);
  auto [code, output] =
      test::run_command({launcher(), (dir / "seed.yaml").string()}, {}, std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  YAML::Node summary = YAML::LoadFile((dir / "summary.yaml").string());
  EXPECT_EQ(summary["frames"].as<int>(), kFrames);
  EXPECT_EQ(summary["tracked"].as<int>(), kFrames);
  EXPECT_EQ(summary["false_identifications"].as<int>(), 0);
  EXPECT_LT(summary["position_error_median_m"].as<double>(), 0.002);
}

TEST(TrackingPipeline, ShippedLaunchFilesAreValid) {
  for (const char* file :
       {"mobile_mocap_demo.yaml", "mobile_mocap_two_process.yaml", "mobile_mocap_camera.yaml"}) {
    auto [code, output] = test::run_command(
        {launcher(), (test::source_dir() / "launch_yaml" / file).string(), "--check"});
    EXPECT_EQ(code, 0) << file << ": " << output;
  }
}

TEST(TrackingPipeline, BadConfigurationFilesAreOneLineErrors) {
  test::TempDir dir;
  test::write_file(dir / "camera.yaml", "image_width: 640\nimage_height: 480\n");
  test::write_file(dir / "db.csv", "Const_ID,1\nPts,L\nName,X_coord,Y_coord,Z_coord\nL,0,0,0\n");
  struct Case {
    std::string component, parameter, value, expected;
  };
  std::vector<Case> cases = {
      {"pose_estimator", "camera", (dir / "camera.yaml").string(),
       "camera.yaml:1: a camera file needs 'camera_matrix'"},
      {"constellation_identifier", "database", (dir / "db.csv").string(),
       "db.csv: line 'L' needs 4 point rows ',x,y,z', found 0"},
      {"pose_estimator", "database", (dir / "missing.yaml").string(),
       "missing.yaml: cannot read the constellation database"},
      {"constellation_tracker", "camera", (dir / "camera.yaml").string(),
       "camera.yaml:1: a camera file needs 'camera_matrix'"},
      {"constellation_tracker", "database", (dir / "db.csv").string(),
       "db.csv: line 'L' needs 4 point rows ',x,y,z', found 0"},
  };
  for (const Case& c : cases) {
    std::string file = fmt::format(
        "dds: {{enabled: false}}\ngroups:\n  - name: g\n    components:\n      - plugin: {}\n"
        "        name: under_test\n        parameters:\n          {}: {}\n",
        c.component, c.parameter, c.value);
    test::write_file(dir / "launch.yaml", file);
    auto [code, output] = test::run_command({launcher(), (dir / "launch.yaml").string()}, {},
                                            std::chrono::seconds(30));
    EXPECT_EQ(code, 1) << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << output;
  }
}

}  // namespace
}  // namespace mocap
