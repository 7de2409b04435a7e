#include "volume/volume_calibration/volume_calibration.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include <mocap/calibration/calibration_config.hpp>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/floor_frame.hpp>

#include "tracking/pose_estimator/planar_pose.hpp"
#include "volume/pose_fusion/pose_fusion.hpp"

namespace mocap::volume {
namespace {

// The cameras that saw the whole board at one capture time, each with its pixels.
struct Frame {
  int64_t stamp_ns = 0;
  std::map<size_t, std::vector<Eigen::Vector2d>> views;
};

// A board seen nearly edge-on (its image thinner than this across, pixels) fixes no pose.
constexpr double kMinBoardWidthPx = 3;

// The sighting's pixels when it shows every marker and the board is not edge-on.
std::optional<std::vector<Eigen::Vector2d>> whole(const BoardSighting& sighting, size_t markers) {
  if (sighting.pixels.size() != markers) return std::nullopt;
  std::vector<Eigen::Vector2d> pixels;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& pixel : sighting.pixels) {
    if (!pixel) return std::nullopt;
    pixels.push_back(*pixel);
    mean += *pixel / static_cast<double>(markers);
  }
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : pixels) scatter += (p - mean) * (p - mean).transpose();
  scatter /= static_cast<double>(markers);
  const double narrowest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues().minCoeff();
  if (narrowest < kMinBoardWidthPx * kMinBoardWidthPx) return std::nullopt;
  return pixels;
}

std::vector<Frame> frames_of(std::vector<BoardSighting> sightings, size_t markers,
                             const VolumeCalibrationOptions& options) {
  std::sort(sightings.begin(), sightings.end(),
            [](const BoardSighting& a, const BoardSighting& b) { return a.stamp_ns < b.stamp_ns; });
  const auto same = static_cast<int64_t>(options.same_capture_s * 1e9);
  std::vector<Frame> frames;
  for (const BoardSighting& sighting : sightings) {
    std::optional<std::vector<Eigen::Vector2d>> pixels = whole(sighting, markers);
    if (!pixels) continue;
    if (frames.empty() || sighting.stamp_ns - frames.back().stamp_ns > same) {
      frames.push_back({sighting.stamp_ns, {}});
    }
    frames.back().views[sighting.camera] = std::move(*pixels);
  }
  std::erase_if(frames, [](const Frame& frame) { return frame.views.size() < 2; });
  if (frames.size() > options.max_frames) {
    std::vector<Frame> spread;
    for (size_t i = 0; i < options.max_frames; ++i) {
      spread.push_back(std::move(frames[i * frames.size() / options.max_frames]));
    }
    frames = std::move(spread);
  }
  return frames;
}

// Each camera's pose relative to camera 0 from single-camera board poses of the capture times
// it shares with a camera already placed: the solve's start.
std::vector<Eigen::Isometry3d> starting_poses(const std::vector<CalibrationCamera>& cameras,
                                              const std::vector<Eigen::Vector3d>& board,
                                              const std::vector<Frame>& frames) {
  std::vector<std::map<size_t, Eigen::Isometry3d>> seen(frames.size());  // camera_from_board
  for (size_t f = 0; f < frames.size(); ++f) {
    for (const auto& [c, pixels] : frames[f].views) {
      const pose::PlanarPose pose = pose::estimate_planar_pose(*cameras[c].model, board, pixels);
      if (pose.valid) seen[f][c] = pose.camera_from_object;
    }
  }
  std::vector<std::optional<Eigen::Isometry3d>> placed(cameras.size());
  placed[0] = Eigen::Isometry3d::Identity();
  for (bool grew = true; grew;) {
    grew = false;
    for (const auto& views : seen) {
      for (const auto& [known, known_from_board] : views) {
        if (!placed[known]) continue;
        for (const auto& [c, camera_from_board] : views) {
          if (placed[c]) continue;
          placed[c] = camera_from_board * known_from_board.inverse() * *placed[known];
          grew = true;
        }
      }
    }
  }
  std::vector<Eigen::Isometry3d> poses;
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (!placed[c]) {
      throw VolumeCalibrationError(fmt::format(
          "camera {}: no capture time shows it the whole board together with a camera tied to "
          "{}; wave the board where it and its neighbours see it",
          cameras[c].name, cameras[0].name));
    }
    poses.push_back(*placed[c]);
  }
  return poses;
}

calibration::CalibrationConfig problem_of(const std::vector<CalibrationCamera>& cameras,
                                          const std::vector<Eigen::Vector3d>& board,
                                          const std::vector<Frame>& frames,
                                          const std::vector<Eigen::Isometry3d>& start) {
  using namespace calibration;
  CalibrationConfig config;
  config.source = "volume calibration";
  config.transformations.push_back({"board", false, false, false, 1.0, std::nullopt});
  for (size_t c = 0; c < cameras.size(); ++c) {
    const CalibrationCamera& camera = cameras[c];
    config.cameras.push_back(
        {camera.name, camera.model->type(), true, camera_parameters(*camera.model)});
    DataSpec data;
    data.type = "ir_data";
    data.camera = camera.name;
    if (c > 0) {
      const std::string link = camera.name + "_from_" + cameras[0].name;
      config.transformations.push_back({link, true, false, false, 1.0, start[c]});
      data.transform_chain.push_back({link, true});
    }
    data.transform_chain.push_back({"board", true});
    data.image_width = camera.model->width();
    data.image_height = camera.model->height();
    data.data_file = data.data_path = "waved";  // one data file: shots of a frame share a pose
    data.object_points = board;
    for (size_t i = 0; i < board.size(); ++i) data.corners.push_back(static_cast<int>(i));
    for (size_t f = 0; f < frames.size(); ++f) {
      auto view = frames[f].views.find(c);
      if (view != frames[f].views.end()) data.shots.push_back({f, view->second});
    }
    config.data.push_back(std::move(data));
  }
  return config;
}

// The board lying on the floor, fitted over every camera that saw it whole: its pose in the
// reference camera's frame.
Eigen::Isometry3d board_on_floor(const std::vector<CalibrationCamera>& cameras,
                                 const std::vector<Eigen::Isometry3d>& camera_from_reference,
                                 const std::vector<Eigen::Vector3d>& board,
                                 const FloorPlacement& placement,
                                 VolumeCalibration::Placement& fitted) {
  const std::string where =
      fmt::format("the board on the floor at ({}, {})", placement.mark.x(), placement.mark.y());
  std::vector<CameraView> views;
  std::optional<Eigen::Isometry3d> start;
  std::vector<bool> saw(cameras.size(), false);
  for (const BoardSighting& sighting : placement.sightings) {
    std::optional<std::vector<Eigen::Vector2d>> pixels = whole(sighting, board.size());
    if (!pixels || sighting.camera >= cameras.size()) continue;
    const calibration::CameraModel& model = *cameras[sighting.camera].model;
    const Eigen::Isometry3d& extrinsics = camera_from_reference[sighting.camera];
    if (!start) {
      const pose::PlanarPose pose = pose::estimate_planar_pose(model, board, *pixels);
      if (pose.valid) start = extrinsics.inverse() * pose.camera_from_object;
    }
    views.push_back({&model, extrinsics, board, std::move(*pixels), {}});
    saw[sighting.camera] = true;
  }
  if (!start) throw VolumeCalibrationError("no camera saw " + where + " whole");
  MultiCameraPoseOptions fit;
  fit.max_reprojection_rms_px = 1e9;  // reported, not judged: the views are the user's
  const MultiCameraPose pose = estimate_multi_camera_pose(views, *start, fit);
  if (!pose.valid) throw VolumeCalibrationError(where + ": " + pose.rejection);
  fitted.cameras = static_cast<size_t>(std::count(saw.begin(), saw.end(), true));
  fitted.rms_px = pose.reprojection_rms_px;
  return pose.world_from_body;
}

}  // namespace

std::optional<std::string> VolumeCalibrationOptions::problem() const {
  // Negative, no two sightings would be one capture time, and no shot would tie two cameras.
  if (!(same_capture_s >= 0)) return fmt::format("same_capture_s: {} is below 0", same_capture_s);
  if (max_frames == 0) return "max_frames: 0 leaves no capture time for the solve";
  if (!(robust_scale_px >= 0)) {
    return fmt::format("robust_scale_px: {} is below 0", robust_scale_px);
  }
  return std::nullopt;
}

VolumeCalibration calibrate_volume(const std::vector<CalibrationCamera>& cameras,
                                   const std::vector<Eigen::Vector3d>& board,
                                   const std::vector<BoardSighting>& waved,
                                   const std::vector<FloorPlacement>& on_floor,
                                   const VolumeCalibrationOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("VolumeCalibrationOptions::" + *problem);
  }
  if (cameras.empty()) throw VolumeCalibrationError("no cameras");
  if (board.size() < 4) throw VolumeCalibrationError("the board needs 4 markers or more");
  if (on_floor.empty()) {
    throw VolumeCalibrationError("no placement of the board on the floor: it sets the world frame");
  }
  if (on_floor.size() == 2) {
    throw VolumeCalibrationError(
        "the board on the floor at two marks: lay it at one, or at three or more not in a line");
  }
  const std::vector<Frame> frames = frames_of(waved, board.size(), options);
  const std::vector<Eigen::Isometry3d> start = starting_poses(cameras, board, frames);

  VolumeCalibration result;
  result.frames_used = frames.size();
  calibration::CalibrationOptions solve;
  solve.robust_scale_px = options.robust_scale_px;
  solve.compute_covariance = false;
  solve.on_iteration = options.on_iteration;
  std::vector<Eigen::Isometry3d> camera_from_reference(cameras.size());
  try {
    calibration::CalibrationProblem problem(problem_of(cameras, board, frames, start), solve);
    result.report = problem.solve();
    if (!result.report.converged) {
      throw VolumeCalibrationError("the solve did not converge: " + result.report.termination);
    }
    for (const auto& [name, pose] : problem.camera_poses(cameras[0].name)) {
      for (size_t c = 0; c < cameras.size(); ++c) {
        if (cameras[c].name == name) camera_from_reference[c] = pose;
      }
    }
  } catch (const calibration::CalibrationError& e) {
    throw VolumeCalibrationError(e.what());
  }

  std::vector<Eigen::Isometry3d> reference_from_board;
  for (const FloorPlacement& placement : on_floor) {
    VolumeCalibration::Placement fitted;
    reference_from_board.push_back(
        board_on_floor(cameras, camera_from_reference, board, placement, fitted));
    result.floor.push_back(fitted);
  }
  Eigen::Isometry3d reference_from_world;
  if (on_floor.size() == 1) {
    reference_from_world =
        calibration::reference_from_world_of_board(reference_from_board[0], on_floor[0].mark);
  } else {
    std::vector<Eigen::Vector3d> centres;
    std::vector<Eigen::Vector2d> marks;
    for (size_t p = 0; p < on_floor.size(); ++p) {
      centres.push_back(reference_from_board[p].translation());
      marks.push_back(on_floor[p].mark);
    }
    const std::optional<Eigen::Isometry3d> fitted =
        calibration::reference_from_world_of_marks(centres, marks);
    if (!fitted) {
      throw VolumeCalibrationError(
          "the floor's marks lie in a line, or set the cameras under the floor (x and y "
          "swapped?): give three or more marks that span the floor");
    }
    reference_from_world = *fitted;
    for (size_t p = 0; p < on_floor.size(); ++p) {
      const Eigen::Vector3d centre = reference_from_world.inverse() * centres[p];
      result.floor[p].off_mark_m = (centre - Eigen::Vector3d(marks[p].x(), marks[p].y(), 0)).norm();
    }
  }
  result.camera_from_world =
      calibration::cameras_in_world(camera_from_reference, reference_from_world);
  return result;
}

}  // namespace mocap::volume
