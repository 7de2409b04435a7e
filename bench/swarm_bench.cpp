// The swarm tracker (the marker cloud, then the swarm's robots) on eight cameras sending
// centroids at 240 Hz with 0.05 px of noise:
//  1. its cost on one thread, frames already projected: correspondence + triangulation +
//     tracking with tracks, and the same frames from scratch (no tracks: every marker matched
//     by its rays, every robot searched for), for 25 to 200 robots: how it grows;
//  2. its figures on every swarm scene (take-off, formation, crossing pairs, an exchange of
//     places, random flight) for 100 single-marker robots, 50 identical quadrotors and both
//     (50 + 50): identity swaps, robot-frames tracked, position and orientation error.
//
//   build/bin/swarm_bench [--quick]      (--quick: 5 s scenes instead of 60)
//
// Targets (issue: swarms in the volume): 0 identity swaps, >= 99.9 % tracked, position median
// <= 0.1 mm, orientation median <= 0.2 degrees; >= 2,000 frames/s for 100 markers with tracks.
// Anchors: Crazyswarm flew 49 quadrotors under a 24-camera Vicon (about 26 ms end to end);
// crazyswarm2's motion_capture_tracking tracks up to 50 robots.
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "test/volume/swarm_rig.hpp"

namespace {

using namespace mocap::volume;
using mocap::synthetic::SwarmScene;
using Clock = std::chrono::steady_clock;

constexpr double kRate_hz = 240;

mocap::synthetic::CentroidCameraOptions centroid_options() {
  mocap::synthetic::CentroidCameraOptions options;
  options.noise_px = 0.05;
  return options;
}

test::SwarmRig rig(uint64_t seed) {
  return test::SwarmRig(MOCAP_CONFIG_DIR, 8, centroid_options(), seed);
}

int64_t stamp_of(int frame) { return static_cast<int64_t>(std::llround(frame / kRate_hz * 1e9)); }

// Frames per second of `work` over the frames, once through them.
double frames_per_second(size_t frames, const std::function<void(size_t)>& work) {
  const auto start = Clock::now();
  for (size_t f = 0; f < frames; ++f) work(f);
  return static_cast<double>(frames) / std::chrono::duration<double>(Clock::now() - start).count();
}

void cost_table(bool quick) {
  fmt::print(
      "\nCost on one thread, 8 cameras at 240 Hz, frames projected beforehand (random "
      "flight):\n\n");
  fmt::print("| {:<34} | {:>7} | {:>12} | {:>12} | {:>12} | {:>11} |\n", "robots", "markers",
             "tracked f/s", "us/frame", "scratch f/s", "us/frame");
  fmt::print("|{:-<36}|{:-<9}|{:-<14}|{:-<14}|{:-<14}|{:-<13}|\n", "", "", "", "", "", "");
  struct Row {
    std::string name;
    SwarmScene scene;
  };
  const auto single = mocap::synthetic::single_marker_layout();
  const auto deck = mocap::synthetic::marker_deck_layout();
  const std::vector<Row> rows = {
      {"25 single-marker", mocap::synthetic::random_flight(single, 25, 3.0, 1.0, 0.1, 10, 1)},
      {"50 single-marker", mocap::synthetic::random_flight(single, 50, 3.0, 1.0, 0.1, 10, 2)},
      {"100 single-marker", mocap::synthetic::random_flight(single, 100, 3.0, 1.0, 0.1, 10, 3)},
      {"200 single-marker", mocap::synthetic::random_flight(single, 200, 3.4, 1.0, 0.08, 10, 4)},
      {"25 quadrotors (4 markers)",
       mocap::synthetic::random_flight(deck, 25, 3.0, 1.0, 0.1, 10, 5)},
      {"50 quadrotors", mocap::synthetic::random_flight(deck, 50, 3.0, 1.0, 0.1, 10, 6)},
      {"50 quadrotors + 50 single-marker",
       mocap::synthetic::random_flight(deck, 50, 3.0, 1.3, 0.1, 10, 7)
           .with(mocap::synthetic::random_flight(single, 50, 3.0, 0.6, 0.1, 10, 8))},
  };
  const int frames = quick ? 240 : 1200;
  for (const Row& row : rows) {
    test::SwarmRig cameras = rig(1);
    std::vector<std::vector<CameraDetections>> projected;
    for (int f = 0; f < frames; ++f) projected.push_back(cameras.frame(row.scene, f / kRate_hz));
    MarkerCloudTracker cloud;
    SwarmTracker swarm(test::swarm_database_of(row.scene));
    // Acquired first: the tracked figure is the steady state.
    swarm.track(stamp_of(0), cloud.track(stamp_of(0), projected[0]));
    const double tracked = frames_per_second(frames - 1, [&](size_t f) {
      swarm.track(stamp_of(static_cast<int>(f) + 1),
                  cloud.track(stamp_of(static_cast<int>(f) + 1), projected[f + 1]));
    });
    const SwarmDatabase database = test::swarm_database_of(row.scene);
    const size_t scratch_frames = static_cast<size_t>(frames / 4);
    const double scratch = frames_per_second(scratch_frames, [&](size_t f) {
      MarkerCloudTracker fresh_cloud;
      SwarmTracker fresh_swarm(database);
      fresh_swarm.track(0, fresh_cloud.track(0, projected[f]));
    });
    fmt::print("| {:<34} | {:>7} | {:>12.0f} | {:>12.1f} | {:>12.0f} | {:>11.1f} |\n", row.name,
               row.scene.markers(0).size(), tracked, 1e6 / tracked, scratch, 1e6 / scratch);
  }
}

struct Scenes {
  std::string swarm;
  std::vector<std::pair<std::string, SwarmScene>> scenes;
};

// The scenes for one swarm: its robots as `make` lays them out for each kind.
std::vector<Scenes> swarm_scenes(double duration_s) {
  using namespace mocap::synthetic;
  const auto single = single_marker_layout();
  const auto deck = marker_deck_layout();
  // Crossing pairs and an exchange among robots that keep flying at random around them.
  auto with_crossings = [&](const std::vector<Eigen::Vector3d>& layout, int others, double height) {
    return crossing_pairs(layout, 3, 0.05, 1.0, 0.5, height + 0.5, duration_s, "pair")
        .with(random_flight(layout, others, 3.0, height, 0.1, duration_s, 31));
  };
  auto with_exchange = [&](const std::vector<Eigen::Vector3d>& layout, int others, double height) {
    return place_exchange(layout, Eigen::Vector3d(0, 0, height + 0.5), 0.8, 0.05, 1.0, 2.0,
                          duration_s, "swap")
        .with(random_flight(layout, others, 3.0, height, 0.1, duration_s, 32));
  };
  Scenes singles{"100 single-marker robots", {}};
  singles.scenes = {
      {"take-off from a grid", takeoff_grid(single, 10, 10, 0.3, 1.0, 0.5, duration_s)},
      {"formation flight", formation_circle(single, 100, 1.4, 1.0, 0.5, duration_s)},
      {"pairs crossing 5 cm apart", with_crossings(single, 94, 0.9)},
      {"two exchanging places", with_exchange(single, 98, 0.9)},
      {"random flight", random_flight(single, 100, 3.0, 1.0, 0.1, duration_s, 33)},
  };
  Scenes quads{"50 identical quadrotors", {}};
  quads.scenes = {
      {"take-off from a grid", takeoff_grid(deck, 5, 10, 0.3, 1.0, 0.5, duration_s)},
      {"formation flight", formation_circle(deck, 50, 1.4, 1.0, 0.5, duration_s)},
      {"pairs crossing 5 cm apart", with_crossings(deck, 44, 0.9)},
      {"two exchanging places", with_exchange(deck, 48, 0.9)},
      {"random flight", random_flight(deck, 50, 3.0, 1.0, 0.1, duration_s, 34)},
  };
  Scenes mixed{"50 quadrotors + 50 single-marker", {}};
  mixed.scenes = {
      {"take-off from a grid",
       takeoff_grid(deck, 5, 10, 0.3, 1.0, 0.5, duration_s, "cf")
           .with(takeoff_grid(single, 5, 10, 0.3, 0.6, 0.5, duration_s, "rover")
                     .shifted(Eigen::Vector3d(0.15, 0.15, 0)))},
      {"formation flight",
       formation_circle(deck, 50, 1.4, 1.3, 0.5, duration_s, "cf")
           .with(formation_circle(single, 50, 1.0, 0.7, -0.5, duration_s, "rover"))},
      {"pairs crossing 5 cm apart",
       crossing_pairs(deck, 3, 0.05, 1.0, 0.5, 1.6, duration_s, "cf_pair")
           .with(random_flight(deck, 44, 3.0, 1.2, 0.1, duration_s, 35, "cf"))
           .with(random_flight(single, 50, 3.0, 0.6, 0.1, duration_s, 36, "rover"))},
      {"two exchanging places",
       place_exchange(deck, Eigen::Vector3d(0, 0, 1.6), 0.8, 0.05, 1.0, 2.0, duration_s, "cf_swap")
           .with(random_flight(deck, 48, 3.0, 1.2, 0.1, duration_s, 37, "cf"))
           .with(random_flight(single, 50, 3.0, 0.6, 0.1, duration_s, 38, "rover"))},
      {"random flight",
       random_flight(deck, 50, 3.0, 1.3, 0.1, duration_s, 39, "cf")
           .with(random_flight(single, 50, 3.0, 0.6, 0.1, duration_s, 40, "rover"))},
  };
  // Beyond the hundred: twice as many markers, to see the cloud's ghosts grow.
  Scenes crowd{"200 single-marker robots",
               {{"random flight", random_flight(single, 200, 3.4, 1.0, 0.08, duration_s, 41)}}};
  return {singles, quads, mixed, crowd};
}

void accuracy_table(bool quick) {
  const double duration_s = quick ? 5 : 60;
  fmt::print(
      "\nEvery swarm scene, {:.0f} s at 240 Hz, 8 cameras in centroid mode, 0.05 px noise:\n\n",
      duration_s);
  fmt::print(
      "| {:<34} | {:<26} | {:>6} | {:>6} | {:>6} | {:>9} | {:>9} | {:>9} | {:>9} | {:>8} |\n",
      "swarm", "scene", "robots", "swaps", "wrong", "tracked", "pos mm", "pos p95", "orient deg",
      "ghosts");
  fmt::print("|{:-<36}|{:-<28}|{:-<8}|{:-<8}|{:-<8}|{:-<11}|{:-<11}|{:-<11}|{:-<11}|{:-<10}|\n", "",
             "", "", "", "", "", "", "", "", "");
  uint64_t seed = 100;
  for (const Scenes& swarm : swarm_scenes(duration_s)) {
    for (const auto& [name, scene] : swarm.scenes) {
      test::SwarmRig cameras = rig(++seed);
      const test::SwarmFigures figures = test::track_swarm(scene, cameras, kRate_hz, duration_s);
      std::vector<double> sorted = figures.position_errors_m;
      std::sort(sorted.begin(), sorted.end());
      const double p95 = sorted.empty() ? 0 : sorted[sorted.size() * 95 / 100];
      fmt::print(
          "| {:<34} | {:<26} | {:>6} | {:>6} | {:>6} | {:>8.3f}% | {:>9.4f} | {:>9.4f} | {:>9} | "
          "{:>7.3f}% |\n",
          swarm.swarm, name, scene.robots.size(), figures.identity_swaps, figures.wrong_poses,
          100 * figures.tracked_fraction(),
          1e3 * test::SwarmFigures::median(figures.position_errors_m), 1e3 * p95,
          figures.orientation_errors_deg.empty()
              ? std::string("-")
              : fmt::format("{:.4f}", test::SwarmFigures::median(figures.orientation_errors_deg)),
          figures.cloud_markers == 0 ? 0.0
                                     : 100.0 * static_cast<double>(figures.ghost_markers) /
                                           static_cast<double>(figures.cloud_markers));
      std::fflush(stdout);
    }
  }
  fmt::print(
      "\nwrong: poses more than 5 cm or 5 deg off their own robot's truth (the evaluator's false "
      "identifications). ghosts: the cloud's markers more than 5 mm from every true "
      "marker.\nTargets: 0 swaps, >= 99.9 % tracked, position median <= 0.1 mm, "
      "orientation median <= "
      "0.2 deg. Anchors: Crazyswarm 49 quadrotors (24-camera Vicon, ~26 ms end to end); "
      "motion_capture_tracking up to 50 robots.\n");
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  cost_table(quick);
  accuracy_table(quick);
  return 0;
}
