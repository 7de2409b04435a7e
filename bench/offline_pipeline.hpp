// The tracking pipeline as plain function calls (tracker -> identifier -> pose), without the
// runtime: what the benchmarks time and score. The plugins call the same libraries.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/calibration/camera_model.hpp>

#include "sim/synthetic_ir_camera/scene.hpp"
#include "tracking/constellation_identifier/constellation_identifier.hpp"
#include "tracking/constellation_tracker/constellation_tracker.hpp"
#include "tracking/fiducial_tracker/fiducial_tracker.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"

namespace mocap::bench {

// The shipped database and camera (config/), which the benchmarks measure with.
struct ShippedConfiguration {
  constellations::ConstellationDatabase database =
      constellations::load_database(MOCAP_CONFIG_DIR "/constellations.yaml");
  calibration::CameraFile camera =
      calibration::load_camera_file(MOCAP_CONFIG_DIR "/cameras/synthetic_ir_1280x720.yaml");
};

// A board standing still at `position` (camera frame, metres), turned by `rpy_deg` from
// facing the camera (synthetic/trajectory.hpp).
inline synthetic::SceneObject static_board(const constellations::ConstellationModel& model,
                                           const Eigen::Vector3d& position,
                                           const Eigen::Vector3d& rpy_deg) {
  synthetic::SceneObject object;
  object.constellation = model.name;
  object.markers = model.points;
  synthetic::StaticTrajectory pose;
  pose.position = position;
  pose.rpy_deg = rpy_deg;
  object.trajectory = pose;
  return object;
}

struct PipelineTimes {
  double tracker_s = 0, identifier_s = 0, pose_s = 0;
};

// What became of a frame on its way, for the benchmarks' failure reports.
struct PipelineTrace {
  size_t fiducials = 0;
  std::vector<std::string> identified;
  std::vector<std::string> rejections;  // "name: why" of poses rejected
};

struct PipelinePose {
  std::string name;
  pose::PlanarPose pose;
};

// The per-frame pipeline, as the shipped deployments ran before tracking: every frame
// identified from scratch (identifier options as the constellation_identifier plugin's), then
// planar PnP.
class OfflinePipeline {
 public:
  OfflinePipeline(const constellations::ConstellationDatabase& database,
                  std::shared_ptr<const calibration::CameraModel> camera,
                  constellations::IdentifierOptions options = {})
      : camera_(std::move(camera)), identifier_(database, options) {}

  // The fiducials of one image, pixels.
  const std::vector<Eigen::Vector2d>& detect(const cv::Mat& mono8, PipelineTimes* times = nullptr) {
    auto t0 = std::chrono::steady_clock::now();
    const auto& detected = detector_.detect(mono8);
    pixels_.clear();
    fiducials_.clear();
    for (const auto& f : detected) {
      pixels_.emplace_back(f.x, f.y);
      fiducials_.push_back({pixels_.back(), f.area_px});
    }
    if (times) {
      times->tracker_s +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return pixels_;
  }

  // The last detect()'s fiducials with their sizes, as the tracker takes them.
  const std::vector<tracking::ImageFiducial>& fiducials() const { return fiducials_; }

  // Accepted poses of one frame's fiducials.
  std::vector<PipelinePose> identify(const std::vector<Eigen::Vector2d>& pixels,
                                     PipelineTimes* times = nullptr,
                                     PipelineTrace* trace = nullptr) {
    using Clock = std::chrono::steady_clock;
    auto t1 = Clock::now();
    ideal_.clear();
    for (const auto& pixel : pixels) {
      auto ray = camera_->unproject(pixel);
      ideal_.push_back(ray ? Eigen::Vector2d(camera_->focal_length_px() * ray->head<2>())
                           : Eigen::Vector2d::Constant(NAN));
    }
    auto found = identifier_.identify(ideal_);
    auto t2 = Clock::now();
    std::vector<PipelinePose> poses;
    for (const auto& constellation : found) {
      std::vector<Eigen::Vector3d> object;
      std::vector<Eigen::Vector2d> image;
      for (size_t m = 0; m < constellation.image_point_of.size(); ++m) {
        int i = constellation.image_point_of[m];
        if (i < 0) continue;
        object.push_back(constellation.model->points[m]);
        image.push_back(pixels[i]);
      }
      pose::PlanarPose pose = pose::estimate_planar_pose(*camera_, object, image);
      if (pose.valid) poses.push_back({constellation.model->name, pose});
      if (trace) {
        trace->identified.push_back(constellation.model->name);
        if (!pose.valid)
          trace->rejections.push_back(constellation.model->name + ": " + pose.rejection);
      }
    }
    auto t3 = Clock::now();
    if (times) {
      times->identifier_s += std::chrono::duration<double>(t2 - t1).count();
      times->pose_s += std::chrono::duration<double>(t3 - t2).count();
    }
    if (trace) trace->fiducials = pixels.size();
    return poses;
  }

  std::vector<PipelinePose> run(const cv::Mat& mono8, PipelineTimes* times = nullptr,
                                PipelineTrace* trace = nullptr) {
    detect(mono8, times);
    return identify(pixels_, times, trace);
  }

 private:
  std::shared_ptr<const calibration::CameraModel> camera_;
  tracking::FiducialDetector detector_;
  constellations::ConstellationIdentifier identifier_;
  std::vector<Eigen::Vector2d> pixels_, ideal_;
  std::vector<tracking::ImageFiducial> fiducials_;
};

// The identifier's options as the per-frame deployments used them before tracking: a
// constellation from two whole lines needed two more markers, none from one line.
inline constellations::IdentifierOptions per_frame_options() {
  constellations::IdentifierOptions options;
  options.min_extra_markers = 2;
  return options;
}

}  // namespace mocap::bench
