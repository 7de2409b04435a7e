// The volume's frame-by-frame tracker (volume_fusion.hpp) on a synthetic volume: two rigid
// bodies of no particular shape moving through it, seen through occluders, with a camera that
// stops, a camera that is bumped, and bodies that only one camera keeps seeing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include "test/volume/synthetic_volume.hpp"
#include "volume/rigid_bodies/rigid_body_database.hpp"
#include "volume/volume_fusion/volume_fusion.hpp"

namespace mocap::volume {
namespace {

constexpr double kRate_hz = 120;

const char* const kBodies = R"(bodies:
  - name: helmet
    markers: [[0, 0, 0.1], [0.04, 0.09, 0.04], [-0.06, 0.01, 0.12], [0.05, -0.11, 0.19],
              [0.11, 0.11, 0.04]]
  - name: drone
    markers: [[0.16, 0, 0], [0, 0.12, 0.01], [-0.08, 0.15, 0.05], [0.1, -0.01, 0.06],
              [-0.1, 0.04, 0.09]]
)";

// Where each body is at time t: the helmet circles 1 m up, the drone flies a figure of eight
// higher up, both turning as they go.
std::vector<Eigen::Isometry3d> truth_at(double t) {
  const double a = 2 * test::kPi * t / 5, b = 2 * test::kPi * t / 7;
  Eigen::Isometry3d helmet = Eigen::Isometry3d::Identity(), drone = helmet;
  helmet.linear() = (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(0.3 * std::sin(3 * a), Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
  helmet.translation() = Eigen::Vector3d(std::cos(a), std::sin(a), 1.0);
  drone.linear() = Eigen::AngleAxisd(-b, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  drone.translation() = Eigen::Vector3d(0.8 * std::sin(b), 0.5 * std::sin(2 * b), 1.6);
  return {helmet, drone};
}

// The synthetic volume's cameras, cam_0 .. cam_3.
std::vector<VolumeCamera> cameras_of(const test::Volume& volume) {
  std::vector<VolumeCamera> cameras;
  for (size_t c = 0; c < volume.extrinsics.size(); ++c) {
    const std::string name = "cam_" + std::to_string(c);
    cameras.push_back({name, volume.camera, volume.extrinsics[c], name + "_optical"});
  }
  return cameras;
}

struct Sequence {
  const test::Volume volume;
  const RigidBodyDatabase bodies = parse_rigid_bodies(kBodies, "bodies.yaml", 0.004, 3);
  std::mt19937 random{5};

  std::vector<VolumeCamera> cameras() const { return cameras_of(volume); }

  // Each camera's detections of the bodies at `poses`, through `extrinsics` (the cameras' true
  // places), each camera missing one marker of each body at random (an occluder), shuffled.
  std::vector<CameraFrame> frame(int64_t stamp_ns, const std::vector<Eigen::Isometry3d>& poses,
                                 const std::vector<Eigen::Isometry3d>& extrinsics) {
    std::normal_distribution<double> noise(0, 0.3);
    std::vector<CameraFrame> frame(extrinsics.size());
    for (size_t c = 0; c < extrinsics.size(); ++c) {
      frame[c].received = true;
      frame[c].stamp_ns = stamp_ns;
      for (size_t b = 0; b < poses.size(); ++b) {
        const auto& markers = bodies.bodies[b].markers;
        const size_t hidden = std::uniform_int_distribution<size_t>(0, markers.size() - 1)(random);
        for (size_t m = 0; m < markers.size(); ++m) {
          const Eigen::Vector3d in_camera = extrinsics[c] * poses[b] * markers[m];
          const auto pixel = volume.camera->project(in_camera);
          if (m == hidden || in_camera.z() <= 0 || !pixel || !volume.camera->in_image(*pixel)) {
            continue;
          }
          frame[c].pixels.push_back(*pixel + test::draws<2>(noise, random));
        }
      }
      std::shuffle(frame[c].pixels.begin(), frame[c].pixels.end(), random);
    }
    return frame;
  }
};

int64_t stamp_of(int frame) { return static_cast<int64_t>(frame * 1e9 / kRate_hz); }

// The board of eight markers at `truth` as each camera whose `sees` is set sees it through
// `extrinsics` (the cameras' true places), with 0.1 px of noise; every camera's message came.
std::vector<CameraFrame> board_frame(const test::Volume& volume,
                                     const std::vector<Eigen::Isometry3d>& extrinsics,
                                     const Eigen::Isometry3d& truth, int64_t stamp_ns,
                                     const std::vector<bool>& sees, std::mt19937& random) {
  std::normal_distribution<double> noise(0, 0.1);
  std::vector<CameraFrame> frame(extrinsics.size());
  for (size_t c = 0; c < extrinsics.size(); ++c) {
    frame[c] = {true, stamp_ns, {}, {}};
    if (!sees[c]) continue;
    for (const Eigen::Vector3d& marker : test::kBoard) {
      const Eigen::Vector3d in_camera = extrinsics[c] * truth * marker;
      const auto pixel = volume.camera->project(in_camera);
      if (in_camera.z() <= 0 || !pixel || !volume.camera->in_image(*pixel)) continue;
      frame[c].pixels.push_back(*pixel + test::draws<2>(noise, random));
      frame[c].pixel_sigma_px.push_back(0.1);
    }
  }
  return frame;
}

double position_error(const TrackedBodyPose& pose, const std::vector<Eigen::Isometry3d>& truth) {
  const size_t b = pose.name == "helmet" ? 0 : 1;
  return (pose.world_from_body.translation() - truth[b].translation()).norm();
}

// 10 s at 120 Hz, every camera missing a marker of each body in every frame, and camera 2
// stopped for 2 s in the middle: both bodies posed in every frame, identified once each (the
// tracks hold throughout), within a millimetre and a half (median), velocities within 0.1 m/s.
TEST(VolumeTracker, TracksEveryBodyThroughOcclusionAndAStoppedCamera) {
  Sequence sequence;
  VolumeTracker tracker(sequence.cameras(), sequence.bodies);
  std::vector<double> errors;
  int posed = 0;
  double worst_speed_error = 0;
  const int frames = 1200;
  for (int f = 0; f < frames; ++f) {
    const std::vector<Eigen::Isometry3d> truth = truth_at(f / kRate_hz);
    std::vector<CameraFrame> frame = sequence.frame(stamp_of(f), truth, sequence.volume.extrinsics);
    if (f >= 400 && f < 640) frame[2] = CameraFrame{};
    const std::vector<TrackedBodyPose> poses = tracker.track(stamp_of(f), frame);
    for (const TrackedBodyPose& pose : poses) {
      ++posed;
      errors.push_back(position_error(pose, truth));
      EXPECT_GE(pose.cameras_used, 3) << pose.name << ", frame " << f;
      if (f > 10) {
        ASSERT_TRUE(pose.velocity_known);
        // The helmet's speed: 2 pi m in 5 s.
        if (pose.name == "helmet") {
          worst_speed_error = std::max(worst_speed_error,
                                       std::abs(pose.linear_velocity.norm() - 2 * test::kPi / 5));
        }
      }
    }
  }
  EXPECT_EQ(posed, 2 * frames);
  EXPECT_EQ(tracker.identifications(), 2);
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p99 = errors[errors.size() * 99 / 100];
  std::printf(
      "%d of %d body poses; position error median %.2f mm, p99 %.2f mm, max %.2f mm; "
      "helmet speed error up to %.3f m/s\n",
      posed, 2 * frames, median * 1e3, p99 * 1e3, errors.back() * 1e3, worst_speed_error);
  EXPECT_LT(median, 1.5e-3);
  EXPECT_LT(p99, 3e-3);
  // A frame where a marker is taken for a neighbour stays within the fusion's RMS limit.
  EXPECT_LT(errors.back(), 1e-2);
  EXPECT_LT(worst_speed_error, 0.1);
  for (const CameraHealth& health : tracker.camera_health()) EXPECT_FALSE(health.drifted);
}

// Camera 1 is knocked by 0.4 degrees after 1 s (its markers land about 6 px off): it is found
// drifted by its residuals, named, and left out, and the poses stay right.
TEST(VolumeTracker, ABumpedCameraIsFoundAndLeftOut) {
  Sequence sequence;
  VolumeTracker tracker(sequence.cameras(), sequence.bodies);
  std::vector<Eigen::Isometry3d> actual = sequence.volume.extrinsics;
  std::vector<double> errors_after;
  int found_at = -1;
  for (int f = 0; f < 720; ++f) {
    if (f == 120) {
      actual[1] = Eigen::AngleAxisd(0.4 * test::kPi / 180, Eigen::Vector3d::UnitY()) * actual[1];
    }
    const std::vector<Eigen::Isometry3d> truth = truth_at(f / kRate_hz);
    const auto poses = tracker.track(stamp_of(f), sequence.frame(stamp_of(f), truth, actual));
    if (found_at < 0 && tracker.camera_health()[1].drifted) found_at = f;
    if (f >= 360) {
      EXPECT_EQ(poses.size(), 2u) << "frame " << f;
      for (const TrackedBodyPose& pose : poses) errors_after.push_back(position_error(pose, truth));
    }
  }
  std::printf("camera 1 found drifted at frame %d (bumped at 120); residual %.2f px\n", found_at,
              tracker.camera_health()[1].average_error_px);
  EXPECT_GE(found_at, 120);
  EXPECT_LT(found_at, 360);
  for (size_t c = 0; c < 4; ++c) EXPECT_EQ(tracker.camera_health()[c].drifted, c == 1) << c;
  ASSERT_FALSE(errors_after.empty());
  EXPECT_LT(*std::max_element(errors_after.begin(), errors_after.end()), 5e-3);
}

// The board of eight markers circling as the helmet does, every camera seeing it for 1 s, then
// camera 0 alone for 2 s: its track goes on from that camera, flagged by cameras_used 1, within
// a few centimetres (depth from one view) and within what each pose's covariance says.
TEST(VolumeTracker, OneCameraAloneKeepsATrackFlaggedAsSuch) {
  const test::Volume volume;
  RigidBodyDatabase bodies;
  bodies.bodies.push_back({"board", test::kBoard});
  const std::vector<VolumeCamera> cameras = cameras_of(volume);
  VolumeTracker tracker(cameras, bodies);
  std::mt19937 random(7);
  int single = 0, beyond_three_sigma = 0;
  std::vector<double> errors;
  for (int f = 0; f < 360; ++f) {
    const Eigen::Isometry3d truth = truth_at(f / kRate_hz)[0];
    std::vector<bool> sees(cameras.size(), f < 120);
    sees[0] = true;
    const std::vector<CameraFrame> frame =
        board_frame(volume, volume.extrinsics, truth, stamp_of(f), sees, random);
    for (const TrackedBodyPose& pose : tracker.track(stamp_of(f), frame)) {
      if (f < 120) continue;
      EXPECT_EQ(pose.cameras_used, 1) << "frame " << f;
      ++single;
      const Eigen::Vector3d error = pose.world_from_body.translation() - truth.translation();
      errors.push_back(error.norm());
      const double nees = error.dot(pose.covariance.topLeftCorner<3, 3>().ldlt().solve(error));
      beyond_three_sigma += nees > 14.16 ? 1 : 0;
    }
  }
  std::sort(errors.begin(), errors.end());
  ASSERT_FALSE(errors.empty());
  std::printf(
      "board posed from one camera in %d of 240 frames, position error median %.1f mm, max %.1f "
      "mm; %d beyond their covariance's 3 sigma\n",
      single, errors[errors.size() / 2] * 1e3, errors.back() * 1e3, beyond_three_sigma);
  EXPECT_GE(single, 235);
  EXPECT_LT(errors[errors.size() / 2], 0.03);
  EXPECT_LE(beyond_three_sigma, single / 100);
}

// The board seen by cameras 0 and 2 for 1 s, then by camera 2 and camera 1, knocked by a quarter
// of a degree (its markers land about 4 px off, as the volume demo's bumped camera's do) and
// never yet in a view with two others: nothing has measured its residuals. The two disagree
// and each agrees with itself; the track that cameras 0 and 2 fused predicts where the board
// is, and camera 1's markers lie pixels off it: camera 1 is left out, and the board goes on
// from camera 2. Before, the board went unposed in 46 of the 240 frames, and camera 2 was left
// out in others (the fit of the two kept the camera with more points).
TEST(VolumeTracker, OfTwoCamerasThatDisagreeTheOneOffTheFusedTrackIsLeftOut) {
  const test::Volume volume;
  RigidBodyDatabase bodies;
  bodies.bodies.push_back({"board", test::kBoard});
  VolumeTracker tracker(cameras_of(volume), bodies);
  std::vector<Eigen::Isometry3d> actual = volume.extrinsics;
  actual[1] = Eigen::AngleAxisd(0.25 * test::kPi / 180, Eigen::Vector3d::UnitY()) * actual[1];
  std::mt19937 random(11);
  int posed = 0;
  std::vector<double> errors;
  for (int f = 0; f < 360; ++f) {
    const Eigen::Isometry3d truth = truth_at(f / kRate_hz)[0];
    const std::vector<bool> sees = f < 120 ? std::vector<bool>{true, false, true, false}
                                           : std::vector<bool>{false, true, true, false};
    const std::vector<CameraFrame> frame =
        board_frame(volume, actual, truth, stamp_of(f), sees, random);
    for (const TrackedBodyPose& pose : tracker.track(stamp_of(f), frame)) {
      if (f < 120) continue;
      ++posed;
      EXPECT_EQ(pose.cameras_used, 1) << "frame " << f;
      errors.push_back((pose.world_from_body.translation() - truth.translation()).norm());
    }
  }
  std::sort(errors.begin(), errors.end());
  const CameraHealth& bumped = tracker.camera_health()[1];
  std::printf(
      "board posed in %d of 240 frames seen by camera 2 and the bumped camera 1; camera 1 left "
      "out %lld times (residual %.2f px), camera 2 %lld; position error median %.1f mm\n",
      posed, static_cast<long long>(bumped.left_out), bumped.average_error_px,
      static_cast<long long>(tracker.camera_health()[2].left_out),
      errors.empty() ? 0.0 : errors[errors.size() / 2] * 1e3);
  EXPECT_GE(posed, 235);
  EXPECT_GE(bumped.left_out, 235);
  EXPECT_EQ(tracker.camera_health()[2].left_out, 0);
  ASSERT_FALSE(errors.empty());
  EXPECT_LT(errors[errors.size() / 2], 0.03);
}

// The drone seen by one camera alone, four or five of its markers (one hidden at random): that
// fixes its six unknowns with nothing to check them, so it is not posed rather than posed
// centimetres off; seen by several cameras again, it is found again.
TEST(VolumeTracker, ABodyOneCameraSeesByFewerThanSixMarkersIsNotPosed) {
  Sequence sequence;
  VolumeTracker tracker(sequence.cameras(), sequence.bodies);
  int drone_alone = 0, drone_again = 0;
  for (int f = 0; f < 480; ++f) {
    const std::vector<Eigen::Isometry3d> truth = truth_at(f / kRate_hz);
    std::vector<CameraFrame> frame = sequence.frame(stamp_of(f), truth, sequence.volume.extrinsics);
    if (f >= 120 && f < 360) {
      // Cameras 1..3 see the helmet only.
      const std::vector<CameraFrame> helmet_only =
          sequence.frame(stamp_of(f), {truth[0]}, sequence.volume.extrinsics);
      for (size_t c = 1; c < 4; ++c) frame[c] = helmet_only[c];
    }
    for (const TrackedBodyPose& pose : tracker.track(stamp_of(f), frame)) {
      if (pose.name != "drone") continue;
      if (f >= 130 && f < 360) ++drone_alone;
      if (f >= 370) {
        ++drone_again;
        EXPECT_LT(position_error(pose, truth), 5e-3) << "frame " << f;
      }
    }
  }
  EXPECT_EQ(drone_alone, 0);
  EXPECT_EQ(drone_again, 110);
}

// A body of close markers (3 to 9 cm apart, 8 to 25 px in the cameras) flown to and fro at
// 1.5 m/s, turning back at once every half second: at each turn its prediction runs on by 2.5 cm
// (7 px), where a marker's neighbour lies nearer than the marker. Fitted to those, the fit was
// up to a centimetre off and still under the RMS limit; far above the track's usual residuals,
// the neighbours' points are left out, or the fit is set aside and the body fitted from its
// last pose: every pose within a millimetre.
TEST(VolumeTracker, ABodyThatTurnsBackIsNotFittedToItsMarkersNeighbours) {
  const test::Volume volume;
  const RigidBodyDatabase bodies = parse_rigid_bodies(R"(bodies:
  - name: wand
    markers: [[0, 0, 0], [0.035, 0, 0], [0.075, 0.012, 0], [0.13, 0.004, 0.015],
              [0.018, 0.052, 0.006], [0.095, 0.066, 0.024], [0.047, 0.105, 0.003]]
)",
                                                      "bodies.yaml", 0.001, 4);
  const std::vector<VolumeCamera> cameras = cameras_of(volume);
  VolumeTracker tracker(cameras, bodies);
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0, 0.03);
  double worst = 0;
  int posed = 0;
  const int frames = 360;
  for (int f = 0; f < frames; ++f) {
    // A triangle wave along x and y: 60 frames out, 60 back.
    const double phase = std::abs(std::fmod(f / kRate_hz, 1.0) - 0.5);  // 0.5 .. 0 .. 0.5
    Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
    truth.translation() =
        Eigen::Vector3d(1.5 * phase * std::sqrt(0.5), 1.5 * phase * std::sqrt(0.5), 1.2);
    std::vector<CameraFrame> frame(cameras.size());
    for (size_t c = 0; c < cameras.size(); ++c) {
      frame[c] = {true, stamp_of(f), {}, {}};
      for (const Eigen::Vector3d& marker : bodies.bodies[0].markers) {
        const auto pixel = volume.camera->project(volume.extrinsics[c] * truth * marker);
        if (pixel) frame[c].pixels.push_back(*pixel + test::draws<2>(noise, random));
      }
    }
    for (const TrackedBodyPose& pose : tracker.track(stamp_of(f), frame)) {
      ++posed;
      worst = std::max(worst, (pose.world_from_body.translation() - truth.translation()).norm());
    }
  }
  std::printf("%d of %d frames posed, worst %.2f mm; %lld fits set aside\n", posed, frames,
              worst * 1e3, static_cast<long long>(tracker.unusual_fits()));
  EXPECT_EQ(posed, frames);
  EXPECT_LT(worst, 1e-3);
}

TEST(VolumeTracker, BadInputThrows) {
  const test::Volume volume;
  EXPECT_THROW(VolumeTracker({}, RigidBodyDatabase{}), std::invalid_argument);
  VolumeTracker tracker({{"cam_0", volume.camera, volume.extrinsics[0], "cam_0_optical"}},
                        RigidBodyDatabase{});
  EXPECT_THROW(tracker.track(0, {}), std::invalid_argument);
  CameraFrame frame{true, 0, {{600, 300}, {620, 300}}, {0.05}};  // a sigma for one pixel of two
  EXPECT_THROW(tracker.track(0, {frame}), std::invalid_argument);
  frame.pixel_sigma_px.push_back(0.05);
  EXPECT_NO_THROW(tracker.track(0, {frame}));
}

}  // namespace
}  // namespace mocap::volume

namespace mocap::volume {
namespace {

// Options built in code (a benchmark's, a test's) get the checks the plugin's parameter ranges
// give a launch file: the tracker refuses them, naming the field by its path.
TEST(VolumeTrackerOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(VolumeTrackerOptions{}.problem(), std::nullopt);
  VolumeTrackerOptions options;
  options.fusion.min_points = 2;
  EXPECT_EQ(options.problem(), "fusion.min_points: 2; three points at least fix a pose");
  options = {};
  options.fusion.max_orientation_sigma_ratio = 0.5;
  EXPECT_EQ(options.problem(), "fusion.max_orientation_sigma_ratio: 0.5 is below 1");
  options = {};
  options.triangulation.tolerance_px = 0;
  EXPECT_EQ(options.problem(), "triangulation.tolerance_px: 0 is not above 0");
  options = {};
  options.identification.min_markers = 2;
  EXPECT_EQ(options.problem(), "identification.min_markers: 2; three markers at least fix a body");
  options = {};
  options.drift_px = -1;
  EXPECT_EQ(options.problem(), "drift_px: -1 is not above 0");

  const Sequence sequence;
  try {
    VolumeTracker tracker(sequence.cameras(), sequence.bodies, options);
    ADD_FAILURE() << "negative drift_px accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "VolumeTrackerOptions::drift_px: -1 is not above 0");
  }
  EXPECT_THROW(triangulate_markers({}, {.tolerance_px = 1.5, .min_cameras = 1}),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::volume
