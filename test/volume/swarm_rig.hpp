// A swarm scene (sim/swarm_scene) seen by the volume's cameras in centroid mode (sim/
// centroid_camera), tracked as the volume tracks a swarm (the marker cloud, then the swarm
// tracker), and the figures against the truth: for the swarm's tests and its benchmark.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_file.hpp>

#include "sim/centroid_camera/centroid_camera.hpp"
#include "sim/swarm_scene/swarm_scene.hpp"
#include "volume/frame_assembly/frame_assembler.hpp"
#include "volume/marker_cloud/marker_cloud.hpp"
#include "volume/swarm/swarm_tracker.hpp"

namespace mocap::volume::test {

// The volume's cameras (config/volume/cameras/cam_<c>.yaml), each sending centroids.
struct SwarmRig {
  SwarmRig(const std::string& config_dir, int cameras, synthetic::CentroidCameraOptions options,
           uint64_t seed) {
    for (int c = 0; c < cameras; ++c) {
      const calibration::CameraFile file = calibration::load_camera_file(
          config_dir + "/volume/cameras/cam_" + std::to_string(c) + ".yaml");
      centroid_cameras.emplace_back(file.model, file.world_from_camera->inverse(), options,
                                    seed * 1000 + static_cast<uint64_t>(c));
    }
  }

  // Every camera's centroids of the scene's markers at `time_s`, behind its occluders.
  std::vector<CameraDetections> frame(const synthetic::SwarmScene& scene, double time_s) {
    return frame(scene.markers(time_s), scene.occluders);
  }
  // Every camera's centroids of `markers` (world frame).
  std::vector<CameraDetections> frame(
      const std::vector<Eigen::Vector3d>& markers,
      const std::vector<synthetic::OccludingSphere>& occluders = {}) {
    std::vector<CameraDetections> detections;
    for (synthetic::CentroidCamera& camera : centroid_cameras) {
      CameraDetections seen{&camera.model(), camera.camera_from_world(), {}, {}};
      for (const synthetic::Centroid& centroid : camera.project(markers, occluders)) {
        seen.pixels.push_back(centroid.pixel);
        seen.pixel_sigma_px.push_back(centroid.sigma_px);
      }
      detections.push_back(std::move(seen));
    }
    return detections;
  }

  std::vector<synthetic::CentroidCamera> centroid_cameras;
};

// The scene's robots as a swarm database: one layout per distinct marker set, each robot
// starting where the scene has it at time 0.
inline SwarmDatabase swarm_database_of(const synthetic::SwarmScene& scene) {
  SwarmDatabase swarm;
  for (size_t r = 0; r < scene.robots.size(); ++r) {
    const synthetic::SwarmSceneRobot& robot = scene.robots[r];
    auto layout = std::find_if(swarm.layouts.begin(), swarm.layouts.end(),
                               [&](const MarkerLayout& l) { return l.markers == robot.markers; });
    if (layout == swarm.layouts.end()) {
      swarm.layouts.push_back({fmt::format("layout_{}", swarm.layouts.size()), robot.markers});
      layout = swarm.layouts.end() - 1;
    }
    swarm.robots.push_back({robot.name, static_cast<size_t>(layout - swarm.layouts.begin()),
                            scene.pose(r, 0).translation()});
  }
  return swarm;
}

struct SwarmFigures {
  int64_t robot_frames = 0;
  int64_t tracked = 0;
  // Robots reported nearer another robot's true position than their own.
  int64_t identity_swaps = 0;
  // Poses more than 5 cm or 5 degrees off their own robot's truth: what the pose evaluator
  // counts as false identifications.
  int64_t wrong_poses = 0;
  std::vector<double> position_errors_m;
  std::vector<double> orientation_errors_deg;  // robots of several markers
  MarkerCloudCounts cloud;
  // The cloud's markers over every frame, and those further than 5 mm from every true marker
  // (ghosts: rays of different markers taken for one).
  int64_t cloud_markers = 0;
  int64_t ghost_markers = 0;

  double tracked_fraction() const {
    return robot_frames == 0 ? 0 : static_cast<double>(tracked) / static_cast<double>(robot_frames);
  }
  static double median(std::vector<double> values) {
    if (values.empty()) return std::nan("");
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
  }
};

// A machine too busy to keep up, as a live graph on two saturated cores sees it (the swarm
// demo beside a browser: some cameras' centroids late in most frames, the fusion's process
// not run for a third of a second).
struct Overload {
  // Each camera's centroids miss a frame (late) with this probability.
  double camera_late_fraction = 0;
  // Every `stall_every_s`, the fusion stalls for between half and all of `stall_s`; then it
  // fuses the frames of the backlog that volume_fusion's plugin fuses (frames_to_fuse).
  double stall_every_s = 0;
  double stall_s = 0;
  double behind_max_gap_s = 0.02;
  uint64_t seed = 1;
};

// The scene seen and tracked at `rate_hz` for `duration_s`.
inline SwarmFigures track_swarm(const synthetic::SwarmScene& scene, SwarmRig& rig, double rate_hz,
                                double duration_s, MarkerCloudOptions cloud_options = {},
                                SwarmTrackerOptions swarm_options = {}, Overload overload = {}) {
  MarkerCloudTracker cloud(cloud_options);
  SwarmTracker swarm(swarm_database_of(scene), swarm_options);
  SwarmFigures figures;
  const int frames = static_cast<int>(std::lround(duration_s * rate_hz));
  std::vector<Eigen::Vector3d> truth(scene.robots.size());
  std::mt19937_64 random(overload.seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  double stall_until_s = -1;
  std::vector<int> backlog;  // frames captured during a stall
  std::optional<int64_t> last_fused_ns;
  const auto stamp_of = [&](int f) { return std::llround(f / rate_hz * 1e9); };
  for (int next = 0; next < frames; ++next) {
    const double next_s = next / rate_hz;
    if (overload.stall_every_s > 0 && next > 0 &&
        std::floor(next_s / overload.stall_every_s) >
            std::floor((next - 1) / rate_hz / overload.stall_every_s)) {
      stall_until_s = next_s + overload.stall_s * (0.5 + 0.5 * uniform(random));
    }
    backlog.push_back(next);
    if (next_s < stall_until_s) continue;
    std::vector<int64_t> stamps;
    for (int f : backlog) stamps.push_back(stamp_of(f));
    std::vector<int> fused;
    for (size_t i :
         frames_to_fuse(stamps, last_fused_ns, 2, std::llround(overload.behind_max_gap_s * 1e9))) {
      fused.push_back(backlog[i]);
    }
    last_fused_ns = stamps.back();
    backlog.clear();
    for (int f : fused) {
      const double time_s = f / rate_hz;
      const auto stamp_ns = static_cast<int64_t>(std::llround(time_s * 1e9));
      const std::vector<Eigen::Vector3d> true_markers = scene.markers(time_s);
      std::vector<CameraDetections> seen = rig.frame(true_markers, scene.occluders);
      for (CameraDetections& camera : seen) {
        if (uniform(random) >= overload.camera_late_fraction) continue;
        camera.pixels.clear();
        camera.pixel_sigma_px.clear();
      }
      const std::vector<CloudMarker> markers = cloud.track(stamp_ns, seen);
      const std::vector<SwarmRobotPose> poses = swarm.track(stamp_ns, markers);
      figures.cloud_markers += static_cast<int64_t>(markers.size());
      for (const CloudMarker& marker : markers) {
        figures.ghost_markers += std::none_of(
            true_markers.begin(), true_markers.end(),
            [&](const Eigen::Vector3d& truth) { return (truth - marker.position).norm() < 0.005; });
      }
      for (size_t r = 0; r < scene.robots.size(); ++r)
        truth[r] = scene.pose(r, time_s).translation();
      figures.robot_frames += static_cast<int64_t>(scene.robots.size());
      figures.tracked += static_cast<int64_t>(poses.size());
      for (const SwarmRobotPose& pose : poses) {
        const Eigen::Vector3d at = pose.world_from_body.translation();
        const double own = (at - truth[pose.robot]).norm();
        for (size_t other = 0; other < truth.size(); ++other) {
          if (other != pose.robot && (at - truth[other]).norm() < own) {
            ++figures.identity_swaps;
            break;
          }
        }
        figures.position_errors_m.push_back(own);
        if (pose.orientation_known) {
          const Eigen::AngleAxisd off(pose.world_from_body.linear() *
                                      scene.pose(pose.robot, time_s).linear().transpose());
          figures.orientation_errors_deg.push_back(off.angle() * 180 / 3.14159265358979323846);
        }
        const bool turned = pose.orientation_known && figures.orientation_errors_deg.back() > 5;
        if (own > 0.05 || turned) ++figures.wrong_poses;
      }
    }
  }
  figures.cloud = cloud.totals();
  return figures;
}

}  // namespace mocap::volume::test
