// The seed's PixArt ceiling rig (config/pixart/rig.yaml: four cameras 1 m apart at 2.5 m, looking
// down, each turned 90 degrees from the last) calibrated from synthetic shots of the seed's 4-LED
// board (seed 002 §8.4) held around the LED plane: the truth, the configuration the seed would
// write for it and the errors of a solution against the truth. Shared by the calibration test and
// bench/calibration_bench.cpp, so that the test checks the shot set the bench tabulates.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <mocap/calibration/calibration_config.hpp>
#include <mocap/calibration/calibration_problem.hpp>
#include <mocap/calibration/lens_models.hpp>

#include "../draw_order.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"

namespace mocap::calibration::synthetic {

constexpr double kDegree = M_PI / 180;
constexpr int kRigWidth = 1024, kRigHeight = 768;

inline const std::vector<Eigen::Vector3d>& seed_board() {
  static const std::vector<Eigen::Vector3d> board = {
      {0, 0.12, 0}, {0, 0, 0}, {0.262, 0, 0}, {0.262, 0.12, 0}};
  return board;
}

struct RigCameraTruth {
  std::string name;
  std::vector<double> intrinsics;                             // EUCM: alpha, beta, fu, fv, u0, v0
  Eigen::Isometry3d nominal = Eigen::Isometry3d::Identity();  // world_from_camera, rig.yaml's
  Eigen::Isometry3d mounted = Eigen::Isometry3d::Identity();  // world_from_camera, the truth
};

// The defaults are the shot set bench/calibration_bench.cpp tabulates and the test checks.
struct RigShotOptions {
  int frames = 800;               // board positions drawn; those no camera sees whole are dropped
  double height_m = 0.45;         // the LED plane
  double height_spread_m = 0.10;  // the board's centre within ± this of it
  double max_tilt_deg = 25;
  uint32_t seed = 1;
};

struct RigScenario {
  std::vector<RigCameraTruth> cameras;    // the first is the reference: its frame is the board's
  std::vector<Eigen::Isometry3d> boards;  // world_from_board, one per frame
};

// Board poses spread over one camera's whole view at 1.2 to 2.5 m, tilted up to 35 degrees
// either way: corners of the image show the lens's distortion, tilts its focal length.
inline std::vector<Eigen::Isometry3d> spread_board_poses(int count, std::mt19937& random) {
  std::uniform_real_distribution<double> across(-0.3, 0.3), down(-0.22, 0.22), depth(1.2, 2.5),
      tilt(-35 * kDegree, 35 * kDegree), yaw(-M_PI, M_PI);
  std::vector<Eigen::Isometry3d> poses;
  while (static_cast<int>(poses.size()) < count) {
    const double d = depth(random);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    // Last first (draw_order.hpp).
    const double about_y = tilt(random), about_x = tilt(random), about_z = yaw(random);
    pose.linear() = (Eigen::AngleAxisd(about_z, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(about_x, Eigen::Vector3d::UnitX()) *
                     Eigen::AngleAxisd(about_y, Eigen::Vector3d::UnitY()))
                        .toRotationMatrix();
    // The board's centre at the chosen place.
    const double y = down(random) * d, x = across(random) * d;
    pose.translation() = Eigen::Vector3d(x, y, d) - pose.linear() * Eigen::Vector3d(0.131, 0.06, 0);
    poses.push_back(pose);
  }
  return poses;
}

// Pixels within the image with a margin, so that noise cannot push a point out of it.
inline std::optional<Eigen::Vector2d> rig_project(const std::vector<double>& intrinsics,
                                                  const Eigen::Vector3d& point) {
  Eigen::Vector2d pixel;
  if (!eucm_project(intrinsics.data(), point.data(), pixel.data())) return std::nullopt;
  constexpr double kMargin = 2;
  if (pixel.x() < kMargin || pixel.y() < kMargin || pixel.x() > kRigWidth - 1 - kMargin ||
      pixel.y() > kRigHeight - 1 - kMargin) {
    return std::nullopt;
  }
  return pixel;
}

// The board's points as `camera` sees them, or nothing unless it sees all four.
inline std::optional<std::vector<Eigen::Vector2d>> rig_view(const RigCameraTruth& camera,
                                                            const Eigen::Isometry3d& board) {
  std::vector<Eigen::Vector2d> pixels;
  const Eigen::Isometry3d camera_from_board = camera.mounted.inverse() * board;
  for (const Eigen::Vector3d& led : seed_board()) {
    auto pixel = rig_project(camera.intrinsics, camera_from_board * led);
    if (!pixel) return std::nullopt;
    pixels.push_back(*pixel);
  }
  return pixels;
}

// The four cameras as rig.yaml hangs them, ordered by camera id so that camera0 (the reference)
// gets the seed's cam0 result and camera1 its cam1 result (seed 002); the other two are made up
// nearby. Each is mounted up to 2 cm and 1 degree off its nominal pose, as hand-mounted cameras
// are, so that the prior on the transforms between them is not the answer.
inline std::vector<RigCameraTruth> ceiling_cameras(uint32_t seed = 7) {
  // The seed's cam0 had alpha at 0, where beta plays no part; a little alpha keeps every value
  // observable, so the table compares like with like.
  std::vector<RigCameraTruth> cameras = {
      {"camera0", {0.02, 0.36035, 1203.23, 1204.24, 526.616, 389.011}, {}, {}},
      {"camera1", {0.108349, 1.60597, 1220.57, 1216.91, 522.642, 393.629}, {}, {}},
      {"camera2", {0.06, 1.1, 1195.4, 1197.8, 509.3, 381.2}, {}, {}},
      {"camera3", {0.09, 0.8, 1211.8, 1210.1, 517.9, 379.4}, {}, {}}};
  const Eigen::Vector3d positions[] = {
      {0.5, 0.5, 2.5}, {-0.5, 0.5, 2.5}, {-0.5, -0.5, 2.5}, {0.5, -0.5, 2.5}};
  const double yaws_deg[] = {180, 270, 0, 90};
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (size_t i = 0; i < cameras.size(); ++i) {
    cameras[i].nominal = pixart::downward_camera_pose(positions[i], yaws_deg[i]);
    const Eigen::Vector3d axis = mocap::test::draw_last_first<3>(unit, random);
    const Eigen::Vector3d shift = mocap::test::draw_last_first<3>(unit, random);
    cameras[i].mounted = cameras[i].nominal;
    cameras[i].mounted.linear() =
        Eigen::AngleAxisd(1.0 * kDegree * std::abs(unit(random)), axis.normalized()) *
        cameras[i].nominal.linear();
    cameras[i].mounted.translation() += 0.02 * shift / std::sqrt(3.0);
  }
  return cameras;
}

// Board positions drawn over the union of the cameras' views at the LED plane (the four views
// overlap in the middle and pairwise along the sides, so the draw puts shots in the overlap
// zones in proportion to their area), each turned to any heading and tilted up to
// `max_tilt_deg` about a random horizontal axis. Frames no camera sees whole are dropped.
inline RigScenario ceiling_rig(const RigShotOptions& options = {}) {
  RigScenario scenario;
  scenario.cameras = ceiling_cameras();
  std::mt19937 random(options.seed);
  std::uniform_real_distribution<double> across(-1.35, 1.35), unit(-1, 1), angle(-M_PI, M_PI);
  for (int i = 0; i < options.frames; ++i) {
    const double height = options.height_m + options.height_spread_m * unit(random);
    const Eigen::Vector2d place = mocap::test::draw_last_first<2>(across, random);
    const Eigen::Vector3d centre(place.x(), place.y(), height);
    const double heading = angle(random), tilt_axis = angle(random);
    const double tilt = options.max_tilt_deg * kDegree * std::sqrt(std::abs(unit(random)));
    Eigen::Isometry3d board = Eigen::Isometry3d::Identity();
    board.linear() =
        (Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(tilt_axis), std::sin(tilt_axis), 0)) *
         Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    board.translation() = centre - board.linear() * Eigen::Vector3d(0.131, 0.06, 0);
    const bool seen =
        std::any_of(scenario.cameras.begin(), scenario.cameras.end(),
                    [&](const RigCameraTruth& c) { return rig_view(c, board).has_value(); });
    if (seen) scenario.boards.push_back(board);
  }
  return scenario;
}

// The seed's configuration for the rig: one per-shot transform "board" (the board in the
// reference camera's frame); camera i's chain [xi_i0, board] with xi_i0 = camera i from the
// reference, global, with a loose prior at the nominal poses' value (its pull is far below a
// pixel's, so the overlap zones, not rig.yaml, decide it); the reference camera's chain [board].
// Every camera starts from the seed's common guess (Code 8.2).
inline CalibrationConfig rig_config(const RigScenario& scenario, double sigma_px,
                                    uint32_t noise_seed = 1, double prior_stiffness = 1e-3) {
  std::mt19937 random(noise_seed);
  std::normal_distribution<double> noise(0, 1);
  CalibrationConfig config;
  config.source = "synthetic rig";
  config.transformations.push_back({"board", false, false, false, 1.0, std::nullopt});
  const RigCameraTruth& reference = scenario.cameras.front();
  for (size_t i = 0; i < scenario.cameras.size(); ++i) {
    const RigCameraTruth& camera = scenario.cameras[i];
    config.cameras.push_back({camera.name, "eucm", false, {0.01, 1, 1175, 1175, 512, 384}});
    DataSpec data;
    data.type = "ir_data";
    data.camera = camera.name;
    if (i > 0) {
      const std::string name = "xi" + std::to_string(i) + "0";
      config.transformations.push_back(
          {name, true, false, true, prior_stiffness, camera.nominal.inverse() * reference.nominal});
      data.transform_chain.push_back({name, true});
    }
    data.transform_chain.push_back({"board", true});
    data.image_width = kRigWidth;
    data.image_height = kRigHeight;
    // One data file for all cameras: shots of one frame share the board's pose.
    data.data_file = data.data_path = "synthetic_rig.json";
    data.object_points = seed_board();
    data.corners = {0, 1, 2, 3};
    for (size_t frame = 0; frame < scenario.boards.size(); ++frame) {
      auto pixels = rig_view(camera, scenario.boards[frame]);
      if (!pixels) continue;
      Shot shot;
      shot.frame = frame;
      for (const Eigen::Vector2d& pixel : *pixels) {
        shot.points.push_back(pixel + sigma_px * mocap::test::draw_last_first<2>(noise, random));
      }
      data.shots.push_back(std::move(shot));
    }
    config.data.push_back(std::move(data));
  }
  return config;
}

struct RigShotCounts {
  std::vector<int> per_camera;      // shots of each camera
  std::vector<int> frames_seen_by;  // [k]: frames seen by k cameras at once (k = 0..4)
};

inline RigShotCounts rig_shot_counts(const RigScenario& scenario) {
  RigShotCounts counts{std::vector<int>(scenario.cameras.size(), 0),
                       std::vector<int>(scenario.cameras.size() + 1, 0)};
  for (const Eigen::Isometry3d& board : scenario.boards) {
    int seen = 0;
    for (size_t i = 0; i < scenario.cameras.size(); ++i) {
      if (rig_view(scenario.cameras[i], board).has_value()) {
        ++counts.per_camera[i];
        ++seen;
      }
    }
    ++counts.frames_seen_by[static_cast<size_t>(seen)];
  }
  return counts;
}

struct RigErrors {
  // Per camera: the worse of fu and fv, in % of the truth; |(u0, v0) − truth| in pixels.
  std::vector<double> focal_percent, principal_px;
  // Per camera but the reference: its pose relative to the reference against the truth.
  std::vector<double> translation_mm, rotation_deg;
  // The same as the report's covariance predicts them, root mean square: √(σu0² + σv0²),
  // √(σx² + σy² + σz²), √(σrx² + σry² + σrz²); empty without covariance. These are the
  // Cramér-Rao bounds of the shots: no unbiased estimator does better on average.
  std::vector<double> predicted_principal_px, predicted_translation_mm, predicted_rotation_deg;
};

inline RigErrors rig_errors(const RigScenario& scenario, const CalibrationReport& report) {
  RigErrors errors;
  const RigCameraTruth& reference = scenario.cameras.front();
  for (size_t i = 0; i < scenario.cameras.size(); ++i) {
    const std::vector<double>& truth = scenario.cameras[i].intrinsics;
    const std::vector<double>& found = report.cameras[i].value;
    errors.focal_percent.push_back(100 * std::max(std::abs(found[2] - truth[2]) / truth[2],
                                                  std::abs(found[3] - truth[3]) / truth[3]));
    errors.principal_px.push_back(std::hypot(found[4] - truth[4], found[5] - truth[5]));
    const std::vector<double>& sd = report.cameras[i].standard_deviation;
    if (sd.size() == 6) errors.predicted_principal_px.push_back(std::hypot(sd[4], sd[5]));
    if (i == 0) continue;
    const std::vector<double>& pose_sd = report.globals[i - 1].standard_deviation;
    if (pose_sd.size() == 6) {
      errors.predicted_translation_mm.push_back(
          1e3 *
          std::sqrt(pose_sd[0] * pose_sd[0] + pose_sd[1] * pose_sd[1] + pose_sd[2] * pose_sd[2]));
      errors.predicted_rotation_deg.push_back(
          std::sqrt(pose_sd[3] * pose_sd[3] + pose_sd[4] * pose_sd[4] + pose_sd[5] * pose_sd[5]) /
          kDegree);
    }
    const Eigen::Isometry3d camera_from_reference =
        scenario.cameras[i].mounted.inverse() * reference.mounted;
    const Eigen::Isometry3d& solved = report.globals[i - 1].value;
    errors.translation_mm.push_back(
        1e3 * (solved.translation() - camera_from_reference.translation()).norm());
    errors.rotation_deg.push_back(
        Eigen::AngleAxisd(solved.linear().transpose() * camera_from_reference.linear()).angle() /
        kDegree);
  }
  return errors;
}

// The RMS per point (both coordinates) that least squares leaves of Gaussian noise of σ per
// coordinate: σ √(2 (m − p) / m) for m measurements and p unknowns (the fit absorbs p of them).
inline double expected_rms_px(const CalibrationConfig& config, double sigma_px) {
  double measurements = 0, unknowns = 0;
  std::vector<bool> frame_seen;
  for (const DataSpec& data : config.data) {
    for (const Shot& shot : data.shots) {
      measurements += 2.0 * static_cast<double>(shot.points.size());
      if (shot.frame >= frame_seen.size()) frame_seen.resize(shot.frame + 1, false);
      if (!frame_seen[shot.frame]) unknowns += 6;
      frame_seen[shot.frame] = true;
    }
  }
  for (const CameraSpec& camera : config.cameras)
    unknowns += static_cast<double>(camera.value.size());
  for (const TransformSpec& transform : config.transformations)
    unknowns += transform.global ? 6 : 0;
  return sigma_px * std::sqrt(2 * (measurements - unknowns) / measurements);
}

}  // namespace mocap::calibration::synthetic
