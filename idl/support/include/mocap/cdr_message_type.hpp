// MessageType for a fastddsgen class, through the class's own Fast CDR code.
#pragma once

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>

#include <new>

#include <mocap/message_type.hpp>

namespace mocap {

template <class T>
class CdrMessageType final : public MessageType {
 public:
  using MessageType::MessageType;

  std::shared_ptr<void> create() const override { return std::make_shared<T>(); }

  size_t serialized_size(const void* message) const override {
    return kEncapsulationSize + T::getCdrSerializedSize(*static_cast<const T*>(message));
  }

  size_t serialize(const void* message, std::span<uint8_t> out) const override {
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(out.data()), out.size());
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN,
                               eprosima::fastcdr::Cdr::DDS_CDR);
    try {
      cdr.serialize_encapsulation();
      static_cast<const T*>(message)->serialize(cdr);
    } catch (const eprosima::fastcdr::exception::Exception& e) {
      throw SerializationError(name() + ": " + e.what());
    }
    return cdr.getSerializedDataLength();
  }

  void deserialize(std::span<const uint8_t> data, void* message) const override {
    // Fast CDR reads through a non-const pointer but does not write.
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(const_cast<uint8_t*>(data.data())),
                                         data.size());
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN,
                               eprosima::fastcdr::Cdr::DDS_CDR);
    try {
      cdr.read_encapsulation();
      static_cast<T*>(message)->deserialize(cdr);
    } catch (const eprosima::fastcdr::exception::Exception& e) {
      throw SerializationError(name() + ": " + e.what());
    } catch (const std::bad_alloc&) {
      throw SerializationError(name() + ": a length field asks for more memory than there is");
    } catch (const std::length_error&) {
      throw SerializationError(name() + ": a length field is out of range");
    }
  }

 private:
  static constexpr size_t kEncapsulationSize = 4;
};

}  // namespace mocap
