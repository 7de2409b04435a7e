// The fusion's cost: 4 cameras x 8 bodies a frame, one thread, each body's pose fused over
// every view from a start a track would give (the last pose, 5 mm and 1 degree off), beside
// the single-camera pose (IPPE and refinement) of the same views in the same run; then the
// whole frame as the volume_fusion component runs it (volume_fusion.hpp), from each camera's
// unlabelled detections: 8 bodies of 6 markers moving through the volume at 120 Hz, tracked,
// and identified afresh from triangulated markers in every frame (no tracks).
//
//   build/bin/volume_fusion_bench [--quick]
//
// Target (issue: a tracking volume): at least 1,000 frames/s of 4 cameras x 8 bodies.
#include <chrono>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "test/volume/synthetic_volume.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"
#include "volume/pose_fusion/pose_fusion.hpp"
#include "volume/rigid_bodies/rigid_body_database.hpp"
#include "volume/volume_fusion/volume_fusion.hpp"

namespace {

using namespace mocap::volume;
using Clock = std::chrono::steady_clock;

constexpr int kBodies = 8;

struct Frame {
  std::vector<std::vector<CameraView>> bodies;  // each body's views
  std::vector<Eigen::Isometry3d> starts;
};

// Frames of kBodies boards that every camera sees whole.
std::vector<Frame> make_frames(const test::Volume& volume, int count, std::mt19937& random) {
  std::vector<Frame> frames;
  std::normal_distribution<double> offset(0, 0.005 / std::sqrt(3.0));
  while (static_cast<int>(frames.size()) < count) {
    Frame frame;
    while (static_cast<int>(frame.bodies.size()) < kBodies) {
      const Eigen::Isometry3d truth = test::random_pose(random);
      std::vector<CameraView> views = test::views_of(volume, truth, 0.3, random);
      bool all = true;
      for (const CameraView& view : views) all = all && !view.body_points.empty();
      if (!all) continue;
      Eigen::Isometry3d start = truth;
      start.translation() += test::draws<3>(offset, random);
      start.linear() =
          Eigen::AngleAxisd(test::kPi / 180, Eigen::Vector3d::UnitX()) * start.linear();
      frame.bodies.push_back(std::move(views));
      frame.starts.push_back(start);
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

template <class Work>
double frames_per_second(const std::vector<Frame>& frames, Work work) {
  const auto begin = Clock::now();
  int valid = 0;
  for (const Frame& frame : frames) valid += work(frame);
  const double seconds = std::chrono::duration<double>(Clock::now() - begin).count();
  if (valid != static_cast<int>(frames.size()) * kBodies) {
    std::fprintf(stderr, "volume_fusion_bench: %d of %zu poses valid\n", valid,
                 frames.size() * kBodies);
  }
  return static_cast<double>(frames.size()) / seconds;
}

// kBodies bodies of 6 markers within 15 cm, no two of which (nor one with itself) 4 markers
// could confuse: drawn until the database accepts them.
RigidBodyDatabase make_bodies(std::mt19937& random) {
  std::uniform_real_distribution<double> coordinate(-0.15, 0.15);
  std::string text = "bodies:\n";
  RigidBodyDatabase database;
  while (static_cast<int>(database.bodies.size()) < kBodies) {
    std::string body = fmt::format("  - name: body_{}\n    markers: [", database.bodies.size());
    for (int m = 0; m < 6; ++m) {
      const Eigen::Vector3d p = test::draws<3>(coordinate, random);
      body += fmt::format("{}[{:.3f}, {:.3f}, {:.3f}]", m ? ", " : "", p.x(), p.y(), p.z());
    }
    body += "]\n";
    try {
      database = parse_rigid_bodies(text + body, "bench", 0.004, 4);
      text += body;
    } catch (const RigidBodyError&) {
    }
  }
  return database;
}

// Every camera's detections of the bodies, each on a circle of its own through the volume,
// with 0.3 px of noise, shuffled: what the cameras' fiducial trackers send.
std::vector<std::vector<CameraFrame>> make_detections(const test::Volume& volume,
                                                      const RigidBodyDatabase& bodies, int count,
                                                      std::mt19937& random) {
  std::normal_distribution<double> noise(0, 0.3);
  std::vector<std::vector<CameraFrame>> frames;
  for (int f = 0; f < count; ++f) {
    const int64_t stamp_ns = static_cast<int64_t>(f * 1e9 / 120);
    std::vector<CameraFrame> frame(volume.extrinsics.size());
    for (size_t c = 0; c < frame.size(); ++c) {
      frame[c] = {true, stamp_ns, {}, {}};
      for (size_t b = 0; b < bodies.bodies.size(); ++b) {
        const double angle = 2 * test::kPi * (f / 120.0 / 6 + static_cast<double>(b) / kBodies);
        Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
        pose.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        pose.translation() = Eigen::Vector3d(0.9 * std::cos(angle), 0.9 * std::sin(angle),
                                             0.8 + 0.1 * static_cast<double>(b % 4));
        for (const Eigen::Vector3d& marker : bodies.bodies[b].markers) {
          const Eigen::Vector3d in_camera = volume.extrinsics[c] * pose * marker;
          const auto pixel = volume.camera->project(in_camera);
          if (in_camera.z() <= 0 || !pixel || !volume.camera->in_image(*pixel)) continue;
          frame[c].pixels.push_back(*pixel + test::draws<2>(noise, random));
        }
      }
      std::shuffle(frame[c].pixels.begin(), frame[c].pixels.end(), random);
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const test::Volume volume;
  std::mt19937 random(1);
  const std::vector<Frame> frames = make_frames(volume, quick ? 200 : 2000, random);
  const double fused = frames_per_second(frames, [](const Frame& frame) {
    int valid = 0;
    for (int b = 0; b < kBodies; ++b) {
      valid += estimate_multi_camera_pose(frame.bodies[b], frame.starts[b]).valid;
    }
    return valid;
  });
  const double single = frames_per_second(frames, [](const Frame& frame) {
    int valid = 0;
    for (int b = 0; b < kBodies; ++b) {
      bool all = true;
      for (const CameraView& view : frame.bodies[b]) {
        all =
            mocap::pose::estimate_planar_pose(*view.camera, view.body_points, view.pixels).valid &&
            all;
      }
      valid += all;
    }
    return valid;
  });
  const RigidBodyDatabase bodies = make_bodies(random);
  const auto detections = make_detections(volume, bodies, quick ? 120 : 1200, random);
  std::vector<VolumeCamera> cameras;
  for (size_t c = 0; c < volume.extrinsics.size(); ++c) {
    cameras.push_back({fmt::format("cam_{}", c), volume.camera, volume.extrinsics[c], ""});
  }
  size_t posed = 0;
  auto begin = Clock::now();
  VolumeTracker tracker(cameras, bodies);
  for (const auto& frame : detections) {
    posed +=
        tracker.track(static_cast<int64_t>(&frame - detections.data()) * 8'333'333, frame).size();
  }
  const double tracked = static_cast<double>(detections.size()) /
                         std::chrono::duration<double>(Clock::now() - begin).count();
  const double tracked_share =
      static_cast<double>(posed) / static_cast<double>(detections.size() * kBodies);
  const size_t cold_frames = std::min<size_t>(detections.size(), quick ? 20 : 100);
  size_t identified = 0;
  begin = Clock::now();
  for (size_t f = 0; f < cold_frames; ++f) {
    VolumeTracker fresh(cameras, bodies);
    identified += fresh.track(0, detections[f]).size();
  }
  const double cold = static_cast<double>(cold_frames) /
                      std::chrono::duration<double>(Clock::now() - begin).count();
  const double identified_share =
      static_cast<double>(identified) / static_cast<double>(cold_frames * kBodies);

  fmt::print(
      "volume_fusion_bench: {} frames of 4 cameras x {} bodies (8 markers each, 0.3 px noise), "
      "one thread; the tracker on {} frames of {} bodies of 6 markers at 120 Hz.\n\n",
      frames.size(), kBodies, detections.size(), kBodies);
  fmt::print("| {:<56} | {:>10} | {:>14} |\n", "work per frame", "frames/s", "us per body");
  fmt::print("|{:-<58}|{:-<12}|{:-<16}|\n", "", "", "");
  fmt::print("| {:<56} | {:>10.0f} | {:>14.1f} |\n", "fusion over 4 views, from a track's start",
             fused, 1e6 / fused / kBodies);
  fmt::print("| {:<56} | {:>10.0f} | {:>14.1f} |\n",
             "reference: 4 single-camera poses (IPPE + refinement)", single,
             1e6 / single / kBodies);
  fmt::print(
      "| {:<56} | {:>10.0f} | {:>14.1f} |\n",
      fmt::format("tracker: detections to poses, tracked ({:.1f} % posed)", 100 * tracked_share),
      tracked, 1e6 / tracked / kBodies);
  fmt::print(
      "| {:<56} | {:>10.0f} | {:>14.1f} |\n",
      fmt::format("tracker: identified afresh each frame ({:.1f} %)", 100 * identified_share), cold,
      1e6 / cold / kBodies);
  fmt::print("\ntarget: fusion >= 1000 frames/s\n");
  return 0;
}
