// The volume's cameras calibrated from rendered images, in process, as
// scripts/calibrate_volume.sh does it live: the calibration scenes (config/volume/
// calibration_wave.yaml, calibration_floor.yaml) rendered through the demo's four cameras at
// 30 Hz, fiducials detected, each camera's board markers paired with their detections, and
// solved by calibrate_volume. The frames are rendered at exact scene times, so a run gives the
// same cameras every time; live, the cameras' capture times fall anywhere on the path.
//
//   RenderedCalibrationScenes scenes(config_dir);
//   auto waved = scenes.waved(60);            // the first 60 s of the wave
//   auto floor = scenes.on_floor(kFloorMarks, {0, 180});  // each mark laid twice, turned
//   VolumeCalibration result = calibrate_volume(scenes.cameras(), scenes.board(), waved, floor);
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <mocap/calibration/camera_file.hpp>

#include "sim/synthetic_ir_camera/ir_renderer.hpp"
#include "sim/synthetic_ir_camera/scene.hpp"
#include "test/volume/rendered_volume.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "tracking/fiducial_tracker/fiducial_tracker.hpp"
#include "volume/volume_calibration/volume_calibration.hpp"

namespace mocap::volume::test {

// scripts/calibrate_volume.sh's marks: the floor's centre, 1 m along each axis and the corners
// of that square.
inline const std::vector<Eigen::Vector2d> kFloorMarks = {
    {0, 0}, {1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 1}, {-1, 1}, {-1, -1}, {1, -1}};

// How far a calibrated camera lies from where it renders from.
struct CameraOffset {
  double position_m = 0;
  double rotation_deg = 0;
};

inline CameraOffset camera_offset(const Eigen::Isometry3d& calibrated_camera_from_world,
                                  const Eigen::Isometry3d& true_camera_from_world) {
  const Eigen::Isometry3d calibrated = calibrated_camera_from_world.inverse();
  const Eigen::Isometry3d truth = true_camera_from_world.inverse();
  return {(calibrated.translation() - truth.translation()).norm(),
          Eigen::AngleAxisd(calibrated.linear().transpose() * truth.linear()).angle() * 180 /
              std::acos(-1.0)};
}

class RenderedCalibrationScenes {
 public:
  static constexpr double kRateHz = 30;

  explicit RenderedCalibrationScenes(const std::string& config_dir)
      : volume_(config_dir + "/volume/"),
        boards_(constellations::load_database(config_dir + "/constellations.yaml")) {
    for (int c = 0; c < 4; ++c) {
      const auto file =
          calibration::load_camera_file(volume_ + "cameras/cam_" + std::to_string(c) + ".yaml");
      cameras_.push_back({file.name, file.model});
      true_camera_from_world_.push_back(file.world_from_camera->inverse());
    }
  }

  const std::vector<CalibrationCamera>& cameras() const { return cameras_; }
  // Where the cameras render from: the truth a calibration is measured against.
  const std::vector<Eigen::Isometry3d>& true_camera_from_world() const {
    return true_camera_from_world_;
  }
  // The calibration board's markers, indexing the sightings' pixels.
  const std::vector<Eigen::Vector3d>& board() const { return scene_board()->points; }

  // The first `seconds` of the board carried through the volume.
  std::vector<BoardSighting> waved(double seconds) const {
    return sightings("calibration_wave.yaml", Eigen::Isometry3d::Identity(),
                     static_cast<int>(seconds * kRateHz));
  }

  // The board lying still on the floor for `seconds` at each mark, laid once per turn about its
  // centre (degrees; {0, 180}: a second time turned half round, as scripts/calibrate_volume.sh).
  std::vector<FloorPlacement> on_floor(const std::vector<Eigen::Vector2d>& marks,
                                       const std::vector<double>& turns_deg,
                                       double seconds = 3) const {
    std::vector<FloorPlacement> placements;
    for (const Eigen::Vector2d& mark : marks) {
      for (double turn : turns_deg) {
        const Eigen::Isometry3d laid =
            Eigen::Translation3d(mark.x(), mark.y(), 0) *
            Eigen::AngleAxisd(turn * std::acos(-1.0) / 180, Eigen::Vector3d::UnitZ());
        placements.push_back(
            {mark, sightings("calibration_floor.yaml", laid, static_cast<int>(seconds * kRateHz))});
      }
    }
    return placements;
  }

 private:
  const constellations::ConstellationModel* scene_board() const { return boards_.find("board_a"); }

  // Each camera's view of the scene's one board, moved by `world_from_scene`: per frame, the
  // detection nearest each visible marker's true pixel (within 1.5 px), by marker index.
  std::vector<BoardSighting> sightings(const std::string& scene_file,
                                       const Eigen::Isometry3d& world_from_scene,
                                       int frames) const {
    const synthetic::Scene scene = synthetic::load_scene(volume_ + scene_file, boards_);
    tracking::FiducialDetector detector;
    std::vector<BoardSighting> out;
    for (size_t c = 0; c < cameras_.size(); ++c) {
      synthetic::IrRenderer renderer(scene, cameras_[c].model);
      for (int f = 0; f < frames; ++f) {
        const synthetic::RenderedFrame rendered = renderer.render(
            f / kRateHz, static_cast<uint64_t>(f), true_camera_from_world_[c] * world_from_scene);
        std::vector<Eigen::Vector2d> detections;
        for (const auto& fiducial : detector.detect(rendered.image)) {
          detections.emplace_back(fiducial.x, fiducial.y);
        }
        BoardSighting sighting{static_cast<int64_t>(f * 1e9 / kRateHz), c, {}};
        bool seen = false;
        for (const synthetic::MarkerTruth& marker : rendered.objects[0].markers) {
          sighting.pixels.push_back(marker.visible ? detection_of(detections, marker.pixel)
                                                   : std::nullopt);
          seen = seen || sighting.pixels.back().has_value();
        }
        if (seen) out.push_back(std::move(sighting));
      }
    }
    return out;
  }

  std::string volume_;
  constellations::ConstellationDatabase boards_;
  std::vector<CalibrationCamera> cameras_;
  std::vector<Eigen::Isometry3d> true_camera_from_world_;
};

}  // namespace mocap::volume::test
