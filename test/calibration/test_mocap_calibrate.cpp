// mocap_calibrate as a user runs it: a configuration and its data file in, a report and camera
// files out; bad input a one-line error and a non-zero exit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <regex>

#include <fmt/format.h>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/calibration/lens_models.hpp>

#include "test/calibration/synthetic_rig.hpp"
#include "test/test_support.hpp"

namespace mocap::calibration {
namespace {

const std::vector<double> kTruth = {0.3, 1.2, 1210.0, 1206.0, 520.0, 380.0};

std::string calibrate() { return (test::bin_dir() / "mocap_calibrate").string(); }

// A data file of `shots` frames of the seed's 4-LED board seen by camera "cam0" (EUCM, kTruth),
// 0.1 px of noise, and the configuration that reads it.
void write_inputs(const test::TempDir& dir, int shots, const std::string& camera_type = "eucm") {
  const std::vector<Eigen::Vector3d> board = {
      {0, 0.12, 0}, {0, 0, 0}, {0.262, 0, 0}, {0.262, 0.12, 0}};
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0, 0.1);
  std::string frames;
  for (int made = 0; made < shots;) {
    const Eigen::Isometry3d pose = synthetic::spread_board_poses(1, random).front();
    std::vector<std::string> points;
    for (const Eigen::Vector3d& led : board) {
      const Eigen::Vector3d p = pose * led;
      Eigen::Vector2d pixel;
      if (!eucm_project(kTruth.data(), p.data(), pixel.data()) || pixel.x() < 0 || pixel.y() < 0 ||
          pixel.x() > 1023 || pixel.y() > 767) {
        break;
      }
      const Eigen::Vector2d measured = pixel + Eigen::Vector2d{noise(random), noise(random)};
      points.push_back(fmt::format("[{:.4f}, {:.4f}]", measured.x(), measured.y()));
    }
    if (points.size() != board.size()) continue;
    frames += fmt::format("{}[{{\"camera\": \"cam0\", \"points\": [{}]}}]\n", made ? "," : "",
                          fmt::join(points, ", "));
    ++made;
  }
  test::write_file(dir / "data.json", "[\n" + frames + "]\n");
  test::write_file(dir / "calib.json", fmt::format(R"({{
  "transformations": [{{"name": "xiCamBoard", "global": false, "constant": false, "prior": false}}],
  "cameras": [{{"name": "cam0", "type": "{}", "constant": false,
                "value": [0.01, 1, 1175, 1175, 512, 384]}}],
  "data": [{{"type": "ir_data", "camera": "cam0",
             "transform_chain": [{{"name": "xiCamBoard", "direct": true}}],
             "image_width": 1024, "image_height": 768, "data_file": "data.json",
             "object": {{"points": [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]]}}}}]
}})",
                                                   camera_type));
}

TEST(MocapCalibrate, SolvesAndWritesCameraFilesThatLoad) {
  test::TempDir dir;
  write_inputs(dir, 60);
  auto [code, output] = test::run_command(
      {calibrate(), (dir / "calib.json").string(), "--output", (dir / "out").string()});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("converged after"), std::string::npos) << output;
  EXPECT_NE(output.find("camera cam0 (eucm): 60 shots"), std::string::npos) << output;
  EXPECT_NE(output.find("wrote " + (dir / "out" / "cam0.yaml").string()), std::string::npos);
  const CameraFile file = load_camera_file((dir / "out" / "cam0.yaml").string());
  ASSERT_EQ(file.model->type(), "eucm");
  const std::vector<double> value = camera_parameters(*file.model);
  EXPECT_NEAR(value[2], kTruth[2], 0.01 * kTruth[2]) << output;
  EXPECT_NEAR(value[3], kTruth[3], 0.01 * kTruth[3]);
  ASSERT_TRUE(file.world_from_camera);  // the reference camera: the identity
  EXPECT_TRUE(file.world_from_camera->isApprox(Eigen::Isometry3d::Identity()));
}

TEST(MocapCalibrate, BadInputIsOneLineAndANonZeroExit) {
  test::TempDir dir;
  write_inputs(dir, 3);  // too few shots for 6 intrinsics
  auto [too_few, too_few_output] = test::run_command({calibrate(), (dir / "calib.json").string()});
  EXPECT_EQ(too_few, 1);
  EXPECT_NE(too_few_output.find("3 shots are too few for its 6 intrinsics"), std::string::npos)
      << too_few_output;
  EXPECT_NE(too_few_output.find("each shot of 4 points adds 8 measurements and 6 unknowns"),
            std::string::npos);

  write_inputs(dir, 10, "fisheye");
  auto [unknown, unknown_output] = test::run_command({calibrate(), (dir / "calib.json").string()});
  EXPECT_EQ(unknown, 1);
  EXPECT_TRUE(std::regex_search(
      unknown_output,
      std::regex(R"(calib\.json:\d+: cameras\[0\]\.type: unknown camera type 'fisheye')")))
      << unknown_output;

  test::write_file(dir / "broken.json", "{\"cameras\": [\n");
  auto [broken, broken_output] = test::run_command({calibrate(), (dir / "broken.json").string()});
  EXPECT_EQ(broken, 1);
  EXPECT_NE(broken_output.find("broken.json"), std::string::npos) << broken_output;

  auto [usage, usage_output] = test::run_command({calibrate(), "--images", dir.path().string()});
  EXPECT_EQ(usage, 2);
  EXPECT_NE(usage_output.find("--images needs --board and --square"), std::string::npos)
      << usage_output;
}

}  // namespace
}  // namespace mocap::calibration
