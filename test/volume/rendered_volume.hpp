// The volume demo (config/volume/) without processes: its scene rendered through each of its
// cameras by the simulator's renderer and detected by the fiducial detector, frame by frame,
// as its camera processes do; each body's fused pose (VolumeTracker: identified by its
// markers' distances, tracked) beside each camera's own pose of it (that camera's detections
// of the body's markers, matched to them through the renderer's truth: the best a single
// camera could do, with no identification to get wrong; from the planar pose, refined as the
// fusion refines, each pixel weighed by its fiducial's uncertainty), both against the truth.
// What the volume accuracy test and bench measure.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <mocap/calibration/camera_file.hpp>

#include "sim/synthetic_ir_camera/ir_renderer.hpp"
#include "sim/synthetic_ir_camera/scene.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "tracking/fiducial_tracker/fiducial_tracker.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"
#include "volume/rigid_bodies/rigid_body_database.hpp"
#include "volume/volume_fusion/volume_fusion.hpp"

namespace mocap::volume::test {

// The value at quantile q of `values` (nearest rank below); NaN for none.
inline double quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * static_cast<double>(values.size() - 1))];
}

// The index of the detection nearest a marker's true pixel, if one lies within 1.5 px: how a
// marker is paired with what the detector found in a rendered frame.
inline std::optional<size_t> nearest_detection(const std::vector<Eigen::Vector2d>& detections,
                                               const Eigen::Vector2d& true_pixel) {
  std::optional<size_t> nearest;
  for (size_t i = 0; i < detections.size(); ++i) {
    const double distance = (detections[i] - true_pixel).norm();
    if (distance < 1.5 && (!nearest || distance < (detections[*nearest] - true_pixel).norm())) {
      nearest = i;
    }
  }
  return nearest;
}

inline std::optional<Eigen::Vector2d> detection_of(const std::vector<Eigen::Vector2d>& detections,
                                                   const Eigen::Vector2d& true_pixel) {
  const std::optional<size_t> nearest = nearest_detection(detections, true_pixel);
  return nearest ? std::optional(detections[*nearest]) : std::nullopt;
}

struct PoseError {
  double position_m = std::numeric_limits<double>::quiet_NaN();
  double rotation_deg = std::numeric_limits<double>::quiet_NaN();
  bool posed() const { return std::isfinite(position_m); }
};

inline PoseError pose_error(const Eigen::Isometry3d& found, const Eigen::Isometry3d& truth) {
  return {(found.translation() - truth.translation()).norm(),
          Eigen::AngleAxisd(found.linear() * truth.linear().transpose()).angle() * 180 / M_PI};
}

// One body in one frame.
struct BodyFrame {
  std::string body;
  int frame = 0;
  PoseError fused;
  int cameras_used = 0;            // of the fused pose
  double normalized_rms = 0;       // of the fused pose
  double reprojection_rms_px = 0;  // of the fused pose
  // The fused pose's error in position and orientation over its covariance's (x^T C^-1 x, each
  // 3 by 3): chi-square with 3 degrees of freedom when the covariance is right.
  double position_nees = 0, orientation_nees = 0;
  std::vector<PoseError> by_camera;  // each camera's own pose; not posed where it had none
  int most_markers_seen = 0;         // by any one camera (the renderer's visible markers)
};

struct RenderedVolumeOptions {
  int frames = 150;
  double rate_hz = 30;
  double start_s = 0;       // the scene time of the first frame
  uint64_t noise_seed = 0;  // another draws other sensor noise over the same scene
  // cam_0 .. cam_{cameras-1} of config/volume/cameras: 4 is the demo, 8 its larger form.
  int cameras = 4;
  // The extrinsics the tracker uses, by camera (a calibration's); empty: the true ones, which
  // the cameras render from.
  std::vector<Eigen::Isometry3d> tracked_camera_from_world;
  // Each camera's view of the scene changed before rendering (occluders of its own); none:
  // every camera renders the demo's scene as it is.
  std::function<void(size_t camera, synthetic::Scene& scene)> per_camera;
  // The frames whose message from a camera never reaches the fusion (a camera process down, a
  // message late past the fusion's wait on a busy machine); none: every camera, every frame.
  std::function<bool(size_t camera, int frame)> missing;
};

struct RenderedVolume {
  std::vector<std::string> cameras;
  std::vector<BodyFrame> body_frames;  // every body in every frame

  // Of every body-frame the fusion posed, millimetres.
  std::vector<double> fused_position_errors_mm() const {
    std::vector<double> mm;
    for (const BodyFrame& body : body_frames) {
      if (body.fused.posed()) mm.push_back(body.fused.position_m * 1e3);
    }
    return mm;
  }
};

// Frames from scene time start_s, with the demo's files under `config_dir` and the volume_fusion
// component's settings (min_markers 5).
inline RenderedVolume render_volume(const std::string& config_dir,
                                    const RenderedVolumeOptions& rendering = {}) {
  const int frames = rendering.frames;
  const double rate_hz = rendering.rate_hz;
  const std::string volume = config_dir + "/volume/";
  const auto boards = constellations::load_database(volume + "boards.yaml");
  const synthetic::Scene scene = synthetic::load_scene(volume + "scene.yaml", boards);
  VolumeTrackerOptions options;
  options.identification.min_markers = 5;
  std::vector<VolumeCamera> cameras;
  std::vector<std::unique_ptr<synthetic::IrRenderer>> renderers;  // each keeps its buffers
  RenderedVolume out;
  for (int c = 0; c < rendering.cameras; ++c) {
    const auto file =
        calibration::load_camera_file(volume + "cameras/cam_" + std::to_string(c) + ".yaml");
    cameras.push_back({file.name, file.model, file.world_from_camera->inverse(), file.frame_id});
    synthetic::Scene seen = scene;
    if (rendering.per_camera) rendering.per_camera(static_cast<size_t>(c), seen);
    renderers.push_back(std::make_unique<synthetic::IrRenderer>(seen, file.model));
    out.cameras.push_back(file.name);
  }
  std::vector<VolumeCamera> tracked = cameras;
  for (size_t c = 0; c < rendering.tracked_camera_from_world.size() && c < tracked.size(); ++c) {
    tracked[c].camera_from_world = rendering.tracked_camera_from_world[c];
  }
  VolumeTracker tracker(tracked,
                        load_rigid_bodies(volume + "bodies.yaml", options.identification.tolerance,
                                          options.identification.min_markers),
                        options);
  tracking::FiducialDetector detector;
  for (int f = 0; f < frames; ++f) {
    const double time_s = rendering.start_s + f / rate_hz;
    const auto stamp_ns = static_cast<int64_t>(std::llround(time_s * 1e9));
    std::vector<CameraFrame> detections(cameras.size());
    std::vector<synthetic::RenderedFrame> rendered;
    for (size_t c = 0; c < cameras.size(); ++c) {
      rendered.push_back(
          renderers[c]->render(time_s, static_cast<uint64_t>(f) + rendering.noise_seed * 1000003,
                               cameras[c].camera_from_world));
      detections[c] = {true, stamp_ns, {}, {}};
      for (const auto& fiducial : detector.detect(rendered.back().image)) {
        detections[c].pixels.emplace_back(fiducial.x, fiducial.y);
        detections[c].pixel_sigma_px.push_back(fiducial.uncertainty_px);
      }
    }
    std::vector<CameraFrame> received = detections;
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (rendering.missing && rendering.missing(c, f)) received[c] = {};
    }
    const std::vector<TrackedBodyPose> fused = tracker.track(stamp_ns, received);
    for (size_t b = 0; b < scene.objects.size(); ++b) {
      BodyFrame body;
      body.body = scene.objects[b].constellation;
      body.frame = f;
      const Eigen::Isometry3d truth =
          cameras[0].camera_from_world.inverse() * rendered[0].objects[b].pose;
      for (const TrackedBodyPose& pose : fused) {
        if (pose.name != body.body) continue;
        body.fused = pose_error(pose.world_from_body, truth);
        body.cameras_used = pose.cameras_used;
        body.normalized_rms = pose.normalized_rms;
        body.reprojection_rms_px = pose.reprojection_rms_px;
        const Eigen::Vector3d position = pose.world_from_body.translation() - truth.translation();
        const Eigen::AngleAxisd turn(pose.world_from_body.linear() * truth.linear().transpose());
        const Eigen::Vector3d rotation = turn.axis() * turn.angle();
        body.position_nees =
            position.dot(pose.covariance.topLeftCorner<3, 3>().ldlt().solve(position));
        body.orientation_nees =
            rotation.dot(pose.covariance.bottomRightCorner<3, 3>().ldlt().solve(rotation));
      }
      for (size_t c = 0; c < cameras.size(); ++c) {
        // Each marker the camera sees, paired with its nearest detection within 1.5 px.
        CameraView view{cameras[c].model.get(), cameras[c].camera_from_world, {}, {}, {}};
        const synthetic::ObjectTruth& object = rendered[c].objects[b];
        body.most_markers_seen = std::max(body.most_markers_seen, object.visible_markers());
        for (size_t m = 0; m < object.markers.size(); ++m) {
          if (!object.markers[m].visible) continue;
          const std::optional<size_t> nearest =
              nearest_detection(detections[c].pixels, object.markers[m].pixel);
          if (!nearest) continue;
          view.body_points.push_back(scene.objects[b].markers[m]);
          view.pixels.push_back(detections[c].pixels[*nearest]);
          view.pixel_sigma_px.push_back(detections[c].pixel_sigma_px[*nearest]);
        }
        PoseError error;
        if (view.body_points.size() >= 4) {
          const pose::PlanarPose planar =
              pose::estimate_planar_pose(*cameras[c].model, view.body_points, view.pixels);
          if (planar.valid) {
            const MultiCameraPose refined = estimate_multi_camera_pose(
                {view}, cameras[c].camera_from_world.inverse() * planar.camera_from_object,
                options.fusion);
            if (refined.valid) error = pose_error(refined.world_from_body, truth);
          }
        }
        body.by_camera.push_back(error);
      }
      out.body_frames.push_back(std::move(body));
    }
  }
  return out;
}

// One figure of the fused poses against the camera best at that figure: over the body-frames
// both the fusion and that camera posed (each camera must pose 100 or more), the quantile `q`
// of the position (mm) or orientation (degrees) errors.
enum class Figure { Position, Orientation };
struct AgainstBestCamera {
  std::string camera;
  size_t body_frames = 0;
  double camera_value = std::numeric_limits<double>::quiet_NaN();
  double fused_value = std::numeric_limits<double>::quiet_NaN();
  double ratio() const { return camera_value / fused_value; }  // how many times better fused
};

inline AgainstBestCamera against_best_camera(const RenderedVolume& volume, Figure figure,
                                             double q) {
  auto value = [&](const PoseError& e) {
    return figure == Figure::Position ? e.position_m * 1e3 : e.rotation_deg;
  };
  AgainstBestCamera best;
  for (size_t c = 0; c < volume.cameras.size(); ++c) {
    std::vector<double> own, fused;
    for (const BodyFrame& body : volume.body_frames) {
      if (!body.fused.posed() || !body.by_camera[c].posed()) continue;
      own.push_back(value(body.by_camera[c]));
      fused.push_back(value(body.fused));
    }
    if (own.size() < 100) continue;
    if (!(quantile(own, q) >= best.camera_value)) {
      best = {volume.cameras[c], own.size(), quantile(own, q), quantile(fused, q)};
    }
  }
  return best;
}

}  // namespace mocap::volume::test
