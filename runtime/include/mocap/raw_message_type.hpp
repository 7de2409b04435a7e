// A message type that keeps the serialized bytes as they are: for tools that receive types
// they were not built with (echo, hz, recording) and for replaying recorded bytes.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include <mocap/message_type.hpp>

namespace mocap {

// Messages are std::vector<uint8_t> holding the encapsulated CDR.
class RawMessageType final : public MessageType {
 public:
  // `dds_type_name` as discovered on the wire, e.g. "sensor_msgs::msg::dds_::Image_".
  explicit RawMessageType(const std::string& dds_type_name)
      : MessageType(ros_type_name(dds_type_name), "") {}

  std::shared_ptr<void> create() const override { return std::make_shared<std::vector<uint8_t>>(); }
  size_t serialized_size(const void* message) const override { return bytes(message).size(); }
  size_t serialize(const void* message, std::span<uint8_t> out) const override {
    const auto& data = bytes(message);
    if (data.size() > out.size()) throw SerializationError("buffer too small for raw message");
    std::memcpy(out.data(), data.data(), data.size());
    return data.size();
  }
  void deserialize(std::span<const uint8_t> cdr, void* message) const override {
    static_cast<std::vector<uint8_t>*>(message)->assign(cdr.begin(), cdr.end());
  }

 private:
  static const std::vector<uint8_t>& bytes(const void* message) {
    return *static_cast<const std::vector<uint8_t>*>(message);
  }
};

}  // namespace mocap
