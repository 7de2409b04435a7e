// The test stream: FiducialArray messages whose content follows from a sequence number, so a
// receiver can check each one (order, gaps, duplicates, corruption) without the sender.
#pragma once

#include <cstdint>
#include <string>

#include <unistd.h>

#include <fmt/format.h>

#include <mocap_msgs/msg/fiducial_array.hpp>

namespace mocap::test {

inline constexpr const char* kSequenceTopic = "/test/sequence";

inline mocap_msgs::msg::FiducialArray make_sequence_message(int32_t sequence) {
  mocap_msgs::msg::FiducialArray message;
  message.header().stamp().sec(sequence);
  for (int i = 0; i < sequence % 7 + 1; ++i) {
    mocap_msgs::msg::Fiducial fiducial;
    fiducial.x(static_cast<float>(sequence + i));
    fiducial.y(static_cast<float>(2 * sequence + i));
    fiducial.z(static_cast<float>(i));
    fiducial.size(1.0f);
    fiducial.uncertainty(0.5f);
    message.fiducials().push_back(fiducial);
  }
  return message;
}

// Names one object in one process: what the sender writes as the frame id, so that an in-process
// subscriber can tell it received the publisher's object. The process id is part of it because
// an address alone is not unique across processes (under AddressSanitizer, whose allocator maps
// fixed regions, a remote copy can land at the very same address).
inline std::string object_identity(const void* object) {
  return fmt::format("{}:{}", ::getpid(), reinterpret_cast<uintptr_t>(object));
}

// The content of `message` is what make_sequence_message() makes for its sequence number
// (the frame id is ignored: the sender writes object_identity() there).
inline bool is_intact(const mocap_msgs::msg::FiducialArray& message) {
  mocap_msgs::msg::FiducialArray expected = make_sequence_message(message.header().stamp().sec());
  return message.fiducials() == expected.fiducials() && message.header().stamp().nanosec() == 0;
}

}  // namespace mocap::test
