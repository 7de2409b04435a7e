#include "common/can_io/can_frame.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::can {

void validate_frame(const CanFrame& frame) {
  const uint32_t max_id = frame.extended ? kMaxExtendedId : kMaxStandardId;
  if (frame.id > max_id) {
    throw std::invalid_argument(fmt::format("CAN id 0x{:X} does not fit a{} frame (max 0x{:X})",
                                            frame.id, frame.extended ? "n extended" : " standard",
                                            max_id));
  }
  if (frame.length > kMaxDataLength) {
    throw std::invalid_argument(fmt::format("CAN frame length {} is above {}",
                                            static_cast<int>(frame.length), kMaxDataLength));
  }
}

std::string to_string(const CanFrame& frame) {
  std::string text =
      frame.extended ? fmt::format("{:08X}#", frame.id) : fmt::format("{:03X}#", frame.id);
  if (frame.remote) {
    text += 'R';
    if (frame.length != 0) text += fmt::format("{:X}", frame.length);
    return text;
  }
  // A length above 8 (an invalid frame) prints the 8 bytes there are.
  const size_t length = std::min<size_t>(frame.length, frame.data.size());
  for (size_t i = 0; i < length; ++i) text += fmt::format("{:02X}", frame.data[i]);
  return text;
}

}  // namespace mocap::can
