// Markers in 3D from a volume's cameras without labels (triangulation.hpp), and bodies
// found from them (rigid_body_identification.hpp) when no camera sees a whole body.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <random>
#include <vector>

#include "test/volume/synthetic_volume.hpp"
#include "volume/pose_fusion/pose_fusion.hpp"
#include "volume/rigid_bodies/rigid_body_identification.hpp"
#include "volume/triangulation/triangulation.hpp"

namespace mocap::volume {
namespace {

// What each camera sees of `points` (those `visible` says it sees and that fall in its image),
// with pixel noise, shuffled; truth[c][d] is the point that detection d of camera c is.
std::vector<CameraDetections> detections_of(const test::Volume& volume,
                                            const std::vector<Eigen::Vector3d>& points,
                                            double noise_px, std::mt19937& random,
                                            std::vector<std::vector<int>>& truth,
                                            const std::vector<std::vector<bool>>* visible) {
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<CameraDetections> cameras;
  truth.assign(volume.extrinsics.size(), {});
  for (size_t c = 0; c < volume.extrinsics.size(); ++c) {
    CameraDetections camera{volume.camera.get(), volume.extrinsics[c], {}, {}};
    std::vector<int> order;
    for (size_t p = 0; p < points.size(); ++p) {
      if (visible != nullptr && !(*visible)[c][p]) continue;
      const Eigen::Vector3d in_camera = volume.extrinsics[c] * points[p];
      const auto pixel = volume.camera->project(in_camera);
      if (in_camera.z() <= 0 || !pixel || !volume.camera->in_image(*pixel)) continue;
      order.push_back(static_cast<int>(p));
    }
    std::shuffle(order.begin(), order.end(), random);
    for (int p : order) {
      camera.pixels.push_back(*volume.camera->project(volume.extrinsics[c] * points[p]) +
                              test::draws<2>(noise, random));
      truth[c].push_back(p);
    }
    cameras.push_back(std::move(camera));
  }
  return cameras;
}

// Twenty markers spread through the volume: each found once, with the right detection in every
// camera that sees it, within a millimetre (median), and nothing else.
TEST(MarkerTriangulation, FindsEveryMarkerAndNoGhost) {
  const test::Volume volume;
  std::mt19937 random(2);
  std::uniform_real_distribution<double> across(-1.2, 1.2), height(0.2, 1.8);
  std::vector<double> errors;
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector2d xy = test::draws<2>(across, random);
      points.emplace_back(xy.x(), xy.y(), height(random));
    }
    std::vector<std::vector<int>> truth;
    const auto cameras = detections_of(volume, points, 0.3, random, truth, nullptr);
    const std::vector<TriangulatedMarker> markers = triangulate_markers(cameras);
    EXPECT_EQ(markers.size(), points.size()) << "trial " << trial;
    std::vector<int> found(points.size(), 0);
    for (const TriangulatedMarker& marker : markers) {
      const int point = truth[marker.observations[0].first][marker.observations[0].second];
      ++found[point];
      errors.push_back((marker.position - points[point]).norm());
      EXPECT_GE(marker.observations.size(), 2u);
      for (const auto& [c, d] : marker.observations) {
        EXPECT_EQ(truth[c][d], point) << "camera " << c << ", trial " << trial;
      }
    }
    EXPECT_EQ(std::count(found.begin(), found.end(), 1), static_cast<long>(points.size()));
  }
  // 0.3 px at 3 to 4 m from 900 px cameras is about 1.2 mm across a ray.
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 1e-3);
  EXPECT_LT(errors.back(), 4e-3);
}

// The occlusion target: a five-marker body moving through the volume at 120 Hz, every camera
// seeing three of its five markers (a different three each frame, as occluders would hide
// them), so that no camera ever sees it whole. Each frame, the markers two cameras or more see
// are triangulated and the body identified among them; its pose is then fused over every
// camera's pixels of it, markers one camera sees included. When too few markers are
// triangulated to identify it, the last pose is the start instead, as a track's would be.
TEST(MarkerTriangulation, ABodyNoCameraSeesWholeIsTrackedInNearlyEveryFrame) {
  const test::Volume volume;
  RigidBodyDatabase database;
  database.bodies.push_back({"helmet",
                             {{0, 0, 0.1},
                              {0.04, 0.09, 0.04},
                              {-0.06, 0.01, 0.12},
                              {0.05, -0.11, 0.19},
                              {0.11, 0.11, 0.04}}});
  std::mt19937 random(9);
  const int frames = 1200;  // 10 s
  int tracked = 0, identified = 0;
  std::vector<double> errors;
  std::optional<Eigen::Isometry3d> last;
  for (int frame = 0; frame < frames; ++frame) {
    // A circle of 1 m radius, 1 m up, once every 5 s (1.3 m/s), turning as it goes.
    const double t = frame / 120.0, angle = 2 * test::kPi * t / 5;
    Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
    truth.linear() = (Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(0.3 * std::sin(3 * angle), Eigen::Vector3d::UnitX()))
                         .toRotationMatrix();
    truth.translation() = Eigen::Vector3d(std::cos(angle), std::sin(angle), 1.0);
    std::vector<Eigen::Vector3d> points;
    for (const auto& marker : database.bodies[0].markers) points.push_back(truth * marker);
    std::vector<std::vector<bool>> visible(volume.extrinsics.size());
    for (auto& seen : visible) {
      std::vector<int> order = {0, 1, 2, 3, 4};
      std::shuffle(order.begin(), order.end(), random);
      seen.assign(5, false);
      for (int k = 0; k < 3; ++k) seen[order[k]] = true;
    }
    std::vector<std::vector<int>> detection_truth;
    const auto cameras = detections_of(volume, points, 0.3, random, detection_truth, &visible);
    std::vector<Eigen::Vector3d> markers;
    for (const TriangulatedMarker& marker : triangulate_markers(cameras)) {
      markers.push_back(marker.position);
    }
    const auto found = identify_rigid_bodies(database, markers);
    std::optional<Eigen::Isometry3d> start = last;
    if (found.size() == 1) {
      start = found[0].world_from_body;
      ++identified;
    }
    last.reset();
    if (!start) continue;
    const std::vector<CameraView> views =
        views_near(cameras, database.bodies[0].markers, *start, 6.0);
    const MultiCameraPose fused = estimate_multi_camera_pose(views, *start);
    if (!fused.valid) continue;
    last = fused.world_from_body;
    const double error = (fused.world_from_body.translation() - truth.translation()).norm();
    errors.push_back(error);
    if (error < 0.01) ++tracked;
  }
  EXPECT_GE(tracked, frames * 995 / 1000)
      << tracked << " of " << frames << " frames tracked, " << identified << " identified";
  std::sort(errors.begin(), errors.end());
  std::printf(
      "%d of %d frames tracked (%d identified from triangulated markers alone); "
      "position error median %.2f mm, p95 %.2f mm\n",
      tracked, frames, identified, errors[errors.size() / 2] * 1e3,
      errors[errors.size() * 95 / 100] * 1e3);
  EXPECT_LT(errors[errors.size() / 2], 1.5e-3);
}

TEST(MarkerTriangulation, BadOptionsThrow) {
  MarkerTriangulationOptions options;
  options.min_cameras = 1;
  EXPECT_THROW(triangulate_markers({}, options), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::volume
