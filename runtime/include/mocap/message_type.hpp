// Type support as the runtime sees it: a name, a definition, and CDR in and out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace mocap {

// Thrown when bytes cannot be turned into a message or a message does not fit a buffer.
class SerializationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Everything the runtime needs to move one message type: its names, its IDL definition,
// and how to create, serialize and deserialize it. Serialized form is what goes on the DDS
// wire: the 4-byte encapsulation header followed by XCDR1 (plain CDR) data.
//
// The generated message library implements this for every type of idl/; components reach
// it through message_type<T>() and never call it directly.
class MessageType {
 public:
  // name: ROS 2 style, "pkg/msg/Type". definition: the type's own IDL file text.
  MessageType(std::string name, std::string definition);
  virtual ~MessageType() = default;
  MessageType(const MessageType&) = delete;
  MessageType& operator=(const MessageType&) = delete;

  // "mocap_msgs/msg/FiducialArray".
  const std::string& name() const { return name_; }
  // The name on the DDS wire, as ROS 2 spells it: "mocap_msgs::msg::dds_::FiducialArray_".
  const std::string& dds_name() const { return dds_name_; }
  // The IDL text of this type's own file.
  const std::string& definition() const { return definition_; }

  virtual std::shared_ptr<void> create() const = 0;
  // Size of serialize()'s output for this message, encapsulation header included.
  virtual size_t serialized_size(const void* message) const = 0;
  // Writes the encapsulated CDR of `message` to `out` and returns the bytes written.
  // Throws SerializationError if `out` is too small.
  virtual size_t serialize(const void* message, std::span<uint8_t> out) const = 0;
  // Reads encapsulated CDR into `message`. Throws SerializationError on truncated or
  // malformed input; `message` is then in a valid but unspecified state.
  virtual void deserialize(std::span<const uint8_t> cdr, void* message) const = 0;

 private:
  std::string name_;
  std::string dds_name_;
  std::string definition_;
};

// The type support of message class T. Declared here, specialized by each generated
// message header (e.g. <mocap_msgs/msg/fiducial_array.hpp>), which must be included.
template <class T>
const MessageType& message_type();

// Every message type linked into this process registers itself when its library loads,
// so tools can find a type by the name they discover on the wire.
void register_message_type(const MessageType& type);
// Finds a type by ROS name ("pkg/msg/Type") or DDS name ("pkg::msg::dds_::Type_").
const MessageType* find_message_type(std::string_view name);
std::vector<const MessageType*> registered_message_types();

// The type's definition followed by those of every type it includes, in the layout of
// ROS 2's "ros2idl" message definitions (rosbag2, type description services).
std::string full_definition(const MessageType& type);
// full_definition()'s text as a "ros2idl" schema of an MCAP file or a Foxglove channel holds
// it: the root gets its own delimiter line, as ROS 2's tools write it, and the include guards
// (#ifndef, #define, #endif), which Foxglove's parser does not read, are left out. #include
// lines stay.
std::string ros2idl_schema(std::string_view root_type, std::string_view full_definition);

// ROS 2 name mangling for DDS.
std::string dds_type_name(std::string_view ros_type_name);    // a/msg/T -> a::msg::dds_::T_
std::string ros_type_name(std::string_view dds_type_name);    // inverse; unchanged if not ROS
std::string dds_topic_name(std::string_view ros_topic_name);  // /a/b -> rt/a/b
std::string ros_topic_name(std::string_view dds_topic_name);  // inverse; unchanged if not ROS

}  // namespace mocap
