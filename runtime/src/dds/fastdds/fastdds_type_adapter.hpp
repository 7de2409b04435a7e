// Fast DDS type support for any MessageType, so one adapter serves every generated type and
// the raw bytes of tools alike.
#pragma once

#include <memory>

#include <fastdds/dds/topic/TopicDataType.hpp>

#include <mocap/message_type.hpp>

namespace mocap {

// What a DataReader deserializes into. Writers are given the message object itself.
struct DdsSample {
  // Set before taking: an object to deserialize into, reused so that large messages do not
  // cost an allocation each; the adapter creates one when null.
  std::shared_ptr<void> message;
  bool skip = false;       // set before taking: drop without deserializing
  bool malformed = false;  // set by deserialization
};

class DdsTypeAdapter final : public eprosima::fastdds::dds::TopicDataType {
 public:
  explicit DdsTypeAdapter(const MessageType& type);

  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override;
  void* createData() override;
  void deleteData(void* data) override;
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle,
              bool force_md5) override;

 private:
  const MessageType& type_;
};

}  // namespace mocap
