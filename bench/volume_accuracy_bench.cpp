// Fused against single-camera accuracy on the volume demo's own images: the demo's scene
// rendered through its four cameras, fiducials detected, bodies identified and fused as the
// volume_fusion component does (test/volume/rendered_volume.hpp), beside each camera's own
// pose of each body (its markers given by the renderer's truth, refined and weighed as the
// fusion's), on the same body-frames, against the truth; each figure against the camera best
// at it.
//
//   build/bin/volume_accuracy_bench [--seconds S] [--cameras 4|8]
//   (default 20 s of the scene at 30 Hz through the demo's 4 cameras)
//
// Target (issue: a tracking volume): fused position and orientation errors at least 2x lower
// than the best single camera's on the same frames, median and p95.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "test/volume/rendered_volume.hpp"

namespace {

using mocap::volume::test::BodyFrame;
using mocap::volume::test::quantile;

struct Errors {
  std::vector<double> position_mm, rotation_deg;
  void add(const mocap::volume::test::PoseError& e) {
    position_mm.push_back(e.position_m * 1e3);
    rotation_deg.push_back(e.rotation_deg);
  }
};

}  // namespace

int main(int argc, char** argv) {
  double seconds = 20;
  int cameras = 4;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else if (argument == "--cameras" && i + 1 < argc) {
      cameras = std::atoi(argv[++i]);
    } else {
      fmt::print(stderr, "usage: volume_accuracy_bench [--seconds S] [--cameras 4|8]\n");
      return 2;
    }
  }
  const int frames = static_cast<int>(seconds * 30);
  mocap::volume::test::RenderedVolumeOptions options;
  options.frames = frames;
  if (cameras != 4 && cameras != 8) {
    fmt::print(stderr, "volume_accuracy_bench: --cameras: 4 or 8, not {}\n", cameras);
    return 2;
  }
  options.cameras = cameras;
  const auto volume = mocap::volume::test::render_volume(MOCAP_CONFIG_DIR, options);
  size_t fused_count = 0;
  for (const BodyFrame& body : volume.body_frames) fused_count += body.fused.posed() ? 1 : 0;
  fmt::print(
      "{} frames of the volume demo's scene, {} cameras, {} body-frames, {} fused ({:.2f} %)\n\n",
      frames, cameras, volume.body_frames.size(), fused_count,
      100.0 * static_cast<double>(fused_count) / static_cast<double>(volume.body_frames.size()));
  fmt::print(
      "| camera | body-frames | its position mm (median, p95) | fused on them | its orientation "
      "deg (median, p95) | fused on them |\n");
  fmt::print("|---|---:|---|---|---|---|\n");
  for (size_t c = 0; c < volume.cameras.size(); ++c) {
    Errors o, f;
    for (const BodyFrame& body : volume.body_frames) {
      if (!body.fused.posed() || !body.by_camera[c].posed()) continue;
      o.add(body.by_camera[c]);
      f.add(body.fused);
    }
    fmt::print("| {} | {} | {:.3f}, {:.3f} | {:.3f}, {:.3f} | {:.4f}, {:.4f} | {:.4f}, {:.4f} |\n",
               volume.cameras[c], o.position_mm.size(), quantile(o.position_mm, 0.5),
               quantile(o.position_mm, 0.95), quantile(f.position_mm, 0.5),
               quantile(f.position_mm, 0.95), quantile(o.rotation_deg, 0.5),
               quantile(o.rotation_deg, 0.95), quantile(f.rotation_deg, 0.5),
               quantile(f.rotation_deg, 0.95));
  }
  fmt::print(
      "\nEach figure against the camera best at it, on the body-frames both posed (target: "
      "fused >= 2x better; in orientation sqrt({}) = {:.2f}x is what {} equal views allow):\n\n",
      cameras, std::sqrt(cameras), cameras);
  fmt::print(
      "| figure | best camera | it | fused | fused better by | |\n|---|---|---:|---:|---:|---|\n");
  using mocap::volume::test::Figure;
  for (const auto& [which, name] : {std::pair{Figure::Position, "position mm"},
                                    std::pair{Figure::Orientation, "orientation deg"}}) {
    for (double q : {0.5, 0.95}) {
      const auto best = mocap::volume::test::against_best_camera(volume, which, q);
      fmt::print("| {}, {} | {} | {:.4f} | {:.4f} | {:.2f}x | {} |\n", name,
                 q == 0.5 ? "median" : "p95", best.camera, best.camera_value, best.fused_value,
                 best.ratio(), best.ratio() >= 2 ? "met" : "NOT met");
    }
  }
  return 0;
}
