// The fusion's cost: 4 cameras x 8 bodies a frame, one thread, each body's pose fused over
// every view from a start a track would give (the last pose, 5 mm and 1 degree off), beside
// the single-camera pose (IPPE and refinement) of the same views in the same run.
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

#include "multi_camera_pose.hpp"
#include "planar_pose.hpp"
#include "synthetic_volume.hpp"

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
  fmt::print(
      "volume_fusion_bench: {} frames of 4 cameras x {} bodies (8 markers each, 0.3 px noise), "
      "one thread.\n\n",
      frames.size(), kBodies);
  fmt::print("| {:<52} | {:>10} | {:>14} |\n", "work per frame", "frames/s", "us per body");
  fmt::print("|{:-<54}|{:-<12}|{:-<16}|\n", "", "", "");
  fmt::print("| {:<52} | {:>10.0f} | {:>14.1f} |\n", "fusion over 4 views, from a track's start",
             fused, 1e6 / fused / kBodies);
  fmt::print("| {:<52} | {:>10.0f} | {:>14.1f} |\n",
             "reference: 4 single-camera poses (IPPE + refinement)", single,
             1e6 / single / kBodies);
  fmt::print("\ntarget: fusion >= 1000 frames/s\n");
  return 0;
}
