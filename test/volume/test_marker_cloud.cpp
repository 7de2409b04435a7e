// The marker cloud: a hundred markers and more in 3D from eight cameras' centroids (0.05 px of
// noise: about 0.07 mm per axis at 3.5 m), found from scratch without ghosts, then tracked with
// persistent ids and honest covariances; merged blobs and markers one camera sees are counted,
// never triangulated.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <vector>

#include "common/marker_cloud_message/marker_cloud_message.hpp"
#include "test/test_support.hpp"
#include "test/volume/swarm_rig.hpp"
#include "volume/marker_cloud/marker_cloud.hpp"

namespace mocap::volume {
namespace {

using synthetic::SwarmScene;

constexpr double kRate_hz = 240;

synthetic::CentroidCameraOptions noise(double px) {
  synthetic::CentroidCameraOptions options;
  options.noise_px = px;
  return options;
}

test::SwarmRig eight_cameras(double noise_px = 0.05, uint64_t seed = 1) {
  return test::SwarmRig((mocap::test::source_dir() / "config").string(), 8, noise(noise_px), seed);
}

// The true marker nearest `position` and how far it is.
std::pair<size_t, double> nearest_truth(const std::vector<Eigen::Vector3d>& truth,
                                        const Eigen::Vector3d& position) {
  size_t best = 0;
  for (size_t i = 1; i < truth.size(); ++i) {
    if ((truth[i] - position).norm() < (truth[best] - position).norm()) best = i;
  }
  return {best, (truth[best] - position).norm()};
}

// Two markers 25 mm apart along x, flying together from `from` to `to` (the first's places) in
// a second.
SwarmScene two_markers_25mm_apart(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  SwarmScene scene;
  scene.duration_s = 1;
  for (double x : {0.0, 0.025}) {
    synthetic::SwarmSceneRobot robot;
    robot.name = "m" + std::to_string(scene.robots.size());
    robot.markers = synthetic::single_marker_layout();
    synthetic::SwarmLeg leg;
    leg.from = from + Eigen::Vector3d(x, 0, 0);
    leg.to = to + Eigen::Vector3d(x, 0, 0);
    robot.legs.push_back(leg);
    scene.robots.push_back(robot);
  }
  return scene;
}

TEST(MarkerCloud, AHundredMarkersFromScratchAreFoundWithoutGhosts) {
  test::SwarmRig rig = eight_cameras();
  const SwarmScene scene =
      synthetic::random_flight(synthetic::single_marker_layout(), 100, 3.0, 1.0, 0.1, 1.0, 3);
  for (int frame = 0; frame < 5; ++frame) {
    const double time_s = 0.2 * frame;
    const std::vector<Eigen::Vector3d> truth = scene.markers(time_s);
    MarkerCloudTracker cloud;  // no tracks: every frame from scratch
    const std::vector<CloudMarker> markers = cloud.track(0, rig.frame(scene, time_s));
    EXPECT_EQ(markers.size(), 100u) << "frame " << frame;
    std::set<size_t> found;
    for (const CloudMarker& marker : markers) {
      const auto [which, off_m] = nearest_truth(truth, marker.position);
      EXPECT_LT(off_m, 0.5e-3) << "a marker 0.5 mm or more from any true one: a ghost";
      found.insert(which);
      EXPECT_GE(std::popcount(marker.cameras), 3);
      EXPECT_EQ(static_cast<int>(marker.observations.size()), std::popcount(marker.cameras));
    }
    EXPECT_EQ(found.size(), markers.size()) << "two markers for one true marker";
    EXPECT_EQ(cloud.counts().started, static_cast<int>(markers.size()));
  }
}

TEST(MarkerCloud, TracksKeepTheirIdsAsTheMarkersMove) {
  test::SwarmRig rig = eight_cameras();
  const SwarmScene scene =
      synthetic::random_flight(synthetic::single_marker_layout(), 100, 3.0, 1.0, 0.1, 1.0, 5);
  MarkerCloudTracker cloud;
  std::map<uint32_t, size_t> truth_of_id;
  for (int f = 0; f < 240; ++f) {
    const double time_s = f / kRate_hz;
    const std::vector<Eigen::Vector3d> truth = scene.markers(time_s);
    const std::vector<CloudMarker> markers =
        cloud.track(static_cast<int64_t>(time_s * 1e9), rig.frame(scene, time_s));
    ASSERT_EQ(markers.size(), 100u) << "frame " << f;
    if (f > 0) {
      EXPECT_EQ(cloud.counts().tracked, 100) << "frame " << f;
      EXPECT_EQ(cloud.counts().started, 0) << "frame " << f;
    }
    for (const CloudMarker& marker : markers) {
      const auto [which, off_m] = nearest_truth(truth, marker.position);
      EXPECT_LT(off_m, 1e-3);
      // Its covariance says how far off it may be: within six sigmas (3 degrees of freedom:
      // one in ten million beyond), over 24,000 markers.
      const Eigen::Vector3d error = marker.position - truth[which];
      EXPECT_LT(error.dot(marker.covariance.inverse() * error), 36) << "marker " << marker.id;
      const auto [it, added] = truth_of_id.emplace(marker.id, which);
      EXPECT_EQ(it->second, which) << "marker " << marker.id << " changed which marker it is";
    }
  }
  EXPECT_EQ(truth_of_id.size(), 100u);
  EXPECT_EQ(cloud.totals().dropped, 0);
}

TEST(MarkerCloud, ADetectionOneCameraAloneSeesIsCountedNotTriangulated) {
  test::SwarmRig rig = eight_cameras();
  const SwarmScene scene =
      synthetic::random_flight(synthetic::single_marker_layout(), 20, 3.0, 1.0, 0.1, 1.0, 4);
  MarkerCloudTracker cloud;
  std::vector<CameraDetections> frame = rig.frame(scene, 0);
  frame[3].pixels.emplace_back(640, 300);  // a glint, or a marker only camera 3 sees
  frame[3].pixel_sigma_px.push_back(0.05);
  EXPECT_EQ(cloud.track(0, frame).size(), 20u);
  EXPECT_EQ(cloud.counts().unexplained, 1);
}

// A tracked marker seen by two cameras only, in one of them as a blob merged with a
// neighbour's (stated with a wide sigma, its centre 2 px off): two rays meet anywhere on the
// epipolar line, so the marker is not placed from them; the markers both cameras see cleanly
// are.
TEST(MarkerCloud, AMarkerOfTwoCamerasOneOfThemAMergedBlobIsNotPlaced) {
  test::SwarmRig rig = eight_cameras();
  const SwarmScene scene =
      synthetic::random_flight(synthetic::single_marker_layout(), 20, 3.0, 1.0, 0.1, 1.0, 5);
  MarkerCloudTracker cloud;
  ASSERT_EQ(cloud.track(0, rig.frame(scene, 0)).size(), 20u);
  const double time_s = 1 / kRate_hz;
  std::vector<CameraDetections> frame = rig.frame(scene, time_s);
  for (size_t c = 2; c < frame.size(); ++c) {
    frame[c].pixels.clear();
    frame[c].pixel_sigma_px.clear();
  }
  // The detection of a marker both cameras see, in camera `c`; nullopt if it does not.
  const auto detection_of = [&](const Eigen::Vector3d& marker, size_t c) -> std::optional<size_t> {
    const std::optional<Eigen::Vector2d> at = rig.centroid_cameras[c].model().project(
        rig.centroid_cameras[c].camera_from_world() * marker);
    for (size_t d = 0; at && d < frame[c].pixels.size(); ++d) {
      if ((frame[c].pixels[d] - *at).norm() < 0.5) return d;
    }
    return std::nullopt;
  };
  Eigen::Vector3d blurred;
  std::optional<size_t> blob;
  for (const Eigen::Vector3d& marker : scene.markers(time_s)) {
    blurred = marker;
    blob = detection_of(marker, 1);
    if (blob && detection_of(marker, 0)) break;
  }
  ASSERT_TRUE(blob.has_value()) << "no marker both cameras see";
  const std::optional<Eigen::Vector2d> at = rig.centroid_cameras[1].model().project(
      rig.centroid_cameras[1].camera_from_world() * blurred);
  // Along camera 0's ray as camera 1 sees it (the epipolar line): consistent with camera 0.
  const Eigen::Vector3d from_camera_0 =
      blurred - rig.centroid_cameras[0].camera_from_world().inverse().translation();
  const std::optional<Eigen::Vector2d> further = rig.centroid_cameras[1].model().project(
      rig.centroid_cameras[1].camera_from_world() * (blurred + 0.01 * from_camera_0.normalized()));
  ASSERT_TRUE(further.has_value());
  frame[1].pixels[*blob] += 1.5 * (*further - *at).normalized();
  frame[1].pixel_sigma_px[*blob] = 1.0;
  const std::vector<CloudMarker> markers = cloud.track(static_cast<int64_t>(time_s * 1e9), frame);
  EXPECT_GE(markers.size(), 10u);
  for (const CloudMarker& marker : markers) {
    EXPECT_LT(nearest_truth(scene.markers(time_s), marker.position).second, 0.5e-3);
    EXPECT_GT((marker.position - blurred).norm(), 0.005) << "placed from the merged blob";
  }
}

TEST(MarkerCloud, DetectionsWhereTwoMarkersMergeAreLeftOut) {
  // Two markers 25 mm apart along x: the two cameras on the x axis see them nearly end on, their
  // images merged; the others see them apart.
  const SwarmScene scene =
      two_markers_25mm_apart(Eigen::Vector3d(-0.2, 0, 1), Eigen::Vector3d(0.2, 0.1, 1));
  test::SwarmRig rig = eight_cameras();
  MarkerCloudTracker cloud;
  int merged = 0;
  for (int f = 0; f < 240; ++f) {
    const double time_s = f / kRate_hz;
    const std::vector<CloudMarker> markers =
        cloud.track(static_cast<int64_t>(time_s * 1e9), rig.frame(scene, time_s));
    merged += cloud.counts().merged;
    ASSERT_EQ(markers.size(), 2u) << "frame " << f;
    for (const CloudMarker& marker : markers) {
      EXPECT_LT(nearest_truth(scene.markers(time_s), marker.position).second, 0.5e-3);
    }
  }
  EXPECT_GT(merged, 0) << "no camera saw the two markers merged: the test tests nothing";
  EXPECT_EQ(cloud.totals().started, 2);
}

// A blob two tracks claim about equally (two markers merged in a camera's image) is theirs:
// three cameras' blobs of the same pair meet at the point between the markers, where there is
// none, and would start (or move a track to) a marker there.
TEST(MarkerCloud, BlobsTwoTracksClaimStartNoMarkerBetweenThem) {
  // About 7 px apart in the images of the cameras that see them apart, each within a 5 px gate
  // of the point between them.
  const SwarmScene scene =
      two_markers_25mm_apart(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0.01, 1));
  test::SwarmRig rig = eight_cameras();
  MarkerCloudOptions options;
  options.gate_px = 5;
  MarkerCloudTracker cloud(options);
  for (int f = 0; f < 10; ++f) {
    const double time_s = f / kRate_hz;
    ASSERT_EQ(cloud.track(static_cast<int64_t>(time_s * 1e9), rig.frame(scene, time_s)).size(), 2u)
        << "frame " << f;
  }
  const double time_s = 10 / kRate_hz;
  const std::vector<Eigen::Vector3d> truth = scene.markers(time_s);
  const Eigen::Vector3d between = (truth[0] + truth[1]) / 2;
  std::vector<CameraDetections> frame = rig.frame(scene, time_s);
  // Cameras 0 to 2 see one blob between the two markers; the others neither.
  for (size_t c = 0; c < frame.size(); ++c) {
    const synthetic::CentroidCamera& camera = rig.centroid_cameras[c];
    auto pixel_of = [&](const Eigen::Vector3d& point) {
      return camera.model().project(camera.camera_from_world() * point);
    };
    for (size_t d = frame[c].pixels.size(); d-- > 0;) {
      bool of_the_pair = false;
      for (const Eigen::Vector3d& marker : truth) {
        const std::optional<Eigen::Vector2d> at = pixel_of(marker);
        of_the_pair = of_the_pair || (at && (frame[c].pixels[d] - *at).norm() < 3);
      }
      if (!of_the_pair) continue;
      frame[c].pixels.erase(frame[c].pixels.begin() + static_cast<long>(d));
      frame[c].pixel_sigma_px.erase(frame[c].pixel_sigma_px.begin() + static_cast<long>(d));
    }
    if (c < 3) {
      const std::optional<Eigen::Vector2d> blob = pixel_of(between);
      ASSERT_TRUE(blob.has_value());
      frame[c].pixels.push_back(*blob);
      frame[c].pixel_sigma_px.push_back(1.0);
    }
  }
  const std::vector<CloudMarker> markers = cloud.track(static_cast<int64_t>(time_s * 1e9), frame);
  EXPECT_EQ(cloud.counts().merged, 3) << "the blobs are not both tracks': the test tests nothing";
  for (const CloudMarker& marker : markers) {
    EXPECT_GT((marker.position - between).norm(), 0.003) << "a marker where there is none";
  }
  EXPECT_EQ(cloud.counts().started, 0);
  EXPECT_EQ(cloud.counts().continued, 0);
  EXPECT_EQ(cloud.counts().coasting, 2);
}

TEST(MarkerCloud, BadOptionsAreRefusedNamingTheField) {
  MarkerCloudOptions options;
  options.min_cameras_to_start = 1;
  try {
    MarkerCloudTracker cloud(options);
    FAIL() << "one camera accepted to start a marker";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "MarkerCloudOptions::min_cameras_to_start: 1 is below 2");
  }
}

TEST(MarkerCloudMessage, ThePointCloudCarriesEveryFieldAndIsReadBack) {
  std_msgs::msg::Header header;
  header.frame_id("world");
  header.stamp().sec(12);
  const std::vector<LabeledMarker> markers = {
      {Eigen::Vector3f(0.5f, -1.25f, 1.75f), 3, 2, 41, 0.04f, 0b10110101},
      {Eigen::Vector3f(-2, 0, 0.25f), -1, 0, 7, 0.125f, 0x80000001u}};
  const sensor_msgs::msg::PointCloud2 cloud = to_point_cloud(header, markers);
  EXPECT_EQ(cloud.header().frame_id(), "world");
  EXPECT_EQ(cloud.height(), 1u);
  EXPECT_EQ(cloud.width(), 2u);
  EXPECT_EQ(cloud.point_step(), 32u);
  EXPECT_EQ(cloud.row_step(), 64u);
  EXPECT_EQ(cloud.data().size(), 64u);
  ASSERT_EQ(cloud.fields().size(), 8u);
  EXPECT_EQ(cloud.fields()[3].name(), "body");
  EXPECT_EQ(cloud.fields()[3].datatype(), 5);  // INT32
  EXPECT_EQ(cloud.fields()[4].datatype(), 4);  // UINT16
  // x of the second point, little-endian float32 at byte 32.
  float x = 0;
  std::memcpy(&x, cloud.data().data() + 32, 4);
  EXPECT_EQ(x, -2.0f);
  const auto back = markers_from_point_cloud(cloud);
  ASSERT_TRUE(back);
  ASSERT_EQ(back->size(), 2u);
  for (size_t i = 0; i < markers.size(); ++i) {
    EXPECT_EQ((*back)[i].position, markers[i].position);
    EXPECT_EQ((*back)[i].body, markers[i].body);
    EXPECT_EQ((*back)[i].marker, markers[i].marker);
    EXPECT_EQ((*back)[i].id, markers[i].id);
    EXPECT_EQ((*back)[i].residual_px, markers[i].residual_px);
    EXPECT_EQ((*back)[i].cameras, markers[i].cameras);
  }

  sensor_msgs::msg::PointCloud2 no_id = cloud;
  no_id.fields().erase(no_id.fields().begin() + 5);
  std::string problem;
  EXPECT_FALSE(markers_from_point_cloud(no_id, &problem));
  EXPECT_EQ(problem, "fields: no 'id'");
  sensor_msgs::msg::PointCloud2 short_data = cloud;
  short_data.data().resize(60);
  EXPECT_FALSE(markers_from_point_cloud(short_data, &problem));
  EXPECT_EQ(problem, "data: 60 bytes, not 2 points of 32 bytes");
}

}  // namespace
}  // namespace mocap::volume
