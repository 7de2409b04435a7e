// The volume's cameras calibrated from rendered images (test/volume/rendered_calibration.hpp),
// for waves of several lengths and several ways of setting the floor: the board laid once at the
// origin (its axes the room's), at five or nine marks, once or twice at each (turned).
// Each calibration's cameras against the truth, and the demo's poses fused through them against
// the same poses fused through the true cameras, on the same rendered frames.
//
//   build/bin/volume_calibration_bench [--seconds S]   (S of the demo fused, default 20 s at 30 Hz)
//
// Targets (issue: a tracking volume): extrinsics within 2 mm and 0.05 degrees of the truth;
// fused accuracy within 20 % of what the true extrinsics give.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "test/volume/rendered_calibration.hpp"
#include "test/volume/rendered_volume.hpp"

namespace {

using namespace mocap::volume;
using test::quantile;

// One calibration's row: its cameras against the truth, and the demo's poses fused through
// them against `on_truth`.
void print_row(const std::string& wave, const std::string& floor,
               const test::RenderedCalibrationScenes& scenes,
               const std::vector<BoardSighting>& waved,
               const std::vector<FloorPlacement>& placements, test::RenderedVolumeOptions rendering,
               const std::vector<double>& on_truth) {
  const VolumeCalibration calibrated =
      calibrate_volume(scenes.cameras(), scenes.board(), waved, placements);
  double worst_m = 0, worst_deg = 0;
  for (size_t c = 0; c < scenes.cameras().size(); ++c) {
    const test::CameraOffset off =
        test::camera_offset(calibrated.camera_from_world[c], scenes.true_camera_from_world()[c]);
    worst_m = std::max(worst_m, off.position_m);
    worst_deg = std::max(worst_deg, off.rotation_deg);
  }
  rendering.tracked_camera_from_world = calibrated.camera_from_world;
  const std::vector<double> fused =
      test::render_volume(MOCAP_CONFIG_DIR, rendering).fused_position_errors_mm();
  const double median = quantile(fused, 0.5) / quantile(on_truth, 0.5) - 1;
  const double p95 = quantile(fused, 0.95) / quantile(on_truth, 0.95) - 1;
  const bool met = worst_m < 2e-3 && worst_deg < 0.05 && median <= 0.2 && p95 <= 0.2;
  fmt::print(
      "| {} | {} | {} | {:.3f} | {:.3f}, {:.4f} | {:.4f}, {:.4f} | {:+.0f} %, {:+.0f} % | {} |\n",
      wave, floor, calibrated.frames_used, calibrated.report.rms_px, worst_m * 1e3, worst_deg,
      quantile(fused, 0.5), quantile(fused, 0.95), 100 * median, 100 * p95,
      met ? "met" : "NOT met");
}

void print_header() {
  fmt::print(
      "| wave | floor | capture times | RMS px | worst camera mm, deg | fused mm (median, p95) | "
      "against the true cameras' | targets |\n");
  fmt::print("|---:|---|---:|---:|---|---|---|---|\n");
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 20;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else {
      fmt::print(stderr, "usage: volume_calibration_bench [--seconds S]\n");
      return 2;
    }
  }
  const test::RenderedCalibrationScenes scenes(MOCAP_CONFIG_DIR);
  test::RenderedVolumeOptions rendering;
  rendering.frames = static_cast<int>(seconds * 30);
  const std::vector<double> on_truth =
      test::render_volume(MOCAP_CONFIG_DIR, rendering).fused_position_errors_mm();
  fmt::print(
      "The demo's poses fused over {} frames through the true cameras: position {:.4f} mm "
      "median, {:.4f} mm p95\n\n",
      rendering.frames, quantile(on_truth, 0.5), quantile(on_truth, 0.95));

  fmt::print(
      "The wave's length, the floor as scripts/calibrate_volume.sh lays it (9 marks, each "
      "twice, turned half round):\n\n");
  print_header();
  const std::vector<FloorPlacement> shipped_floor = scenes.on_floor(test::kFloorMarks, {0, 180});
  const std::vector<BoardSighting> waved = scenes.waved(120);
  for (double wave_s : {20.0, 30.0, 60.0, 120.0}) {
    std::vector<BoardSighting> part;
    for (const BoardSighting& sighting : waved) {
      if (sighting.stamp_ns < static_cast<int64_t>(wave_s * 1e9)) part.push_back(sighting);
    }
    print_row(fmt::format("{:.0f} s", wave_s), "9 marks, turned 180 deg", scenes, part,
              shipped_floor, rendering, on_truth);
  }

  fmt::print(
      "\nThe floor, after a 60 s wave. The cameras stand in a square, so a board turned by 180 "
      "degrees shows each camera what it showed the opposite one: its detection biases cancel. "
      "Turned by 45 degrees, no such symmetry helps.\n\n");
  print_header();
  std::vector<BoardSighting> minute;
  for (const BoardSighting& sighting : waved) {
    if (sighting.stamp_ns < static_cast<int64_t>(60e9)) minute.push_back(sighting);
  }
  const std::vector<Eigen::Vector2d> five(test::kFloorMarks.begin(), test::kFloorMarks.begin() + 5);
  struct Floor {
    const char* name;
    std::vector<FloorPlacement> placements;
  };
  const Floor floors[] = {
      {"laid once at the origin (its axes the room's)", scenes.on_floor({{0, 0}}, {0})},
      {"5 marks (centre, 1 m along each axis)", scenes.on_floor(five, {0})},
      {"5 marks, turned 180 deg", scenes.on_floor(five, {0, 180})},
      {"9 marks (and the corners)", scenes.on_floor(test::kFloorMarks, {0})},
      {"9 marks, turned 45 deg", scenes.on_floor(test::kFloorMarks, {0, 45})},
      {"9 marks, turned 180 deg", shipped_floor}};
  for (const Floor& floor : floors) {
    print_row("60 s", floor.name, scenes, minute, floor.placements, rendering, on_truth);
  }
  return 0;
}
