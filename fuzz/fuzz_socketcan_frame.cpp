// What a raw CAN socket delivers, one struct can_frame per 16 bytes: from_linux_frame must make
// a frame that a classic CAN bus can carry out of any bytes (flags, oversized length, error
// flag), which to_linux_frame takes back unchanged and which candump's notation keeps.
#include <linux/can.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include "common/can_io/can_frame.hpp"
#include "common/can_io/candump_log.hpp"
#include "common/can_io/socketcan.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using mocap::can::CanFrame;
  for (size_t offset = 0; offset + sizeof(can_frame) <= size; offset += sizeof(can_frame)) {
    can_frame linux_frame;
    std::memcpy(&linux_frame, data + offset, sizeof(linux_frame));
    const CanFrame frame = mocap::can::from_linux_frame(linux_frame);
    mocap::can::validate_frame(frame);  // std::invalid_argument escapes: a crash
    if (frame.stamp_ns != 0) std::abort();
    if (mocap::can::from_linux_frame(mocap::can::to_linux_frame(frame)) != frame) std::abort();
    const mocap::can::CandumpRecord record =
        mocap::can::parse_candump_line("(0.0) can0 " + mocap::can::to_string(frame));
    if (record.frame != frame) std::abort();
  }
  return 0;
}
