// The test stream: FiducialArray messages whose content follows from a sequence number, so a
// receiver can check each one (order, gaps, duplicates, corruption) without the sender.
#pragma once

#include <cstdint>
#include <string>

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

// The content of `message` is what make_sequence_message() makes for its sequence number
// (the frame id is ignored: the sender writes the message's address there).
inline bool is_intact(const mocap_msgs::msg::FiducialArray& message) {
  mocap_msgs::msg::FiducialArray expected = make_sequence_message(message.header().stamp().sec());
  return message.fiducials() == expected.fiducials() && message.header().stamp().nanosec() == 0;
}

}  // namespace mocap::test
