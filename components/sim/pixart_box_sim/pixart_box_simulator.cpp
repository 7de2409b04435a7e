#include "sim/pixart_box_sim/pixart_box_simulator.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "pixart/pixart_bridge/pixart_bridge.hpp"

namespace mocap::pixart {

std::optional<std::string> PixartBoxSimulatorOptions::problem() const {
  // Camera 0's two frames at least; the rig's cameras are checked with the rig. In 64 bits,
  // so that no base_id wraps.
  if (uint64_t{base_id} + 1 > can::kMaxStandardId) {
    return fmt::format(
        "base_id: {:#x} leaves no room for camera 0's second frame (IDs end at "
        "{:#x})",
        base_id, can::kMaxStandardId);
  }
  if (!(noise_px >= 0)) return fmt::format("noise_px: {} is below 0", noise_px);
  if (!std::isfinite(noise_px)) return fmt::format("noise_px: {} is not finite", noise_px);
  return std::nullopt;
}

PixartBoxSimulator::PixartBoxSimulator(Rig rig, PixartScene scene,
                                       PixartBoxSimulatorOptions options)
    : rig_(std::move(rig)), scene_(std::move(scene)), options_(options), random_(options.seed) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("PixartBoxSimulatorOptions::" + *problem);
  }
  for (const RigCamera& camera : rig_.cameras) {
    if (options_.base_id + 2u * static_cast<uint32_t>(camera.camera_id) + 1 > can::kMaxStandardId) {
      throw std::invalid_argument(fmt::format(
          "PixArt box simulator: camera '{}' (id {}) with base_id 0x{:X} needs CAN ID 0x{:X}, "
          "above 0x{:X}",
          camera.name, camera.camera_id, options_.base_id,
          options_.base_id + 2u * static_cast<uint32_t>(camera.camera_id) + 1,
          can::kMaxStandardId));
    }
    camera_from_world_.push_back(camera.world_from_camera.inverse());
  }
}

Eigen::Vector3d PixartBoxSimulator::led_position(size_t object, size_t led, double time_s) const {
  const SceneObject& thing = scene_.objects.at(object);
  const FloorPose pose = pose_at(thing.trajectory, time_s);
  const Eigen::Vector2d offset = Eigen::Rotation2Dd(pose.theta) * thing.leds.at(led).position;
  return {pose.x + offset.x(), pose.y + offset.y(), thing.height_m};
}

std::vector<CameraView> PixartBoxSimulator::views_at(double time_s) {
  // The LEDs that are on, in scene order, where they are now: the same for every camera.
  struct LitLed {
    size_t object, led;
    Eigen::Vector3d world;
  };
  std::vector<LitLed> lit;
  for (size_t o = 0; o < scene_.objects.size(); ++o) {
    const SceneObject& object = scene_.objects[o];
    for (size_t l = 0; l < object.leds.size(); ++l) {
      if (object.leds[l].is_on(time_s)) lit.push_back({o, l, led_position(o, l, time_s)});
    }
  }
  std::normal_distribution<double> standard_normal;  // scaled: a zero sigma is not allowed
  std::vector<CameraView> views;
  views.reserve(rig_.cameras.size());
  for (size_t c = 0; c < rig_.cameras.size(); ++c) {
    CameraView view;
    view.camera_id = static_cast<uint16_t>(rig_.cameras[c].camera_id);
    for (const LitLed& led : lit) {
      auto pixel = rig_.cameras[c].model->project(camera_from_world_[c] * led.world);
      if (!pixel) continue;
      Eigen::Vector2d measured = *pixel;
      if (options_.noise_px > 0) {
        // y before x, written out: a call's arguments are drawn in an order each compiler
        // picks, and this keeps the one the recorded figures were made with (g++'s).
        const double noise_y = standard_normal(random_), noise_x = standard_normal(random_);
        measured += options_.noise_px * Eigen::Vector2d(noise_x, noise_y);
      }
      // The sensor reports whole pixels; x = 1023 is its "no point" value, so the last column
      // cannot be reported.
      const double x = std::round(measured.x()), y = std::round(measured.y());
      if (!(x >= 0 && x < kNoPoint && y >= 0 && y < kSensorHeight)) continue;
      if (view.points.size() == kPointsPerCamera) {
        ++view.excess;
        continue;
      }
      view.points.push_back(
          {static_cast<uint16_t>(x), static_cast<uint16_t>(y), led.object, led.led});
    }
    stats_.points += view.points.size();
    stats_.excess_points += static_cast<uint64_t>(view.excess);
    views.push_back(std::move(view));
  }
  ++stats_.samples;
  return views;
}

std::vector<can::CanFrame> PixartBoxSimulator::encode(const std::vector<CameraView>& views,
                                                      int64_t stamp_ns) const {
  std::vector<can::CanFrame> frames;
  frames.reserve(2 * views.size());
  for (const CameraView& view : views) {
    for (int half = 0; half < 2; ++half) {
      std::array<PointSlot, 2> slots;
      for (size_t s = 0; s < 2; ++s) {
        const size_t index = 2 * static_cast<size_t>(half) + s;
        if (index < view.points.size()) {
          slots[s] = std::array<uint16_t, 2>{view.points[index].x, view.points[index].y};
        }
      }
      frames.push_back(
          encode_pixart_frame(options_.base_id, view.camera_id, half, slots, stamp_ns));
    }
  }
  return frames;
}

std::vector<can::CanFrame> PixartBoxSimulator::frames_at(double time_s, int64_t stamp_ns) {
  return encode(views_at(time_s), stamp_ns);
}

std::vector<RobotTruth> PixartBoxSimulator::ground_truth(double time_s) const {
  std::vector<RobotTruth> robots;
  for (const SceneObject& object : scene_.objects) {
    if (object.kind != SceneObject::Kind::Robot) continue;
    robots.push_back({object.name, pose_at(object.trajectory, time_s)});
  }
  return robots;
}

}  // namespace mocap::pixart
