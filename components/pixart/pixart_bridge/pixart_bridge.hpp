// PixArt points from the CAN frames of the camera boxes (docs/pixart_can.md).
//
// A box carries four PixArt sensors and sends each sensor's up to four points in two
// standard 8-byte frames: ID base + 2·camera_id for points 0–1, base + 2·camera_id + 1 for
// points 2–3, where camera_id = 4·box + camera. Each point is x then y, big-endian uint16.
// A coordinate of 1023 (the sensor's empty slot) or a y of 768 or more is "no point".
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/can_io/can_frame.hpp"

namespace mocap::pixart {

constexpr uint16_t kSensorWidth = 1024;
constexpr uint16_t kSensorHeight = 768;
constexpr uint16_t kNoPoint = 1023;
constexpr int kCamerasPerBox = 4;
constexpr int kPointsPerCamera = 4;

struct PixartPoint {
  uint16_t camera_id = 0;  // 4·box + camera in the box
  uint8_t point_id = 0;    // 0..3, the sensor's slot
  uint16_t x = 0;          // 0..1023
  uint16_t y = 0;          // 0..767
  int64_t stamp_ns = 0;    // of the frame that carried it
};

struct PixartDecoderOptions {
  // CAN ID of box 0, camera 0, points 0–1. The public ROS 1 `pixart` package uses 0x100.
  uint32_t base_id = 0x100;
  // Boxes on the bus: IDs base .. base + 8·boxes − 1 are PixArt frames, others unknown.
  int boxes = 8;

  // Why these options cannot be used, naming the field ("boxes: 0 is below 1"); nullopt when
  // they can. PixartDecoder's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct PixartDecodeStats {
  uint64_t frames = 0;          // PixArt frames decoded
  uint64_t points = 0;          // valid points
  uint64_t empty_slots = 0;     // slots holding the "no point" value
  uint64_t invalid_points = 0;  // x > 1023 or y in 768..1022 (not the empty value)
  uint64_t wrong_length = 0;    // PixArt IDs with a length other than 8
  uint64_t unknown_id = 0;      // other IDs, extended or remote frames
};

class PixartDecoder {
 public:
  // Throws std::invalid_argument for options that cannot be used (a base or box count that
  // leaves the 11-bit ID range).
  explicit PixartDecoder(PixartDecoderOptions options = {});

  // Appends the valid points of `frame` to `points`. Returns the camera the frame belongs to,
  // or nullopt when it is not a well-formed PixArt frame (counted in stats(), never thrown).
  std::optional<uint16_t> decode(const can::CanFrame& frame, std::vector<PixartPoint>& points);

  const PixartDecodeStats& stats() const { return stats_; }
  const PixartDecoderOptions& options() const { return options_; }

 private:
  PixartDecoderOptions options_;
  PixartDecodeStats stats_;
};

// A point slot as the box sends it: a position, or nullopt for "no point".
using PointSlot = std::optional<std::array<uint16_t, 2>>;

// The frame a box sends for `camera_id`'s slots 2·half and 2·half + 1 (half 0 or 1): what
// the simulator writes and what the decoder reads back.
can::CanFrame encode_pixart_frame(uint32_t base_id, uint16_t camera_id, int half,
                                  const std::array<PointSlot, 2>& slots, int64_t stamp_ns = 0);

}  // namespace mocap::pixart
