// Line search, identification and planar pose on projected constellations: the geometry of
// the pipeline without images (test_tracking_pipeline.cpp runs it on rendered images).
#include <gtest/gtest.h>

#include <optional>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/calibration/pinhole_camera.hpp>

#include "test/draw_order.hpp"
#include "test/test_support.hpp"
#include "tracking/constellation_identifier/constellation_identifier.hpp"
#include "tracking/constellation_identifier/line_search.hpp"
#include "tracking/pose_estimator/constellation_pose.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"

namespace mocap::constellations {
namespace {

using calibration::PinholeCamera;
using calibration::PinholeIntrinsics;

ConstellationDatabase shipped_database() {
  return load_database(test::source_dir().string() + "/config/constellations.yaml");
}

PinholeCamera test_camera() {
  PinholeIntrinsics k;
  k.fx = k.fy = 914;
  k.cx = 639.5;
  k.cy = 359.5;
  k.distortion = {-0.05, 0.01, 0, 0, 0};
  return PinholeCamera(1280, 720, k);
}

// A board at `distance` along the optical axis, turned by yaw/pitch (degrees) away from
// facing the camera and rolled about its normal.
Eigen::Isometry3d board_pose(Eigen::Vector3d position, double roll, double pitch, double yaw) {
  auto rad = [](double d) { return d * M_PI / 180; };
  // Facing the camera: board z towards the camera (camera -z), board x along camera x.
  Eigen::Matrix3d facing;
  facing << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(rad(yaw), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rad(pitch), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix() *
                  facing *
                  Eigen::AngleAxisd(rad(roll), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = position;
  return pose;
}

struct Projected {
  std::vector<Eigen::Vector2d> pixels;  // shuffled with distractors
  std::vector<int> truth;               // per model point: index in pixels, -1 if outside
};

Projected project(const calibration::CameraModel& camera, const ConstellationModel& model,
                  const Eigen::Isometry3d& pose, double noise_px, std::mt19937& random,
                  std::vector<Eigen::Vector2d> pixels = {}) {
  std::normal_distribution<double> noise(0, noise_px);
  Projected out;
  out.pixels = std::move(pixels);
  for (const auto& point : model.points) {
    auto pixel = camera.project(pose * point);
    if (!pixel || !camera.in_image(*pixel)) {
      out.truth.push_back(-1);
      continue;
    }
    out.truth.push_back(static_cast<int>(out.pixels.size()));
    out.pixels.push_back(*pixel + test::draw_last_first<2>(noise, random));
  }
  return out;
}

// Pixels without distortion, as the identifier plugin feeds them (focal length units).
std::vector<Eigen::Vector2d> ideal(const calibration::CameraModel& camera,
                                   const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : pixels)
    out.push_back(camera.focal_length_px() * camera.unproject(p)->head<2>());
  return out;
}

TEST(LineSearch, FindsEachGroupOnceWithSharedPointsAndStrays) {
  // Two lines sharing the corner (0, 0), a stray point near one line but beyond tolerance,
  // and a line of 5.
  std::vector<Eigen::Vector2d> points = {{0, 0},    {10, 0},   {25, 0},   {40, 0},  // 0-3
                                         {0, 10},   {0, 30},   {0, 40},             // 4-6
                                         {17, 3},                                   // 7
                                         {300, 50}, {310, 60}, {320, 70}, {330, 80},
                                         {340, 90}};  // 8-12
  auto groups = find_collinear_groups(points, {});
  ASSERT_EQ(groups.size(), 3u);
  std::vector<std::vector<int>> found;
  for (auto& g : groups) {
    std::vector<int> sorted = g.points;
    std::sort(sorted.begin(), sorted.end());
    found.push_back(sorted);
  }
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found[0], (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(found[1], (std::vector<int>{0, 4, 5, 6}));
  EXPECT_EQ(found[2], (std::vector<int>{8, 9, 10, 11, 12}));
  for (auto& g : groups) {
    if (g.points.size() == 5) {
      // In order along the line, whichever end comes first.
      bool forward = g.points.front() == 8;
      for (size_t k = 0; k < 5; ++k) EXPECT_EQ(g.points[k], forward ? 8 + k : 12 - k);
    }
  }
}

TEST(LineSearch, ToleranceDecidesNearCollinearPoints) {
  std::vector<Eigen::Vector2d> points = {{0, 0}, {10, 1.2}, {20, -1.2}, {30, 0}};
  LineSearchOptions tight;
  tight.tolerance_px = 1.0;
  EXPECT_TRUE(find_collinear_groups(points, tight).empty());
  LineSearchOptions loose;
  loose.tolerance_px = 1.5;
  EXPECT_EQ(find_collinear_groups(points, loose).size(), 1u);
}

TEST(LineSearch, NoiseAndManyPoints) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> uniform(0, 1000);
  std::normal_distribution<double> noise(0, 0.2);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 100; ++i) points.push_back(test::draw_last_first<2>(uniform, random));
  // A planted line of 4 with 0.2 px noise.
  for (double t : {0.0, 0.3, 0.55, 1.0}) {
    const Eigen::Vector2d error = test::draw_last_first<2>(noise, random);
    points.push_back(Eigen::Vector2d(200 + 300 * t, 700 - 150 * t) + error);
  }
  auto groups = find_collinear_groups(points, {});
  bool planted = false;
  for (auto& g : groups) {
    int mine = 0;
    for (int p : g.points) mine += p >= 100;
    planted = planted || mine == 4;
  }
  EXPECT_TRUE(planted);
}

TEST(Identifier, NamesABoardInBothDirectionsAndAnyRoll) {
  ConstellationDatabase database = shipped_database();
  ConstellationIdentifier identifier(database);
  PinholeCamera camera = test_camera();
  std::mt19937 random(11);
  for (const ConstellationModel& model : database.constellations()) {
    for (double roll : {0.0, 90.0, 180.0, 237.0}) {
      Projected p =
          project(camera, model, board_pose({0.1, -0.05, 1.5}, roll, 25, -30), 0.05, random);
      auto found = identifier.identify(ideal(camera, p.pixels));
      ASSERT_EQ(found.size(), 1u) << model.name << " roll " << roll;
      EXPECT_EQ(found[0].model->name, model.name);
      EXPECT_EQ(found[0].lines.size(), 4u);
      EXPECT_EQ(found[0].image_point_of, p.truth) << model.name << " roll " << roll;
    }
  }
}

TEST(Identifier, SeveralBoardsDistractorsAndAnOccludedSide) {
  ConstellationDatabase database = shipped_database();
  ConstellationIdentifier identifier(database);
  PinholeCamera camera = test_camera();
  std::mt19937 random(3);
  std::uniform_real_distribution<double> x(0, 1280), y(0, 720);
  std::vector<Eigen::Vector2d> pixels;
  // Distractors, each drawn last first (draw_order.hpp).
  for (int i = 0; i < 10; ++i) {
    const double v = y(random), u = x(random);
    pixels.emplace_back(u, v);
  }
  std::vector<std::vector<int>> truth;
  const auto& models = database.constellations();
  for (int b = 0; b < 8; ++b) {
    Eigen::Vector3d position(-1.05 + 0.7 * (b % 4), -0.25 + 0.5 * (b / 4), 2.5);
    Projected p =
        project(camera, models[b], board_pose(position, 40.0 * b, 10, 15), 0.05, random, pixels);
    pixels = p.pixels;
    truth.push_back(p.truth);
  }
  auto found = identifier.identify(ideal(camera, pixels));
  ASSERT_EQ(found.size(), 8u);
  for (const auto& f : found) {
    int b = static_cast<int>(f.model - models.data());
    EXPECT_EQ(f.image_point_of, truth[b]) << f.model->name;
  }

  // Hide the two markers inside one side of board_a: three sides remain and suffice.
  const ConstellationLine& side = models[0].lines[1];
  std::vector<Eigen::Vector2d> occluded = pixels;
  for (int k : {1, 2}) occluded[truth[0][side.points[k]]] = {NAN, NAN};
  found = identifier.identify(ideal(camera, occluded));
  ASSERT_EQ(found.size(), 8u);
  for (const auto& f : found) {
    if (f.model != &models[0]) continue;
    EXPECT_EQ(f.lines.size(), 3u);
    EXPECT_EQ(f.points_identified(), 10);
  }
}

TEST(Identifier, ABoardWithAHiddenCornerKeepsTwoSidesAndItsOtherMarkers) {
  ConstellationDatabase database = shipped_database();
  ConstellationIdentifier identifier(database);
  PinholeCamera camera = test_camera();
  std::mt19937 random(13);
  const ConstellationModel& model = database.constellations()[3];
  Projected p = project(camera, model, board_pose({0, 0, 1.8}, 70, 20, 10), 0.05, random);
  // The corner shared by lines 0 and 1 hides: two whole sides remain, and the other three
  // markers of the broken ones.
  int corner = model.lines[0].points[0];
  for (int q : model.lines[1].points) {
    for (int r : model.lines[0].points) {
      if (q == r) corner = q;
    }
  }
  p.pixels[p.truth[corner]] = {NAN, NAN};
  auto found = identifier.identify(ideal(camera, p.pixels));
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].lines.size(), 2u);
  EXPECT_EQ(found[0].points_identified(), 11);
  std::vector<int> expected = p.truth;
  expected[corner] = -1;
  EXPECT_EQ(found[0].image_point_of, expected);
  // Without the extra markers' help two sides are not enough.
  IdentifierOptions strict;
  strict.min_extra_markers = 0;
  EXPECT_TRUE(ConstellationIdentifier(database, strict).identify(ideal(camera, p.pixels)).empty());
}

TEST(Identifier, RandomPointsAreNotABoard) {
  ConstellationDatabase database = shipped_database();
  ConstellationIdentifier identifier(database);
  std::mt19937 random(17);
  std::uniform_real_distribution<double> x(0, 1280), y(0, 720);
  int false_identifications = 0;
  IdentificationStats stats;
  size_t matched_lines = 0;
  for (int frame = 0; frame < 1000; ++frame) {
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i < 40; ++i) {
      const double v = y(random), u = x(random);  // last first (draw_order.hpp)
      points.emplace_back(u, v);
    }
    // Distractor lines: many collinear points at random spacings.
    for (int l = 0; l < 4; ++l) {
      const double direction_v = y(random) - 360, direction_u = x(random) - 640;
      const double start_v = y(random), start_u = x(random);
      const Eigen::Vector2d start(start_u, start_v);
      Eigen::Vector2d direction(direction_u, direction_v);
      direction = direction.normalized() * 25;
      double t = 0;
      for (int k = 0; k < 5; ++k) {
        t += 0.5 + std::uniform_real_distribution<double>(0, 1)(random);
        points.push_back(start + t * direction);
      }
    }
    false_identifications += static_cast<int>(identifier.identify(points, &stats).size());
    matched_lines += stats.matched;
  }
  EXPECT_GT(matched_lines, 0u) << "the distractor lines should match some line types";
  EXPECT_EQ(false_identifications, 0);
}

TEST(PlanarPose, RecoversThePoseOfProjectedBoards) {
  ConstellationDatabase database = shipped_database();
  PinholeCamera camera = test_camera();
  std::mt19937 random(23);
  const ConstellationModel& model = database.constellations()[2];
  for (double distance : {0.5, 1.5, 3.5}) {
    for (double skew : {0.0, 30.0, 60.0}) {
      Eigen::Isometry3d truth = board_pose({0.05 * distance, 0.03, distance}, 33, skew, skew / 2);
      Projected p = project(camera, model, truth, 0.0, random);
      std::vector<Eigen::Vector3d> object;
      std::vector<Eigen::Vector2d> pixels;
      for (size_t i = 0; i < model.points.size(); ++i) {
        if (p.truth[i] < 0) continue;
        object.push_back(model.points[i]);
        pixels.push_back(p.pixels[p.truth[i]]);
      }
      pose::PlanarPose pose = pose::estimate_planar_pose(camera, object, pixels);
      ASSERT_TRUE(pose.valid) << pose.rejection;
      EXPECT_LT((pose.camera_from_object.translation() - truth.translation()).norm(), 1e-6)
          << distance << " m, " << skew << " deg";
      EXPECT_LT(pose::rotation_angle_between(Eigen::Quaterniond(pose.camera_from_object.linear()),
                                             Eigen::Quaterniond(truth.linear())),
                1e-6);
      EXPECT_LT(pose.reprojection_rms_px, 1e-6);
      EXPECT_EQ(pose.points_used, 12);
    }
  }
}

TEST(PlanarPose, NoiseGivesSmallErrorsAndAMatchingCovariance) {
  ConstellationDatabase database = shipped_database();
  PinholeCamera camera = test_camera();
  std::mt19937 random(29);
  const ConstellationModel& model = database.constellations()[0];
  Eigen::Isometry3d truth = board_pose({0.1, 0.05, 2.0}, 10, 20, -15);
  std::vector<double> z_errors, z_sigmas;
  double mean_rms = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Projected p = project(camera, model, truth, 0.1, random);
    std::vector<Eigen::Vector3d> object(model.points.begin(), model.points.end());
    pose::PlanarPose pose = pose::estimate_planar_pose(camera, object, p.pixels);
    ASSERT_TRUE(pose.valid) << pose.rejection;
    z_errors.push_back(pose.camera_from_object.translation().z() - truth.translation().z());
    z_sigmas.push_back(std::sqrt(pose.covariance(2, 2)));
    mean_rms += pose.reprojection_rms_px / 200;
  }
  double rms = 0, sigma = 0;
  for (size_t i = 0; i < z_errors.size(); ++i) {
    rms += z_errors[i] * z_errors[i];
    sigma += z_sigmas[i];
  }
  rms = std::sqrt(rms / z_errors.size());
  // Per-point distance: sqrt(2) sigma, less the 6 parameters fitted to 24 coordinates.
  EXPECT_NEAR(mean_rms, 0.1 * std::sqrt(2.0 * 18 / 24), 0.01);
  sigma /= z_sigmas.size();
  EXPECT_LT(rms, 0.005);                // depth within 5 mm at 2 m with 0.1 px noise
  EXPECT_NEAR(sigma / rms, 1.0, 0.35);  // the covariance predicts the scatter
}

TEST(PlanarPose, RejectsPointsThatFitNoBoard) {
  ConstellationDatabase database = shipped_database();
  PinholeCamera camera = test_camera();
  std::mt19937 random(31);
  const ConstellationModel& model = database.constellations()[0];
  Projected p = project(camera, model, board_pose({0, 0, 1.5}, 0, 0, 0), 0.0, random);
  std::vector<Eigen::Vector3d> object(model.points.begin(), model.points.end());
  std::swap(p.pixels[0], p.pixels[5]);  // a misidentification
  pose::PlanarPose pose = pose::estimate_planar_pose(camera, object, p.pixels);
  EXPECT_FALSE(pose.valid);
  EXPECT_NE(pose.rejection.find("reprojection RMS"), std::string::npos) << pose.rejection;
  pose = pose::estimate_planar_pose(camera, {object.begin(), object.begin() + 3},
                                    {p.pixels.begin(), p.pixels.begin() + 3});
  EXPECT_FALSE(pose.valid);
  EXPECT_EQ(pose.rejection, "3 usable points, 4 needed");
}

TEST(PlanarPose, MatchToModelMergesSharedCorners) {
  ConstellationDatabase database = shipped_database();
  const ConstellationModel& model = database.constellations()[0];
  std::vector<pose::ObservedLine> lines;
  for (const auto& line : model.lines) {
    pose::ObservedLine observed{line.name, {}};
    for (int k = 0; k < 4; ++k) {
      observed.pixels[k] = model.plane_points[line.points[k]] * 1000;
    }
    lines.push_back(observed);
  }
  lines.push_back({"nonexistent", {}});
  pose::Correspondences pairs = pose::match_to_model(model, lines);
  EXPECT_EQ(pairs.object_points.size(), 12u);
  EXPECT_EQ(pairs.unknown_lines, std::vector<std::string>{"nonexistent"});
}

// Options built in code get the checks a launch file's parameters get from the plugins' ranges:
// what takes them refuses them first, naming the field (the line search's by its path).
TEST(IdentifierOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(IdentifierOptions{}.problem(), std::nullopt);
  EXPECT_EQ(LineSearchOptions{}.problem(), std::nullopt);
  // Compared squared, a negative length would pass for a positive one.
  EXPECT_EQ(LineSearchOptions{.min_length_px = -8}.problem(), "min_length_px: -8 is below 0");
  EXPECT_EQ(LineSearchOptions{.min_points = 1}.problem(),
            "min_points: 1; a line takes two points at least");
  IdentifierOptions options;
  options.line_search.tolerance_px = 0;
  EXPECT_EQ(options.problem(), "line_search.tolerance_px: 0 is not above 0");
  options = {};
  options.cross_ratio_tolerance = -0.03;
  EXPECT_EQ(options.problem(), "cross_ratio_tolerance: -0.03 is not above 0");
  options = {};
  options.candidate_window = 3;
  EXPECT_EQ(options.problem(), "candidate_window: 3; a line's four points need four at least");
  options = {};
  options.focal_length_px = -1;
  EXPECT_EQ(options.problem(), "focal_length_px: -1 is below 0");
  options = {};
  options.min_lines = 0;
  const ConstellationDatabase database = shipped_database();
  try {
    ConstellationIdentifier identifier(database, options);
    ADD_FAILURE() << "min_lines 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "IdentifierOptions::min_lines: 0 is below 1");
  }
  try {
    find_collinear_groups({}, {.tolerance_px = 0});
    ADD_FAILURE() << "tolerance 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "LineSearchOptions::tolerance_px: 0 is not above 0");
  }
}

// Fewer than four points cannot fix a plane's pose: refused, not a rejection of the points.
TEST(PlanarPoseOptions, NameTheFieldThatCannotBeUsed) {
  using pose::PlanarPoseOptions;
  EXPECT_EQ(PlanarPoseOptions{}.problem(), std::nullopt);
  EXPECT_EQ(PlanarPoseOptions{.min_points = 3}.problem(),
            "min_points: 3; four points at least fix a plane's pose");
  EXPECT_EQ(PlanarPoseOptions{.max_reprojection_rms_px = 0}.problem(),
            "max_reprojection_rms_px: 0 is not above 0");
  EXPECT_EQ(PlanarPoseOptions{.max_iterations = 0}.problem(), "max_iterations: 0 is below 1");
  const PinholeCamera camera = test_camera();
  try {
    pose::estimate_planar_pose(camera, {}, {}, {.min_points = 3});
    ADD_FAILURE() << "min_points 3 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "PlanarPoseOptions::min_points: 3; four points at least fix a plane's pose");
  }
  EXPECT_THROW(pose::refine_planar_pose(camera, Eigen::Isometry3d::Identity(), {}, {},
                                        {.max_iterations = 0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::constellations
