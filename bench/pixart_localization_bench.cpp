// Localization error of the PixArt path against the simulator's ground truth, over the
// shipped two-robot scene: with the cameras where the rig file says ("calibrated") and with
// the real cameras a little off the rig file's nominal poses ("nominal": up to 2 cm and 1
// degree, as hand-mounted cameras are), each in the single-camera and overlap zones; and the
// localizer's cost per camera sample.
//   build/bin/pixart_localization_bench [--quick]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include <fmt/format.h>

#include "pixart/pixart_localizer/pixart_localizer.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"
#include "sim/pixart_box_sim/pixart_box_simulator.hpp"
#include "sim/pixart_box_sim/pixart_scene.hpp"

namespace {

using namespace mocap::pixart;
using localization::RobotLocalizer;
using localization::TrackedRobot;

struct Errors {
  size_t publishes = 0, tracked = 0;
  std::vector<double> position_mm, heading_deg;
};

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  size_t i = std::min(v.size() - 1, static_cast<size_t>(q * v.size()));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(i), v.end());
  return v[i];
}

// The rig as mounted: each camera displaced and turned a little from its nominal pose.
Rig mounted(Rig rig, double shift_m, double turn_deg, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (RigCamera& camera : rig.cameras) {
    Eigen::Vector3d axis{unit(random), unit(random), unit(random)};
    Eigen::AngleAxisd turn(turn_deg * M_PI / 180 * std::abs(unit(random)), axis.normalized());
    camera.world_from_camera.linear() = turn.toRotationMatrix() * camera.world_from_camera.linear();
    camera.world_from_camera.translation() +=
        shift_m * Eigen::Vector3d{unit(random), unit(random), unit(random)} / std::sqrt(3.0);
  }
  return rig;
}

// How many cameras see a floor point at the LED plane.
int views_of(const Rig& rig, double x, double y) {
  int count = 0;
  for (const RigCamera& camera : rig.cameras) {
    Eigen::Vector3d p =
        camera.world_from_camera.inverse() * Eigen::Vector3d(x, y, rig.led_plane_height_m);
    auto pixel = camera.model->project(p);
    count += pixel && camera.model->in_image(*pixel);
  }
  return count;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const double duration_s = quick ? 20 : 80;  // two_robots.yaml: robot_a laps every 20 s
  const std::string config = MOCAP_CONFIG_DIR "/pixart";
  Rig nominal = load_rig(config + "/rig.yaml");
  PixartScene scene = load_pixart_scene(config + "/scenes/two_robots.yaml", nominal);

  struct Case {
    const char* name;
    Rig truth;  // where the simulator's cameras really are
    double noise_px;
  };
  std::vector<Case> cases = {{"calibrated", nominal, 0},
                             {"calibrated, 0.5 px noise", nominal, 0.5},
                             {"nominal (2 cm, 1 deg off)", mounted(nominal, 0.02, 1.0, 7), 0}};

  fmt::print(
      "PixArt localization against ground truth: {} s of scenes/two_robots.yaml, 270 Hz "
      "per camera, poses compared at 50 Hz\n\n",
      duration_s);
  fmt::print(
      "| cameras | zone | poses | tracked | position mm median | p95 | max | "
      "heading deg median | p95 | max |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  double sample_seconds = 0;
  size_t samples = 0;
  for (const Case& c : cases) {
    PixartBoxSimulator simulator(c.truth, scene, {0x100, c.noise_px, 1});
    RobotLocalizer localizer(nominal);
    std::map<std::string, Errors> zones;
    const double period = 1.0 / 270, publish_period = 1.0 / 50;
    double next_publish = 1.0;  // after a second of start-up
    for (double t = 0; t < duration_s; t += period) {
      auto stamp = static_cast<int64_t>(t * 1e9);
      for (const CameraView& view : simulator.views_at(t)) {
        std::vector<Eigen::Vector2d> pixels;
        for (const SimulatedPoint& p : view.points) pixels.emplace_back(p.x, p.y);
        auto start = std::chrono::steady_clock::now();
        localizer.add_sample(nominal.find_camera(view.camera_id)->name, stamp, pixels);
        sample_seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ++samples;
      }
      if (t < next_publish) continue;
      next_publish += publish_period;
      auto tracked = localizer.tracked_robots(stamp);
      for (const RobotTruth& truth : simulator.ground_truth(t)) {
        int views = views_of(nominal, truth.pose.x, truth.pose.y);
        if (views == 0) continue;  // out of every camera: nothing to localize
        Errors& e = zones[views == 1 ? "one camera" : "overlap (2-4 cameras)"];
        ++e.publishes;
        for (const TrackedRobot& robot : tracked) {
          if (robot.name != truth.name || !robot.tracked) continue;
          ++e.tracked;
          e.position_mm.push_back(
              std::hypot(robot.pose.x - truth.pose.x, robot.pose.y - truth.pose.y) * 1e3);
          double heading = std::remainder(robot.pose.theta - truth.pose.theta, 2 * M_PI);
          e.heading_deg.push_back(std::abs(heading) * 180 / M_PI);
        }
      }
    }
    for (const auto& [zone, e] : zones) {
      fmt::print(
          "| {} | {} | {} | {:.1f} % | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} |\n",
          c.name, zone, e.publishes, 100.0 * e.tracked / std::max<size_t>(1, e.publishes),
          quantile(e.position_mm, 0.5), quantile(e.position_mm, 0.95), quantile(e.position_mm, 1.0),
          quantile(e.heading_deg, 0.5), quantile(e.heading_deg, 0.95),
          quantile(e.heading_deg, 1.0));
    }
  }
  fmt::print(
      "\nlocalizer: {:.2f} µs per camera sample ({} samples, one thread); a full box is "
      "4 x 270 samples/s\n",
      sample_seconds / samples * 1e6, samples);
  return 0;
}
