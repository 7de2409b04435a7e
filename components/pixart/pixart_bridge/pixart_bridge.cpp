#include "pixart/pixart_bridge/pixart_bridge.hpp"

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace mocap::pixart {

std::optional<std::string> PixartDecoderOptions::problem() const {
  if (boxes < 1) return fmt::format("boxes: {} is below 1", boxes);
  // At most 256 boxes of 8 IDs fit the 11-bit range; the last ID in 64 bits cannot wrap.
  if (boxes > 256) {
    return fmt::format("boxes: {}; at most 256 boxes of 8 IDs fit the 11-bit CAN IDs", boxes);
  }
  const uint64_t last_id = uint64_t{base_id} + 8u * static_cast<uint64_t>(boxes) - 1;
  if (last_id > can::kMaxStandardId) {
    return fmt::format("base_id: {:#x} with {} boxes needs CAN IDs up to {:#x}, above {:#x}",
                       base_id, boxes, last_id, can::kMaxStandardId);
  }
  return std::nullopt;
}

PixartDecoder::PixartDecoder(PixartDecoderOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("PixartDecoderOptions::" + *problem);
  }
}

std::optional<uint16_t> PixartDecoder::decode(const can::CanFrame& frame,
                                              std::vector<PixartPoint>& points) {
  const uint32_t ids = 8u * static_cast<uint32_t>(options_.boxes);
  if (frame.extended || frame.remote || frame.id < options_.base_id ||
      frame.id >= options_.base_id + ids) {
    ++stats_.unknown_id;
    return std::nullopt;
  }
  if (frame.length != 8) {
    ++stats_.wrong_length;
    return std::nullopt;
  }
  ++stats_.frames;
  const uint32_t offset = frame.id - options_.base_id;
  const auto camera = static_cast<uint16_t>(offset >> 1);
  const int first_slot = 2 * static_cast<int>(offset & 1u);
  for (int slot = 0; slot < 2; ++slot) {
    const uint8_t* bytes = frame.data.data() + 4 * slot;
    auto x = static_cast<uint16_t>((bytes[0] << 8) | bytes[1]);
    auto y = static_cast<uint16_t>((bytes[2] << 8) | bytes[3]);
    if (x == kNoPoint || y == kNoPoint) {
      ++stats_.empty_slots;
    } else if (x >= kSensorWidth || y >= kSensorHeight) {
      ++stats_.invalid_points;
    } else {
      points.push_back({camera, static_cast<uint8_t>(first_slot + slot), x, y, frame.stamp_ns});
      ++stats_.points;
    }
  }
  return camera;
}

can::CanFrame encode_pixart_frame(uint32_t base_id, uint16_t camera_id, int half,
                                  const std::array<PointSlot, 2>& slots, int64_t stamp_ns) {
  can::CanFrame frame;
  frame.id = base_id + 2u * camera_id + static_cast<uint32_t>(half & 1);
  frame.length = 8;
  frame.stamp_ns = stamp_ns;
  for (int slot = 0; slot < 2; ++slot) {
    std::array<uint16_t, 2> value =
        slots[slot].value_or(std::array<uint16_t, 2>{kNoPoint, kNoPoint});
    uint8_t* bytes = frame.data.data() + 4 * slot;
    bytes[0] = static_cast<uint8_t>(value[0] >> 8);
    bytes[1] = static_cast<uint8_t>(value[0] & 0xFF);
    bytes[2] = static_cast<uint8_t>(value[1] >> 8);
    bytes[3] = static_cast<uint8_t>(value[1] & 0xFF);
  }
  return frame;
}

}  // namespace mocap::pixart
