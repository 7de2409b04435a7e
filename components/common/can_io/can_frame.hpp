// A classic CAN 2.0 frame as every input of the PixArt bridge delivers it (SocketCAN, an SLCAN
// serial adaptor, a candump log), independent of where it came from.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace mocap::can {

// Largest identifiers of the two frame formats: 11 bits (standard) and 29 bits (extended).
inline constexpr uint32_t kMaxStandardId = 0x7FF;
inline constexpr uint32_t kMaxExtendedId = 0x1FFFFFFF;
// Classic CAN carries at most 8 data bytes (CAN FD frames are not supported).
inline constexpr uint8_t kMaxDataLength = 8;

struct CanFrame {
  // Identifier without any flag bits: at most kMaxStandardId, or kMaxExtendedId if extended.
  uint32_t id = 0;
  // 29-bit identifier (CAN 2.0B) instead of 11 bits.
  bool extended = false;
  // Remote transmission request: `length` is the requested length and `data` is unused.
  bool remote = false;
  // Data length code, 0..8: the number of valid bytes at the front of `data`.
  uint8_t length = 0;
  std::array<uint8_t, 8> data{};
  // When the frame was received, nanoseconds since the Unix epoch (CLOCK_REALTIME, like the
  // runtime's clock and candump); 0 when unknown.
  int64_t stamp_ns = 0;

  // Compares every field, the unused bytes of `data` and the stamp included.
  bool operator==(const CanFrame&) const = default;
};

// Throws std::invalid_argument naming the problem when `frame` cannot go on a classic CAN bus:
// an identifier too large for its format, or a length above 8. The encoders call it, so that
// a bad frame is refused rather than silently truncated.
void validate_frame(const CanFrame& frame);

// The frame in candump's notation, as `candump -L` logs it and `cansend` takes it: identifier
// in uppercase hex, 3 digits (standard) or 8 (extended), '#', then the data bytes in uppercase
// hex: "123#DEADBEEF", "12345678#00", "123#" (no data). A remote frame is "123#R", followed by
// its length digit when that is not 0 ("123#R4"), as can-utils writes it. The stamp is not
// part of it. Does not validate: a frame that validate_frame refuses is printed as it is.
std::string to_string(const CanFrame& frame);

}  // namespace mocap::can
