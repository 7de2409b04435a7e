#include "pixart/pixart_bridge/pixart_bridge.hpp"

#include <stdexcept>
#include <string>

namespace mocap::pixart {

PixartDecoder::PixartDecoder(PixartDecoderOptions options) : options_(options) {
  // At most 256 boxes of 8 IDs fit the 11-bit range; checked first so that 8·boxes cannot wrap.
  if (options_.boxes < 1 || options_.boxes > 256 || options_.base_id > 0x7FF ||
      options_.base_id + 8u * static_cast<uint32_t>(options_.boxes) - 1 > 0x7FF) {
    throw std::invalid_argument("PixArt decoder: base_id " + std::to_string(options_.base_id) +
                                " with " + std::to_string(options_.boxes) +
                                " boxes leaves the 11-bit CAN ID range");
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
