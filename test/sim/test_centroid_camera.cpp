// The centroid camera: markers projected to centroids as a motion-capture camera reports them,
// merged where their images touch, left out where the frame's edge cuts them or something
// hides them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include <mocap/calibration/pinhole_camera.hpp>

#include "sim/centroid_camera/centroid_camera.hpp"

namespace mocap::synthetic {
namespace {

// An ideal 640x480 lens looking along the world's z from the origin.
std::shared_ptr<const calibration::CameraModel> ideal_camera() {
  calibration::PinholeIntrinsics intrinsics;
  intrinsics.fx = intrinsics.fy = 600;
  intrinsics.cx = 319.5;
  intrinsics.cy = 239.5;
  return std::make_shared<calibration::PinholeCamera>(640, 480, intrinsics);
}

CentroidCameraOptions without_noise() {
  CentroidCameraOptions options;
  options.noise_px = 0;
  return options;
}

TEST(CentroidCamera, AMarkerIsWhereTheModelProjectsIt) {
  CentroidCamera camera(ideal_camera(), Eigen::Isometry3d::Identity(), without_noise(), 1);
  const std::vector<Centroid> seen = camera.project({{0.1, -0.05, 2.0}});
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_NEAR(seen[0].pixel.x(), 319.5 + 600 * 0.05, 1e-9);
  EXPECT_NEAR(seen[0].pixel.y(), 239.5 - 600 * 0.025, 1e-9);
  // 14 mm at 2 m: 4.2 px wide.
  EXPECT_NEAR(seen[0].diameter_px, 600 * 0.014 / Eigen::Vector3d(0.1, -0.05, 2).norm(), 1e-9);
  EXPECT_EQ(seen[0].markers, std::vector<int>{0});
  EXPECT_EQ(seen[0].sigma_px, 0);
}

TEST(CentroidCamera, TheNoiseHasTheSigmaAsked) {
  CentroidCameraOptions options;
  options.noise_px = 0.05;
  CentroidCamera camera(ideal_camera(), Eigen::Isometry3d::Identity(), options, 7);
  double squared = 0;
  const int draws = 4000;
  for (int i = 0; i < draws; ++i) {
    const std::vector<Centroid> seen = camera.project({{0, 0, 2.0}});
    ASSERT_EQ(seen.size(), 1u);
    squared += (seen[0].pixel - Eigen::Vector2d(319.5, 239.5)).squaredNorm();
    EXPECT_DOUBLE_EQ(seen[0].sigma_px, 0.05);
  }
  // Two axes of 0.05 px each: within 5 % over 4000 draws.
  EXPECT_NEAR(std::sqrt(squared / (2 * draws)), 0.05, 0.0025);
}

TEST(CentroidCamera, MarkersWhoseImagesTouchAreOneBlobAtTheirAreaWeightedCentre) {
  CentroidCamera camera(ideal_camera(), Eigen::Isometry3d::Identity(), without_noise(), 1);
  // 12 mm apart at 2 m: 3.6 px apart, images 4.2 px wide. A third far away stays alone.
  const std::vector<Centroid> seen = camera.project({{0, 0, 2.0}, {0.012, 0, 2.0}, {-0.3, 0, 2.0}});
  ASSERT_EQ(seen.size(), 2u);
  const Centroid& blob = seen[0].markers.size() == 2 ? seen[0] : seen[1];
  EXPECT_EQ(blob.markers, (std::vector<int>{0, 1}));
  EXPECT_NEAR(blob.pixel.x(), 319.5 + 1.8, 0.01);  // the same sizes: halfway
  EXPECT_NEAR(blob.sigma_px, 1.8, 0.01);           // each marker 1.8 px from the blob's centre
  // 30 mm apart: 9 px, two centroids.
  EXPECT_EQ(camera.project({{0, 0, 2.0}, {0.03, 0, 2.0}}).size(), 2u);
}

TEST(CentroidCamera, AMarkerTheFramesEdgeCutsOrSomethingHidesIsNotReported) {
  CentroidCamera camera(ideal_camera(), Eigen::Isometry3d::Identity(), without_noise(), 1);
  // Its centre 1 px inside the left edge, its image 4.2 px wide.
  const double x = (-0.5 + 1.0 - 319.5) / 600 * 2.0;
  EXPECT_TRUE(camera.project({{x, 0, 2.0}}).empty());
  EXPECT_EQ(camera.project({{x + 0.01, 0, 2.0}}).size(), 1u);
  EXPECT_TRUE(camera.project({{0, 0, -2.0}}).empty());  // behind

  // A sphere between the camera and a marker hides it; one the marker sits on does not.
  const std::vector<OccludingSphere> spheres = {{{0, 0, 1.0}, 0.05}, {{0.5, 0, 2.0}, 0.05}};
  const std::vector<Centroid> seen =
      camera.project({{0, 0, 2.0}, {0.5, 0, 1.95}, {0.3, 0, 2.0}}, spheres);
  ASSERT_EQ(seen.size(), 2u);
  for (const Centroid& centroid : seen) EXPECT_NE(centroid.markers[0], 0);

  // An image-space occluder.
  const std::vector<Eigen::AlignedBox2d> hidden = {
      Eigen::AlignedBox2d(Eigen::Vector2d(300, 200), Eigen::Vector2d(340, 280))};
  EXPECT_TRUE(camera.project({{0, 0, 2.0}}, {}, hidden).empty());
  EXPECT_EQ(camera.project({{0.3, 0, 2.0}}, {}, hidden).size(), 1u);
}

// 400 markers among forty spheres, one around the camera and one behind it, the camera
// turned: exactly the markers whose line of sight a sphere crosses are hidden (the camera
// tests a marker only against the spheres of its image column).
TEST(CentroidCamera, HidesExactlyTheMarkersBehindASphere) {
  Eigen::Isometry3d camera_from_world = Eigen::Isometry3d::Identity();
  camera_from_world.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  camera_from_world.translation() = Eigen::Vector3d(0.2, -0.1, 0.3);
  const Eigen::Vector3d camera_centre = camera_from_world.inverse().translation();
  std::mt19937 random(3);
  // Across a little more than the 640x480 image's field (x / z within 0.53, y / z 0.4).
  std::uniform_real_distribution<double> across(-0.6, 0.6), depth(0.2, 4.0), radius(0.01, 0.05);
  const auto in_front = [&] {
    // One draw after the other: the draws of one expression come in an order each compiler
    // picks.
    const double z = depth(random);
    const double x = across(random);
    const double y = across(random);
    return camera_from_world.inverse() * Eigen::Vector3d(x * z, y * z, z);
  };
  std::vector<OccludingSphere> spheres;
  for (int s = 0; s < 40; ++s) spheres.push_back({in_front(), radius(random)});
  spheres.push_back({camera_centre + Eigen::Vector3d(0, 0.05, 0), 0.1});  // around the camera
  spheres.push_back({camera_from_world.inverse() * Eigen::Vector3d(0, 0, -1), 0.5});  // behind
  std::vector<Eigen::Vector3d> markers;
  for (int m = 0; m < 400; ++m) markers.push_back(in_front());

  // By hand, every marker against every sphere: on a sphere's surface or in it, a marker
  // belongs to it; otherwise it is hidden when the point of its line of sight nearest the
  // sphere's centre lies between the camera and the marker, inside the sphere.
  const auto hidden = [&](const Eigen::Vector3d& marker) {
    for (const OccludingSphere& sphere : spheres) {
      if ((marker - sphere.centre).norm() <= sphere.radius_m) continue;
      const Eigen::Vector3d line = marker - camera_centre;
      const double along = (sphere.centre - camera_centre).dot(line) / line.squaredNorm();
      if (along > 0 && along < 1 &&
          (camera_centre + along * line - sphere.centre).norm() < sphere.radius_m) {
        return true;
      }
    }
    return false;
  };
  CentroidCamera camera(ideal_camera(), camera_from_world, without_noise(), 1);
  std::set<int> in_the_image, seen;
  for (const Centroid& centroid : camera.project(markers)) {
    in_the_image.insert(centroid.markers.begin(), centroid.markers.end());
  }
  for (const Centroid& centroid : camera.project(markers, spheres)) {
    seen.insert(centroid.markers.begin(), centroid.markers.end());
  }
  std::set<int> expected;
  for (int m : in_the_image) {
    if (!hidden(markers[static_cast<size_t>(m)])) expected.insert(m);
  }
  EXPECT_EQ(seen, expected);
  EXPECT_GT(in_the_image.size(), expected.size() + 50) << "too few hidden: the test tests little";
  EXPECT_GT(expected.size(), 20u) << "too few seen: the test tests little";
}

TEST(CentroidCamera, BadOptionsAreRefusedNamingTheField) {
  CentroidCameraOptions options;
  options.noise_px = -1;
  try {
    CentroidCamera camera(ideal_camera(), Eigen::Isometry3d::Identity(), options, 1);
    FAIL() << "negative noise accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "CentroidCameraOptions::noise_px: -1 is below 0");
  }
  EXPECT_TRUE(CentroidCameraOptions{}.problem() == std::nullopt);
}

}  // namespace
}  // namespace mocap::synthetic
