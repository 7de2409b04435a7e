// The seed's PixArt camera box, simulated (docs/pixart_can.md): the LEDs of a scene seen by
// each camera of a rig, as the CAN frames the box sends for one sample of all its cameras.
//
// A sample of a camera holds the LEDs that are on, projected through the camera's model from
// their world position (the object's floor pose, the LED's offset, the object's LED height),
// rounded to whole pixels as the sensor reports them and kept when they fall on the sensor. The
// sensor reports at most four: the first four in scene order (objects in scene order, each
// object's LEDs in layout order) take slots 0..3, the rest are counted as excess. Each camera
// sample goes out as two frames: slots 0–1 on base + 2·camera_id, slots 2–3 on the next ID,
// empty slots as the "no point" value.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "common/can_io/can_frame.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"
#include "sim/pixart_box_sim/floor_trajectory.hpp"
#include "sim/pixart_box_sim/pixart_scene.hpp"

namespace mocap::pixart {

struct PixartBoxSimulatorOptions {
  // CAN ID of camera 0's first frame; the public ROS 1 `pixart` package uses 0x100.
  uint32_t base_id = 0x100;
  // Standard deviation of Gaussian noise added to each coordinate before rounding, pixels;
  // 0 = none (the LEDs' exact projections, rounded).
  double noise_px = 0;
  // Seeds the noise: the same seed and the same calls give the same frames.
  uint64_t seed = 1;

  // Why these options cannot be used, naming the field ("noise_px: -1 is below 0"); nullopt
  // when they can. PixartBoxSimulator's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// An LED a camera reports, and which LED it is (for tests and diagnostics: the sensor itself
// sends only the position).
struct SimulatedPoint {
  uint16_t x = 0;     // 0..1022: 1023 is the sensor's "no point", so no LED is reported there
  uint16_t y = 0;     // 0..767
  size_t object = 0;  // index in the scene's objects
  size_t led = 0;     // index in the object's LEDs
};

// One camera's sample.
struct CameraView {
  uint16_t camera_id = 0;
  std::vector<SimulatedPoint> points;  // in slot order, at most 4
  int excess = 0;                      // further LEDs on the sensor that it could not report
};

// A robot's true pose at a sample's time.
struct RobotTruth {
  std::string name;
  FloorPose pose;
};

struct PixartBoxSimulatorStats {
  uint64_t samples = 0;        // views_at / frames_at calls
  uint64_t points = 0;         // LEDs reported, over all cameras
  uint64_t excess_points = 0;  // LEDs on a sensor beyond its four slots
};

class PixartBoxSimulator {
 public:
  // Throws std::invalid_argument for options that cannot be used, and when a camera's frames
  // would leave the 11-bit CAN ID range (base_id + 2·camera_id + 1 > 0x7FF).
  PixartBoxSimulator(Rig rig, PixartScene scene, PixartBoxSimulatorOptions options = {});

  // Every camera's sample at scene time `time_s`, in the rig's camera order. Draws noise (when
  // enabled) and counts in stats(), hence not const.
  std::vector<CameraView> views_at(double time_s);
  // The frames of views_at(time_s): two per camera, in the rig's camera order, half 0 first,
  // stamped `stamp_ns`.
  std::vector<can::CanFrame> frames_at(double time_s, int64_t stamp_ns = 0);
  // The two frames carrying `views`.
  std::vector<can::CanFrame> encode(const std::vector<CameraView>& views,
                                    int64_t stamp_ns = 0) const;

  // Every robot's pose at `time_s`, in scene order (calibration boards are not robots). Reads
  // only what the constructor set, so it may run on another thread than views_at.
  std::vector<RobotTruth> ground_truth(double time_s) const;

  // Where the LED `led` of object `object` is in the world at `time_s` (whether on or not).
  Eigen::Vector3d led_position(size_t object, size_t led, double time_s) const;

  const Rig& rig() const { return rig_; }
  const PixartScene& scene() const { return scene_; }
  const PixartBoxSimulatorOptions& options() const { return options_; }
  const PixartBoxSimulatorStats& stats() const { return stats_; }

 private:
  Rig rig_;
  PixartScene scene_;
  PixartBoxSimulatorOptions options_;
  std::vector<Eigen::Isometry3d> camera_from_world_;  // per camera of the rig
  std::mt19937_64 random_;
  PixartBoxSimulatorStats stats_;
};

}  // namespace mocap::pixart
