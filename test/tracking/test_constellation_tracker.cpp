// Tracking over time: the motion filter, the global association, the occlusion check, the
// one-line identification, and the tracker on rendered scenes of config/scenes/ scored against
// their truth (the figures of tracking_accuracy_bench's sequences, as bounds).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <mocap/calibration/camera_file.hpp>

#include "common/min_cost_assignment/min_cost_assignment.hpp"
#include "sim/synthetic_ir_camera/ir_renderer.hpp"
#include "test/draw_order.hpp"
#include "test/test_support.hpp"
#include "tracking/body_motion/body_motion.hpp"
#include "tracking/constellation_identifier/one_line_search.hpp"
#include "tracking/constellation_tracker/constellation_tracker.hpp"
#include "tracking/constellation_tracker/marker_association.hpp"
#include "tracking/constellation_tracker/marker_visibility.hpp"
#include "tracking/fiducial_tracker/fiducial_tracker.hpp"
#include "tracking/pose_evaluator/pose_evaluator.hpp"
#include "tracking/pose_evaluator/sequence_evaluation.hpp"

namespace mocap::tracking {
namespace {

using constellations::ConstellationDatabase;
using evaluation::SequenceScore;

const ConstellationDatabase& database() {
  static const ConstellationDatabase shipped =
      constellations::load_database(test::source_dir().string() + "/config/constellations.yaml");
  return shipped;
}

std::shared_ptr<const calibration::CameraModel> camera() {
  static const calibration::CameraFile file = calibration::load_camera_file(
      test::source_dir().string() + "/config/cameras/synthetic_ir_1280x720.yaml");
  return file.model;
}

double median(std::vector<double> values) {
  return evaluation::EvaluationSummary::quantile(std::move(values), 0.5);
}

TEST(BodyMotionFilter, MeasuresTheVelocitiesOfASteadyMotion) {
  const Eigen::Vector3d v(0.8, -0.3, 0.2), w(0.4, -1.2, 1.5);  // m/s, rad/s
  std::mt19937 random(5);
  // A board at 2 m measured to a third of a millimetre and a thirtieth of a degree.
  std::normal_distribution<double> position_noise(0, 0.0003), angle_noise(0, 0.0006);
  Matrix6d measured = Matrix6d::Zero();
  measured.topLeftCorner<3, 3>() = 0.0003 * 0.0003 * Eigen::Matrix3d::Identity();
  measured.bottomRightCorner<3, 3>() = 0.0006 * 0.0006 * Eigen::Matrix3d::Identity();
  auto truth_at = [&](double t) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(0, 0, 2) + v * t;
    pose.linear() = rotation_from_vector(w * t);
    return pose;
  };
  auto noisy = [&](const Eigen::Isometry3d& pose) {
    Eigen::Isometry3d out = pose;
    out.translation() += test::draw_last_first<3>(position_noise, random);
    out.linear() =
        rotation_from_vector(test::draw_last_first<3>(angle_noise, random)) * pose.linear();
    return out;
  };
  BodyMotionFilter filter(noisy(truth_at(0)), measured, 0);
  for (int k = 1; k <= 90; ++k) {
    const int64_t stamp = k * 33'333'333LL;
    filter.correct(stamp, noisy(truth_at(stamp * 1e-9)), measured);
  }
  const BodyState& state = filter.state();
  EXPECT_LT((state.linear_velocity - v).norm(), 0.03);
  EXPECT_LT((state.angular_velocity - w).norm(), 0.05);
  // The covariance knows it: a few standard deviations hold the error.
  EXPECT_LT((state.linear_velocity - v).norm(),
            4 * std::sqrt(state.velocity_covariance().topLeftCorner<3, 3>().trace()));
  // And predicts a frame ahead where the body will be.
  const BodyState next = filter.predicted(91 * 33'333'333LL);
  EXPECT_LT((next.camera_from_body.translation() - truth_at(91 * 33'333'333LL * 1e-9).translation())
                .norm(),
            0.003);
}

// The prediction's covariance, written block by block, is F P Fᵀ + Q with F the model's whole
// 12 x 12 transition (p += dt v, θ ← turn θ + dt ω); the correction's, the Joseph form's.
TEST(BodyMotionFilter, PropagatesTheCovarianceOfTheWholeModel) {
  BodyMotionOptions options;
  Matrix6d measured = Matrix6d::Identity() * 1e-6;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation_from_vector(Eigen::Vector3d(0.3, -0.2, 0.5));
  BodyMotionFilter filter(pose, measured, 0, options);
  // Two corrections: velocities and a covariance with every block filled.
  pose.translation() += Eigen::Vector3d(0.01, 0.002, -0.003);
  pose.linear() = rotation_from_vector(Eigen::Vector3d(0.02, 0.01, -0.03)) * pose.linear();
  filter.correct(10'000'000, pose, measured);
  pose.translation() += Eigen::Vector3d(0.012, 0.001, -0.002);
  filter.correct(20'000'000, pose, measured);
  const BodyState& state = filter.state();
  const double dt = 0.004;
  Matrix12d f = Matrix12d::Identity();
  f.block<3, 3>(0, 6) = dt * Eigen::Matrix3d::Identity();
  f.block<3, 3>(3, 3) = rotation_from_vector(state.angular_velocity * dt);
  f.block<3, 3>(3, 9) = dt * Eigen::Matrix3d::Identity();
  Matrix12d expected = f * state.covariance * f.transpose();
  const double q = options.linear_acceleration_density, r = options.angular_acceleration_density;
  for (int axis = 0; axis < 3; ++axis) {
    expected(axis, axis) += q * dt * dt * dt / 3;
    expected(axis, 6 + axis) += q * dt * dt / 2;
    expected(6 + axis, axis) += q * dt * dt / 2;
    expected(6 + axis, 6 + axis) += q * dt;
    expected(3 + axis, 3 + axis) += r * dt * dt * dt / 3;
    expected(3 + axis, 9 + axis) += r * dt * dt / 2;
    expected(9 + axis, 3 + axis) += r * dt * dt / 2;
    expected(9 + axis, 9 + axis) += r * dt;
  }
  const BodyState prior = filter.predicted(20'000'000 + 4'000'000);
  EXPECT_LT((prior.covariance - expected).cwiseAbs().maxCoeff(),
            1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_GT((prior.covariance - state.covariance).cwiseAbs().maxCoeff(), 0)
      << "the test tests nothing";

  // And the correction's, in Joseph form: (I − K H) P (I − K H)ᵀ + K R Kᵀ, H = [I 0].
  const Matrix6d innovation = prior.covariance.topLeftCorner<6, 6>() + measured;
  const Eigen::Matrix<double, 12, 6> gain = prior.covariance.leftCols<6>() * innovation.inverse();
  Matrix12d keep = Matrix12d::Identity();
  keep.leftCols<6>() -= gain;
  const Matrix12d joseph =
      keep * prior.covariance * keep.transpose() + gain * measured * gain.transpose();
  filter.correct(20'000'000 + 4'000'000, pose, measured);
  EXPECT_LT((filter.state().covariance - joseph).cwiseAbs().maxCoeff(),
            1e-9 * joseph.cwiseAbs().maxCoeff());
}

TEST(PointMotionFilter, SmoothsAPointAndMeasuresItsVelocity) {
  // A marker at 240 Hz measured to 0.07 mm per axis, moving steadily.
  const Eigen::Vector3d v(0.5, -0.2, 0.1);
  std::mt19937 random(6);
  std::normal_distribution<double> noise(0, 0.00007);
  const Eigen::Matrix3d measured = 0.00007 * 0.00007 * Eigen::Matrix3d::Identity();
  BodyMotionOptions options;
  options.linear_acceleration_density = 0.3;
  auto truth_at = [&](double t) -> Eigen::Vector3d { return Eigen::Vector3d(0, 0, 1) + v * t; };
  PointMotionFilter filter(truth_at(0), measured, 0, options);
  std::vector<double> raw, filtered;
  for (int k = 1; k <= 480; ++k) {
    const int64_t stamp = k * 4'166'667LL;
    const Eigen::Vector3d truth = truth_at(stamp * 1e-9);
    const Eigen::Vector3d seen = truth + test::draw_last_first<3>(noise, random);
    filter.correct(stamp, seen, measured);
    if (k < 240) continue;  // settled
    raw.push_back((seen - truth).norm());
    filtered.push_back((filter.state().position - truth).norm());
  }
  // A density that follows a quadrotor's changes of speed smooths a little (8 % here).
  EXPECT_LT(median(filtered), 0.95 * median(raw));
  EXPECT_LT((filter.state().velocity - v).norm(), 0.05);
  EXPECT_LT((filter.state().velocity - v).norm(),
            4 * std::sqrt(filter.state().covariance.bottomRightCorner<3, 3>().trace()));
  EXPECT_LT((filter.predicted(481 * 4'166'667LL).position - truth_at(481 * 4'166'667e-9)).norm(),
            0.0003);
}

TEST(MinCostAssignment, EqualsTheBestOfEveryPermutation) {
  std::mt19937 random(9);
  std::uniform_real_distribution<double> cost(0, 10);
  for (int trial = 0; trial < 50; ++trial) {
    const int rows = 1 + trial % 4, columns = rows + trial % 3;
    Eigen::MatrixXd matrix(rows, columns);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < columns; ++c) matrix(r, c) = cost(random);
    }
    std::vector<int> assignment = min_cost_assignment(matrix);
    double total = 0;
    for (int r = 0; r < rows; ++r) total += matrix(r, assignment[r]);
    std::vector<int> order(columns);
    std::iota(order.begin(), order.end(), 0);
    double best = std::numeric_limits<double>::infinity();
    do {
      double sum = 0;
      for (int r = 0; r < rows; ++r) sum += matrix(r, order[r]);
      best = std::min(best, sum);
    } while (std::next_permutation(order.begin(), order.end()));
    EXPECT_NEAR(total, best, 1e-9) << "trial " << trial;
    std::vector<int> sorted = assignment;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::unique(sorted.begin(), sorted.end()), sorted.end());
  }
}

// Over gated pairs, group by group, a row may stay without a column at its own cost: the same
// total as the whole matrix with a "none" column per row and the pairs not allowed priced out.
TEST(MinCostAssignment, OverAllowedPairsEqualsTheWholeMatrix) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> cost(0, 10);
  std::bernoulli_distribution allowed_pair(0.3);
  for (int trial = 0; trial < 100; ++trial) {
    const int rows = 1 + trial % 7, columns = 1 + trial % 5;
    std::vector<AllowedPair> allowed;
    std::vector<double> none(rows);
    const double forbidden = 1e6;
    Eigen::MatrixXd whole = Eigen::MatrixXd::Constant(rows, columns + rows, forbidden);
    for (int r = 0; r < rows; ++r) {
      none[r] = cost(random);
      whole(r, columns + r) = none[r];
      for (int c = 0; c < columns; ++c) {
        if (!allowed_pair(random)) continue;
        allowed.push_back({r, c, cost(random)});
        whole(r, c) = allowed.back().cost;
      }
    }
    const std::vector<int> assignment = min_cost_assignment(rows, columns, allowed, none);
    double total = 0;
    std::vector<int> taken;
    for (int r = 0; r < rows; ++r) {
      if (assignment[r] < 0) {
        total += none[r];
        continue;
      }
      ASSERT_LT(whole(r, assignment[r]), forbidden) << "a pair not allowed, trial " << trial;
      total += whole(r, assignment[r]);
      taken.push_back(assignment[r]);
    }
    const std::vector<int> best = min_cost_assignment(whole);
    double best_total = 0;
    for (int r = 0; r < rows; ++r) best_total += whole(r, best[r]);
    EXPECT_NEAR(total, best_total, 1e-9) << "trial " << trial;
    std::sort(taken.begin(), taken.end());
    EXPECT_EQ(std::unique(taken.begin(), taken.end()), taken.end());
  }
}

TEST(MarkerAssociation, DecidesForEveryMarkerAtOnce) {
  // Two markers of crossing boards predicted close together: the greedy choice gives the
  // first marker its nearest fiducial and leaves the second with none; the global one keeps
  // both.
  std::vector<PredictedMarker> predictions(2);
  predictions[0].pixel = {100, 100};
  predictions[1].pixel = {103, 100};
  for (auto& p : predictions) p.covariance = Eigen::Matrix2d::Identity() * 1.0;
  const std::vector<Eigen::Vector2d> fiducials = {{102, 100}, {98.5, 100}, {400, 300}};
  const std::vector<int> chosen = associate_markers(predictions, fiducials, 16.0);
  EXPECT_EQ(chosen, (std::vector<int>{1, 0}));
  // Beyond the gate: nothing, however alone the fiducial is.
  predictions[1].pixel = {300, 300};
  EXPECT_EQ(associate_markers(predictions, fiducials, 16.0), (std::vector<int>{1, -1}));
  // The gate follows the prediction's uncertainty: a wide one reaches further.
  predictions[1].covariance = Eigen::Matrix2d::Identity() * 100 * 100;
  EXPECT_EQ(associate_markers(predictions, fiducials, 16.0), (std::vector<int>{1, 2}));
}

TEST(OneBandCovers, WhatOneOccluderCanHide) {
  // Markers round a board's outline, in order.
  std::vector<Eigen::Vector2d> ring;
  for (int k = 0; k < 12; ++k) {
    const double a = 2 * M_PI * k / 12;
    ring.emplace_back(100 * std::cos(a), 60 * std::sin(a));
  }
  auto split = [&](const std::vector<int>& hidden_indices) {
    std::pair<std::vector<Eigen::Vector2d>, std::vector<Eigen::Vector2d>> out;
    for (int k = 0; k < 12; ++k) {
      bool hidden =
          std::find(hidden_indices.begin(), hidden_indices.end(), k) != hidden_indices.end();
      (hidden ? out.first : out.second).push_back(ring[k]);
    }
    return out;
  };
  // A hand over one side, a pole across the middle.
  auto [side, side_seen] = split({4, 5, 6, 7, 8});
  EXPECT_TRUE(one_band_covers(side, side_seen));
  auto [pole, pole_seen] = split({2, 3, 4, 8, 9, 10});
  EXPECT_TRUE(one_band_covers(pole, pole_seen));
  // Markers a third of the way round from each other: any band over two of them holds seen
  // ones; with one spare (a glare) the other two are a band.
  auto [apart, apart_seen] = split({0, 4, 8});
  EXPECT_FALSE(one_band_covers(apart, apart_seen));
  EXPECT_TRUE(one_band_covers(apart, apart_seen, 1));
  // Four of them, two spread apart: not even with a spare.
  auto [four, four_seen] = split({0, 3, 6, 9});
  EXPECT_FALSE(one_band_covers(four, four_seen));
  EXPECT_FALSE(one_band_covers(four, four_seen, 1));
  // A lone marker always can (a thin pole, a fingertip); two with a seen one between them on
  // their line, and seen ones around, cannot.
  std::vector<Eigen::Vector2d> grid_seen;
  for (int x = -1; x <= 3; ++x) {
    for (int y = -1; y <= 1; ++y) {
      if (y != 0 || (x != 0 && x != 2)) grid_seen.emplace_back(x * 10, y * 10);
    }
  }
  EXPECT_TRUE(one_band_covers({{0, 0}}, grid_seen));
  EXPECT_FALSE(one_band_covers({{0, 0}, {20, 0}}, grid_seen));
}

TEST(PlaceLine, FindsALineOfKnownSpacingFromItsImage) {
  const std::array<double, 4> along = {0, 0.05, 0.14, 0.2};
  const Eigen::Vector3d start(-0.3, 0.1, 1.8);
  const Eigen::Vector3d direction = Eigen::Vector3d(0.6, 0.3, 0.5).normalized();
  std::array<Eigen::Vector2d, 4> seen;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d p = start + along[k] * direction;
    seen[k] = p.head<2>() / p.z();
  }
  auto placed = constellations::place_line(seen, along);
  ASSERT_TRUE(placed);
  EXPECT_LT((placed->start - start).norm(), 1e-9);
  EXPECT_LT((placed->direction - direction).norm(), 1e-9);
  EXPECT_LT(placed->rms_error, 1e-12);
}

// Ideal pixels of a board's markers at `pose` in the shipped camera, with noise.
std::vector<Eigen::Vector2d> ideal_markers(const constellations::ConstellationModel& model,
                                           const Eigen::Isometry3d& pose, double noise_px,
                                           std::mt19937& random) {
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : model.points) {
    const Eigen::Vector3d q = pose * p;
    out.push_back(camera()->focal_length_px() * q.head<2>() / q.z() +
                  test::draw_last_first<2>(noise, random));
  }
  return out;
}

Eigen::Isometry3d facing_pose(const Eigen::Vector3d& position, double roll_deg, double yaw_deg) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = synthetic::facing_orientation({roll_deg, 10, yaw_deg});
  pose.translation() = position;
  return pose;
}

TEST(Identifier, FindsABoardFromOneWholeLineAndItsLooseMarkers) {
  constellations::IdentifierOptions options;
  options.focal_length_px = camera()->focal_length_px();
  constellations::ConstellationIdentifier identifier(database(), options);
  constellations::ConstellationIdentifier without_focal(database());
  std::mt19937 random(4);
  int found = 0;
  for (size_t b = 0; b < database().constellations().size(); ++b) {
    const auto& model = database().constellations()[b];
    std::vector<Eigen::Vector2d> points =
        ideal_markers(model, facing_pose({0.1, -0.05, 1.6}, 30.0 * b, 20), 0.1, random);
    // Keep line 0 whole and one inner marker of each other line; hide the rest (a hand over
    // most of the board): no other line is whole.
    const auto& line = model.lines[0].points;
    std::vector<int> kept(line.begin(), line.end());
    for (size_t l = 1; l < model.lines.size(); ++l)
      kept.push_back(model.lines[l].points[1 + l % 2]);
    for (int m = 0; m < static_cast<int>(points.size()); ++m) {
      if (std::find(kept.begin(), kept.end(), m) == kept.end()) points[m] = {NAN, NAN};
    }
    EXPECT_TRUE(without_focal.identify(points).empty()) << model.name;
    auto result = identifier.identify(points);
    ASSERT_LE(result.size(), 1u);
    if (result.empty()) continue;
    EXPECT_EQ(result[0].model, &model);
    EXPECT_TRUE(result[0].from_one_line);
    for (int m : kept) EXPECT_EQ(result[0].image_point_of[m], m) << model.name << " marker " << m;
    ++found;
  }
  EXPECT_EQ(found, 8);
}

TEST(Identifier, OneLineHypothesesNameNoBoardInRandomPoints) {
  constellations::IdentifierOptions options;
  options.focal_length_px = camera()->focal_length_px();
  constellations::ConstellationIdentifier identifier(database(), options);
  std::mt19937 random(23);
  std::uniform_real_distribution<double> x(-640, 640), y(-360, 360);
  constellations::IdentificationStats stats;
  size_t hypotheses = 0;
  int false_identifications = 0;
  for (int frame = 0; frame < 1000; ++frame) {
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i < 40; ++i) {
      const double v = y(random), u = x(random);  // last first (draw_order.hpp)
      points.emplace_back(u, v);
    }
    // A real board's whole line among them, its other markers hidden: the line alone must not
    // name a board, nor may random points complete it.
    const auto& model = database().constellations()[frame % 8];
    const double roll = 45.0 * (frame % 7);
    auto board = ideal_markers(model, facing_pose({0.0, 0.0, 2.0}, roll, 15), 0.1, random);
    for (int m : model.lines[frame % 4].points) points.push_back(board[m]);
    false_identifications += static_cast<int>(identifier.identify(points, &stats).size());
    hypotheses += stats.one_line_hypotheses;
  }
  EXPECT_GT(hypotheses, 1000u) << "every frame should try the line";
  EXPECT_EQ(false_identifications, 0);
}

// Renders `scene_file` at 30 Hz for `seconds` and scores the tracker (and, when asked, the
// per-frame identifier's poses) over it.
struct SceneRun {
  SequenceScore tracked;
  std::vector<std::vector<TrackedConstellation>> frames;
};

SceneRun run_scene(const std::string& scene_file, double seconds, bool without_occluders = false) {
  synthetic::Scene scene = synthetic::load_scene(
      test::source_dir().string() + "/config/scenes/" + scene_file, database());
  if (without_occluders) {
    scene.distractors.occluders.clear();
    for (auto& object : scene.objects) object.occlusion.reset();
  }
  synthetic::IrRenderer renderer(scene, camera());
  FiducialDetector detector;
  ConstellationTracker tracker(database(), camera());
  evaluation::SequenceEvaluator evaluator;
  SceneRun run;
  for (int k = 0; k < static_cast<int>(seconds * 30); ++k) {
    const double time_s = k / 30.0;
    synthetic::RenderedFrame frame = renderer.render(time_s, static_cast<uint64_t>(k));
    std::vector<ImageFiducial> fiducials;
    for (const auto& f : detector.detect(frame.image)) fiducials.push_back({{f.x, f.y}, f.area_px});
    auto boards = tracker.update(k * 33'333'333LL, fiducials);
    std::vector<evaluation::SequenceTruth> truth;
    for (const auto& object : frame.objects) {
      truth.push_back({object.constellation, object.pose, object.linear_velocity,
                       object.angular_velocity, object.facing_camera, object.visible_markers(),
                       static_cast<int>(object.markers.size())});
    }
    std::vector<evaluation::SequenceEstimate> estimates;
    for (const auto& board : boards) {
      evaluation::SequenceEstimate estimate{
          board.identified.model->name, board.pose.camera_from_object, {}, {}};
      if (board.frames_tracked >= 10) {
        estimate.linear_velocity = board.motion.linear_velocity;
        estimate.angular_velocity = board.motion.angular_velocity;
      }
      estimates.push_back(estimate);
    }
    evaluator.add_frame(time_s, truth, estimates);
    run.frames.push_back(std::move(boards));
  }
  run.tracked = evaluator.score();
  return run;
}

void expect_no_mistakes(const SequenceScore& score) {
  EXPECT_EQ(score.false_identifications, 0);
  EXPECT_EQ(score.identity_swaps, 0);
  EXPECT_GT(score.episodes, 0);
  EXPECT_EQ(score.acquired, score.episodes);
}

TEST(ConstellationTracker, HoldsBoardsUnderAHandAndBehindAPole) {
  const SceneRun occluded = run_scene("hand_and_pole.yaml", 8);
  const SceneRun clear = run_scene("hand_and_pole.yaml", 8, true);
  expect_no_mistakes(occluded.tracked);
  EXPECT_GE(occluded.tracked.tracked_after_acquisition_percent(), 99.0);
  EXPECT_LE(median(occluded.tracked.position_error_mm),
            2 * median(clear.tracked.position_error_mm));
  EXPECT_LE(median(occluded.tracked.orientation_error_deg),
            2 * median(clear.tracked.orientation_error_deg));
  // Most frames come from the tracks, not from identifying the boards again.
  int tracked = 0, all = 0;
  for (const auto& frame : occluded.frames) {
    for (const auto& board : frame) {
      ++all;
      tracked += board.source == PoseSource::Tracked;
    }
  }
  EXPECT_GT(tracked, all * 9 / 10);
}

TEST(ConstellationTracker, FollowsBoardsOutOfThePictureAndBack) {
  const SceneRun run = run_scene("image_edge.yaml", 12);
  expect_no_mistakes(run.tracked);
  EXPECT_GE(run.tracked.episodes, 4) << "both boards leave and come back";
  EXPECT_GE(run.tracked.tracked_after_acquisition_percent(), 99.0);
}

TEST(ConstellationTracker, KeepsUpWithFastMotion) {
  const SceneRun run = run_scene("fast_motion.yaml", 4);
  expect_no_mistakes(run.tracked);
  EXPECT_GE(run.tracked.tracked_after_acquisition_percent(), 99.0);
}

TEST(ConstellationTracker, MeasuresVelocities) {
  const SceneRun run = run_scene("steady_motion.yaml", 8);
  expect_no_mistakes(run.tracked);
  ASSERT_GT(run.tracked.velocity_error_mps.size(), 100u);
  EXPECT_LE(median(run.tracked.velocity_error_mps), 0.02);         // 2 cm/s at 1 m/s
  EXPECT_LE(median(run.tracked.angular_velocity_error_dps), 2.0);  // 2 deg/s at 90 deg/s
}

TEST(ConstellationTracker, EightBoardsCrossWithoutSwapping) {
  const SceneRun run = run_scene("eight_crossing.yaml", 8);
  expect_no_mistakes(run.tracked);
  EXPECT_GE(run.tracked.tracked_after_acquisition_percent(), 99.0);
}

TEST(ConstellationTracker, NamesNoDistractor) {
  const SceneRun run = run_scene("distractors.yaml", 8);
  expect_no_mistakes(run.tracked);
  EXPECT_GE(run.tracked.tracked_after_acquisition_percent(), 99.0);
}

// A camera on a turret that starts and stops turning moves the whole picture by tens of pixels
// between frames, which no motion of the board foretells: the track is found again by the
// picture's shift, keeps its identity and is not identified afresh.
TEST(ConstellationTracker, KeepsItsTrackWhenTheCameraTurnsInJerks) {
  synthetic::Scene scene;
  scene.source = "jerks";
  const auto& model = database().constellations()[2];
  synthetic::SceneObject board;
  board.constellation = model.name;
  board.markers = model.points;
  synthetic::StaticTrajectory at;
  at.position = {0.0, 0.1, 2.5};
  at.rpy_deg = {20, 10, 0};
  board.trajectory = at;
  // A hand over its left third: a line or two stay whole, not enough to identify it each time.
  board.occlusion = synthetic::ObjectOcclusion{0.3};
  scene.objects.push_back(board);
  synthetic::IrRenderer renderer(scene, camera());
  FiducialDetector detector;
  ConstellationTracker tracker(database(), camera());
  // Still for 0.3 s, then turning at 0.9 rad/s for 0.3 s, and so on, one way then the other.
  double yaw = 0;
  int frames_found = 0, identified = 0, relocked = 0;
  std::set<uint64_t> track_ids;
  for (int k = 0; k < 72; ++k) {
    const int phase = (k / 9) % 4;
    yaw += (phase == 1 ? 0.9 : phase == 3 ? -0.9 : 0.0) / 30;
    Eigen::Isometry3d camera_from_world = Eigen::Isometry3d::Identity();
    camera_from_world.linear() =
        Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
    synthetic::RenderedFrame frame =
        renderer.render(k / 30.0, static_cast<uint64_t>(k), camera_from_world);
    std::vector<ImageFiducial> fiducials;
    for (const auto& f : detector.detect(frame.image)) fiducials.push_back({{f.x, f.y}, f.area_px});
    TrackerStats stats;
    for (const auto& found : tracker.update(k * 33'333'333LL, fiducials, &stats)) {
      EXPECT_EQ(found.identified.model, &model);
      EXPECT_LT((found.pose.camera_from_object.translation() - frame.objects[0].pose.translation())
                    .norm(),
                0.01)
          << "frame " << k;
      ++frames_found;
      track_ids.insert(found.track_id);
    }
    identified += stats.identified;
    relocked += stats.relocked;
  }
  EXPECT_EQ(frames_found, 72);
  EXPECT_EQ(identified, 1) << "found once, then followed";
  EXPECT_EQ(track_ids.size(), 1u);
  EXPECT_GE(relocked, 4) << "each start and stop of the turning moves the picture";
}

TEST(ConstellationTracker, TheSameFramesGiveTheSameAnswers) {
  const SceneRun first = run_scene("hand_and_pole.yaml", 3);
  const SceneRun second = run_scene("hand_and_pole.yaml", 3);
  ASSERT_EQ(first.frames.size(), second.frames.size());
  for (size_t k = 0; k < first.frames.size(); ++k) {
    ASSERT_EQ(first.frames[k].size(), second.frames[k].size());
    for (size_t b = 0; b < first.frames[k].size(); ++b) {
      const auto& a = first.frames[k][b];
      const auto& c = second.frames[k][b];
      EXPECT_EQ(a.identified.image_point_of, c.identified.image_point_of);
      EXPECT_EQ(a.pose.camera_from_object.matrix(), c.pose.camera_from_object.matrix());
      EXPECT_EQ(a.motion.linear_velocity, c.motion.linear_velocity);
      EXPECT_EQ(a.track_id, c.track_id);
    }
  }
}

TEST(ConstellationTracker, FindsBoardsWithAFifthHiddenFromScratch) {
  FiducialDetector detector;
  ConstellationTracker tracker(database(), camera());
  std::mt19937 random(31);
  std::uniform_real_distribution<double> unit(0, 1);
  int found = 0, frames = 0, false_identifications = 0;
  for (int i = 0; i < 100; ++i) {
    synthetic::Scene scene;
    scene.source = "fifth";
    scene.seed = static_cast<uint64_t>(i + 1);
    scene.render.noise_sigma_dn = 3;
    const auto& model = database().constellations()[i % 8];
    synthetic::SceneObject object;
    object.constellation = model.name;
    object.markers = model.points;
    synthetic::StaticTrajectory pose;
    const double z = 1.0 + unit(random) * 2, y = (unit(random) - 0.5) * 0.5,
                 x = (unit(random) - 0.5) * 1.0;
    pose.position = {x, y, z};
    const double yaw = unit(random) * 40 - 20, pitch = unit(random) * 40 - 20,
                 roll = unit(random) * 360;
    pose.rpy_deg = {roll, pitch, yaw};
    object.trajectory = pose;
    object.occlusion = synthetic::ObjectOcclusion{0.2};
    scene.objects.push_back(object);
    synthetic::IrRenderer renderer(scene, camera());
    synthetic::RenderedFrame frame = renderer.render(0.0, static_cast<uint64_t>(i));
    std::vector<ImageFiducial> fiducials;
    for (const auto& f : detector.detect(frame.image)) fiducials.push_back({{f.x, f.y}, f.area_px});
    tracker.reset();
    ++frames;
    for (const auto& board : tracker.update(0, fiducials)) {
      const bool right =
          board.identified.model == &model &&
          (board.pose.camera_from_object.translation() - frame.objects[0].pose.translation())
                  .norm() < 0.05;
      found += right;
      false_identifications += !right;
    }
  }
  EXPECT_EQ(false_identifications, 0);
  EXPECT_GE(found, frames * 9 / 10) << found << " of " << frames;
}

TEST(SequenceEvaluator, CountsSwapsFalseIdentificationsAndEpisodes) {
  evaluation::SequenceEvaluator evaluator;
  evaluation::SequenceTruth a{"a", Eigen::Isometry3d::Identity(), {}, {}, true, 12, 12};
  a.pose.translation() = Eigen::Vector3d(0, 0, 2);
  evaluation::SequenceTruth b = a;
  b.name = "b";
  b.pose.translation() = Eigen::Vector3d(0.5, 0, 2);
  auto estimate = [](const std::string& name, const evaluation::SequenceTruth& at) {
    return evaluation::SequenceEstimate{name, at.pose, {}, {}};
  };
  evaluator.add_frame(0.0, {a, b}, {});                                    // not found
  evaluator.add_frame(0.1, {a, b}, {estimate("a", a), estimate("b", b)});  // found
  evaluator.add_frame(0.2, {a, b}, {estimate("b", a), estimate("a", b)});  // swapped
  Eigen::Isometry3d nowhere = Eigen::Isometry3d::Identity();
  evaluator.add_frame(0.3, {a, b}, {estimate("a", a), {"c", nowhere, {}, {}}});  // false id
  a.visible_markers = 3;                                                         // a ends
  evaluator.add_frame(0.4, {a, b}, {estimate("b", b)});
  a.visible_markers = 12;  // a again
  evaluator.add_frame(0.5, {a, b}, {estimate("a", a), estimate("b", b)});
  const SequenceScore& score = evaluator.score();
  EXPECT_EQ(score.episodes, 3);
  EXPECT_EQ(score.acquired, 3);
  EXPECT_EQ(score.identity_swaps, 2);
  EXPECT_EQ(score.false_identifications, 1);
  EXPECT_NEAR(score.acquisition_delay_s[0], 0.1, 1e-9);
  // a: found at 0.1, missed at 0.2 (swapped), found at 0.3: 2 of 3; b: 0.1, 0.4, 0.5 of
  // 0.1..0.5; a again: 1 of 1.
  EXPECT_EQ(score.frames_after_acquisition, 3 + 5 + 1);
  EXPECT_EQ(score.tracked_after_acquisition, 2 + 3 + 1);
}

// Options built in code get the checks a launch file's parameters get from the plugin's ranges:
// the tracker refuses them at construction, naming the field (its parts' by their path), rather
// than failing in the middle of a frame.
TEST(TrackerOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(TrackerOptions{}.problem(), std::nullopt);
  TrackerOptions options;
  options.identification.line_search.min_length_px = -1;
  EXPECT_EQ(options.problem(), "identification.line_search.min_length_px: -1 is below 0");
  options = {};
  options.pose.max_iterations = 0;
  EXPECT_EQ(options.problem(), "pose.max_iterations: 0 is below 1");
  options = {};
  options.motion.angular_acceleration_density = -8;
  EXPECT_EQ(options.problem(), "motion.angular_acceleration_density: -8 is below 0");
  options = {};
  options.visibility.max_view_angle_deg = 120;
  EXPECT_EQ(options.problem(), "visibility.max_view_angle_deg: 120 is not in [0, 90]");
  options = {};
  options.min_size_ratio = 2;
  EXPECT_EQ(options.problem(), "min_size_ratio: 2 is not in [0, 1]");
  options = {};
  options.relock_min_markers = 3;
  EXPECT_EQ(options.problem(), "relock_min_markers: 3; four markers at least fix a plane's pose");
  // Three markers would have thrown from the pose fit of the first tracked frame.
  options = {};
  options.min_tracked_markers = 3;
  try {
    ConstellationTracker tracker(database(), camera(), options);
    ADD_FAILURE() << "three tracked markers accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "TrackerOptions::min_tracked_markers: 3; four markers at least fix a plane's pose");
  }
}

TEST(VisibilityOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(VisibilityOptions{}.problem(), std::nullopt);
  EXPECT_EQ(VisibilityOptions{.max_view_angle_deg = 91}.problem(),
            "max_view_angle_deg: 91 is not in [0, 90]");
  EXPECT_EQ(VisibilityOptions{.border_margin_px = -3}.problem(), "border_margin_px: -3 is below 0");
  try {
    marker_images(*camera(), database().constellations()[0], Eigen::Isometry3d::Identity(),
                  {.max_view_angle_deg = -70});
    ADD_FAILURE() << "a negative angle accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "VisibilityOptions::max_view_angle_deg: -70 is not in [0, 90]");
  }
}

// A negative density would take uncertainty away: the covariance would stop being one.
TEST(BodyMotionOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(BodyMotionOptions{}.problem(), std::nullopt);
  EXPECT_EQ(BodyMotionOptions{.angular_acceleration_density = -1}.problem(),
            "angular_acceleration_density: -1 is below 0");
  EXPECT_EQ(BodyMotionOptions{.initial_linear_velocity_sigma_mps = -2}.problem(),
            "initial_linear_velocity_sigma_mps: -2 is below 0");
  try {
    BodyMotionFilter filter(Eigen::Isometry3d::Identity(), Matrix6d::Identity(), 0,
                            {.linear_acceleration_density = -2});
    ADD_FAILURE() << "a negative density accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "BodyMotionOptions::linear_acceleration_density: -2 is below 0");
  }
}

TEST(SequenceOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(evaluation::SequenceOptions{}.problem(), std::nullopt);
  EXPECT_EQ(evaluation::SequenceOptions{.position_bound_m = 0}.problem(),
            "position_bound_m: 0 is not above 0");
  EXPECT_EQ(evaluation::SequenceOptions{.orientation_bound_deg = 0}.problem(),
            "orientation_bound_deg: 0 is not above 0");
  try {
    evaluation::SequenceEvaluator evaluator({.position_bound_m = -0.05});
    ADD_FAILURE() << "a negative bound accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "SequenceOptions::position_bound_m: -0.05 is not above 0");
  }
}

}  // namespace
}  // namespace mocap::tracking
