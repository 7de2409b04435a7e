#include "dds/fastdds/fastdds_type_adapter.hpp"

#include <new>

namespace mocap {

using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

DdsTypeAdapter::DdsTypeAdapter(const MessageType& type) : type_(type) {
  setName(type.dds_name().c_str());
  // Only the initial payload size: endpoints reallocate to what the topic carries.
  m_typeSize = 512;
  m_isGetKeyDefined = false;
}

bool DdsTypeAdapter::serialize(void* data, SerializedPayload_t* payload) {
  try {
    size_t length = type_.serialize(data, {payload->data, payload->max_size});
    payload->length = static_cast<uint32_t>(length);
    payload->encapsulation = payload->data[1] == 0 ? CDR_BE : CDR_LE;
    return true;
  } catch (const SerializationError&) {
    return false;
  }
}

bool DdsTypeAdapter::deserialize(SerializedPayload_t* payload, void* data) {
  auto* sample = static_cast<DdsSample*>(data);
  if (sample->skip) return true;
  try {
    if (sample->message == nullptr) sample->message = type_.create();
    type_.deserialize({payload->data, payload->length}, sample->message.get());
  } catch (const SerializationError&) {
    sample->malformed = true;
  } catch (const std::bad_alloc&) {
    sample->malformed = true;  // a corrupt length that asked for more than memory holds
  }
  return true;  // the sample is consumed either way; the subscription counts it
}

std::function<uint32_t()> DdsTypeAdapter::getSerializedSizeProvider(void* data) {
  return [this, data] { return static_cast<uint32_t>(type_.serialized_size(data)); };
}

void* DdsTypeAdapter::createData() { return new DdsSample(); }

void DdsTypeAdapter::deleteData(void* data) { delete static_cast<DdsSample*>(data); }

bool DdsTypeAdapter::getKey(void*, InstanceHandle_t*, bool) { return false; }

}  // namespace mocap
