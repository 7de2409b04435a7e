// The Ceres calibration (calibration_problem.hpp) on synthetic shots of the seed's 4-LED board
// (seed 002 §8.4: 0.262 x 0.12 m) seen by EUCM cameras of known intrinsics and placement, with
// Gaussian pixel noise: the solver must give the true values back, and say why when the data
// cannot determine them.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <mocap/calibration/calibration_config.hpp>
#include <mocap/calibration/calibration_problem.hpp>
#include <mocap/calibration/lens_models.hpp>

#include "test/calibration/synthetic_rig.hpp"

namespace mocap::calibration {
namespace {

constexpr double kDegree = M_PI / 180;

// A PixArt-like camera: 1024 x 768, EUCM.
const std::vector<double> kTrueCamera0 = {0.55, 1.1, 1203.0, 1204.0, 526.6, 389.0};
const std::vector<double> kTrueCamera1 = {0.50, 1.3, 1220.0, 1217.0, 522.6, 393.6};

const std::vector<Eigen::Vector3d> kBoard = {
    {0, 0.12, 0}, {0, 0, 0}, {0.262, 0, 0}, {0.262, 0.12, 0}};

std::optional<Eigen::Vector2d> project(const std::vector<double>& camera,
                                       const Eigen::Vector3d& point) {
  Eigen::Vector2d pixel;
  if (!eucm_project(camera.data(), point.data(), pixel.data())) return std::nullopt;
  if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > 1023 || pixel.y() > 767) return std::nullopt;
  return pixel;
}

// One data entry of `camera` seeing the boards through `camera_from_reference`, with noise.
DataSpec shots_of(const std::string& camera, const std::vector<double>& intrinsics,
                  const Eigen::Isometry3d& camera_from_reference,
                  const std::vector<Eigen::Isometry3d>& boards, double sigma_px,
                  std::mt19937& random, std::vector<ChainLink> chain) {
  std::normal_distribution<double> noise(0, sigma_px);
  DataSpec data;
  data.type = "ir_data";
  data.camera = camera;
  data.transform_chain = std::move(chain);
  data.image_width = 1024;
  data.image_height = 768;
  data.data_file = data.data_path = "synthetic.json";
  data.object_points = kBoard;
  data.corners = {0, 1, 2, 3};
  for (size_t frame = 0; frame < boards.size(); ++frame) {
    Shot shot;
    shot.frame = frame;
    for (const Eigen::Vector3d& led : kBoard) {
      auto pixel = project(intrinsics, camera_from_reference * boards[frame] * led);
      if (!pixel) break;
      shot.points.push_back(*pixel + test::draw_last_first<2>(noise, random));
    }
    if (shot.points.size() == kBoard.size()) data.shots.push_back(std::move(shot));
  }
  return data;
}

CalibrationConfig one_camera(int shots, double sigma_px, uint32_t seed = 1) {
  std::mt19937 random(seed);
  CalibrationConfig config;
  config.source = "synthetic";
  config.transformations.push_back({"board", false, false, false, 1.0, std::nullopt});
  // Started as the seed did (Code 8.2): far from the truth.
  config.cameras.push_back({"cam0", "eucm", false, {0.01, 1, 1175, 1175, 512, 384}});
  config.data.push_back(shots_of("cam0", kTrueCamera0, Eigen::Isometry3d::Identity(),
                                 synthetic::spread_board_poses(shots, random), sigma_px, random,
                                 {{"board", true}}));
  return config;
}

TEST(CalibrationProblem, RecoversOneCamerasIntrinsicsFromNoiselessShots) {
  CalibrationConfig config = one_camera(20, 0.0);
  ASSERT_EQ(config.data[0].shots.size(), 20u);
  CalibrationProblem problem(config);
  const CalibrationReport report = problem.solve();
  ASSERT_TRUE(report.converged) << report.summary();
  EXPECT_LT(report.rms_px, 1e-6);
  for (size_t i = 0; i < kTrueCamera0.size(); ++i) {
    EXPECT_NEAR(report.cameras[0].value[i], kTrueCamera0[i],
                1e-5 * std::abs(kTrueCamera0[i]) + 1e-6)
        << "parameter " << i << "\n"
        << report.summary();
  }
}

// Four points a shot say little (8 measurements for 6 unknowns of pose): with 0.1 px of noise
// the intrinsics come out to about 0.3 % (focal) and a few pixels (centre) from 60 shots, and
// the covariance must say so. The calibration benchmark tabulates accuracy against noise and
// shot count.
TEST(CalibrationProblem, WithNoiseTheErrorsLieWithinTheReportedUncertainty) {
  CalibrationConfig config = one_camera(60, 0.1, 7);
  CalibrationProblem problem(config);
  const CalibrationReport report = problem.solve();
  ASSERT_TRUE(report.converged) << report.summary();
  const std::vector<double>& value = report.cameras[0].value;
  const std::vector<double>& sigma = report.cameras[0].standard_deviation;
  ASSERT_EQ(sigma.size(), 6u) << report.covariance_problem;
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_LT(std::abs(value[i] - kTrueCamera0[i]), 4 * sigma[i]) << "parameter " << i << "\n"
                                                                  << report.summary();
  }
  EXPECT_LT(sigma[2] / kTrueCamera0[2], 0.005);  // the focal length to better than 0.5 %
  EXPECT_NEAR(value[2], kTrueCamera0[2], 0.01 * kTrueCamera0[2]);
  // The residual is the noise less what the fit absorbs: per point (two coordinates),
  // σ √(2 (m − p) / m) for m measurements and p unknowns (6 intrinsics, 6 per shot).
  const double m = 8.0 * static_cast<double>(config.data[0].shots.size());
  const double p = 6.0 + 6.0 * static_cast<double>(config.data[0].shots.size());
  EXPECT_NEAR(report.rms_px, 0.1 * std::sqrt(2 * (m - p) / m), 0.01);
  EXPECT_EQ(report.outliers(), 0u);
}

TEST(CalibrationProblem, TwoCamerasAndTheTransformBetweenThem) {
  std::mt19937 random(3);
  // Camera 1 is 0.3 m to the side of camera 0 and turned 10 degrees towards it, so both see
  // the boards (the ceiling rig's overlap zones).
  Eigen::Isometry3d camera1_from_camera0 = Eigen::Isometry3d::Identity();
  camera1_from_camera0.linear() =
      Eigen::AngleAxisd(10 * kDegree, Eigen::Vector3d(0.1, 1, 0.05).normalized())
          .toRotationMatrix();
  camera1_from_camera0.translation() = Eigen::Vector3d(-0.3, 0.02, 0.01);
  const std::vector<Eigen::Isometry3d> boards = synthetic::spread_board_poses(25, random);

  CalibrationConfig config;
  config.source = "synthetic";
  config.transformations.push_back({"board", false, false, false, 1.0, std::nullopt});
  // The seed's stereo set-up (Code 8.1): a global transform between the cameras with a prior,
  // here loose (stiffness 1e-3) and 3 cm and 3 degrees off.
  Eigen::Isometry3d prior = camera1_from_camera0;
  prior.translation() += Eigen::Vector3d(0.03, -0.02, 0.01);
  prior.rotate(Eigen::AngleAxisd(3 * kDegree, Eigen::Vector3d::UnitZ()));
  config.transformations.push_back({"xi10", true, false, true, 1e-3, prior});
  config.cameras.push_back({"cam0", "eucm", false, {0.01, 1, 1175, 1175, 512, 384}});
  config.cameras.push_back({"cam1", "eucm", false, {0.01, 1, 1175, 1175, 512, 384}});
  config.data.push_back(shots_of("cam0", kTrueCamera0, Eigen::Isometry3d::Identity(), boards, 0.1,
                                 random, {{"board", true}}));
  config.data.push_back(shots_of("cam1", kTrueCamera1, camera1_from_camera0, boards, 0.1, random,
                                 {{"xi10", true}, {"board", true}}));
  ASSERT_GE(config.data[1].shots.size(), 15u);

  CalibrationProblem problem(config);
  const CalibrationReport report = problem.solve();
  ASSERT_TRUE(report.converged) << report.summary();
  ASSERT_EQ(report.globals.size(), 1u);
  const Eigen::Isometry3d& found = report.globals[0].value;
  EXPECT_LT((found.translation() - camera1_from_camera0.translation()).norm(), 0.002)
      << report.summary();
  EXPECT_LT(Eigen::AngleAxisd(found.linear().transpose() * camera1_from_camera0.linear()).angle(),
            0.1 * kDegree);
  EXPECT_NEAR(report.cameras[1].value[2], kTrueCamera1[2], 0.005 * kTrueCamera1[2]);

  // The poses relative to camera 0: camera 1 where the transform puts it.
  const auto poses = problem.camera_poses("cam0");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_TRUE(poses[0].second.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(poses[1].second.isApprox(found, 1e-12));
  EXPECT_THROW(problem.camera_poses("cam9"), CalibrationError);
}

TEST(CalibrationProblem, TooFewShotsSaysWhy) {
  CalibrationConfig config = one_camera(3, 0.1);
  try {
    CalibrationProblem problem(config);
    ADD_FAILURE() << "no error";
  } catch (const CalibrationError& e) {
    EXPECT_EQ(std::string(e.what()),
              "synthetic: camera cam0: 3 shots are too few for its 6 intrinsics: each shot of 4 "
              "points adds 8 measurements and 6 unknowns (its board pose), so 4 shots are needed "
              "at least (seed 002 §2.3); more, from different angles, make the result reliable");
  }
}

TEST(CalibrationProblem, DegenerateShotsAreNamed) {
  CalibrationConfig config = one_camera(10, 0.1);
  Shot& shot = config.data[0].shots[4];
  for (Eigen::Vector2d& point : shot.points) point = shot.points[0];  // all in one spot
  try {
    CalibrationProblem problem(config);
    ADD_FAILURE() << "no error";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("data[0] (cam0), frame " + std::to_string(shot.frame)),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("on one line or in one spot"), std::string::npos);
  }
}

// Boards held square to an undistorted camera look the same if the focal length and every
// board's distance grow together, or the principal point and every board move across together:
// the solver may settle anywhere along those lines, and the report must say that the data leave
// the parameters undetermined rather than print standard deviations for them.
TEST(CalibrationProblem, UndeterminedParametersGetNoStandardDeviations) {
  const std::vector<double> truth = {900, 900, 512, 384, 0, 0, 0, 0, 0};  // no distortion
  std::mt19937 random(5);
  std::uniform_real_distribution<double> across(-0.4, 0.4), spin(-M_PI, M_PI);
  CalibrationConfig config;
  config.source = "synthetic";
  config.transformations.push_back({"board", false, false, false, 1.0, std::nullopt});
  config.cameras.push_back({"cam0", "pinhole", false, {880, 880, 500, 380}});
  DataSpec data;
  data.type = "ir_data";
  data.camera = "cam0";
  data.transform_chain = {{"board", true}};
  data.image_width = 1024;
  data.image_height = 768;
  data.data_file = data.data_path = "square.json";
  data.object_points = kBoard;
  data.corners = {0, 1, 2, 3};
  for (size_t frame = 0; frame < 12; ++frame) {
    const double heading = spin(random);  // last first (draw_order.hpp)
    const Eigen::Vector2d centre = test::draw_last_first<2>(across, random);
    const Eigen::Isometry3d board = Eigen::Translation3d(centre.x(), centre.y(), 1.5) *
                                    Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ());
    Shot shot;
    shot.frame = frame;
    for (const Eigen::Vector3d& led : kBoard) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(pinhole_project(truth.data(), (board * led).eval().data(), pixel.data()));
      shot.points.push_back(pixel);
    }
    data.shots.push_back(std::move(shot));
  }
  config.data.push_back(std::move(data));
  CalibrationProblem problem(config);
  const CalibrationReport report = problem.solve();
  EXPECT_TRUE(report.cameras[0].standard_deviation.empty()) << report.summary();
  EXPECT_NE(report.covariance_problem.find("not all determined by the data"), std::string::npos)
      << report.summary();
  // Any point on those lines fits the noiseless points exactly.
  EXPECT_LT(report.rms_px, 1e-6) << report.summary();
}

TEST(CalibrationProblem, ABadShotIsFlaggedAndARobustLossKeepsTheFit) {
  CalibrationConfig config = one_camera(20, 0.1, 11);
  config.data[0].shots[5].points[2] += Eigen::Vector2d(25, -18);  // a reflection, say
  CalibrationProblem plain(config);
  const CalibrationReport flagged = plain.solve();
  ASSERT_TRUE(flagged.converged);
  ASSERT_EQ(flagged.outliers(), 1u) << flagged.summary();
  CalibrationProblem robust(config, {.robust_scale_px = 0.5});
  const CalibrationReport report = robust.solve();
  ASSERT_TRUE(report.converged);
  EXPECT_NEAR(report.cameras[0].value[2], kTrueCamera0[2], 0.005 * kTrueCamera0[2])
      << report.summary();
  EXPECT_LT(std::abs(report.cameras[0].value[2] - kTrueCamera0[2]),
            std::abs(flagged.cameras[0].value[2] - kTrueCamera0[2]));
}

}  // namespace
}  // namespace mocap::calibration
