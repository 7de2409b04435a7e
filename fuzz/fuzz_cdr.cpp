// CDR from any DDS peer: the first byte picks one of the message types of idl/, the rest is
// its encapsulated CDR. The generated deserializer and the schema-driven formatter of
// `mocap_topic echo` (which also reads foreign types through --idl) must both turn bad bytes
// into a SerializationError; what deserializes must serialize back to bytes that deserialize
// to the same serialization.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include <mocap/generated_message_types.hpp>
#include <mocap/message_type.hpp>
#include "messages/cdr_format.hpp"
#include "messages/idl_schema.hpp"

namespace {

struct Types {
  std::vector<const mocap::MessageType*> list;
  std::vector<mocap::IdlSchema> schemas;
};

const Types& types() {
  static const Types all = [] {
    Types t;
    t.list = mocap::generated_message_types();
    for (const auto* type : t.list) {
      t.schemas.emplace_back().parse(mocap::full_definition(*type));
    }
    return t;
  }();
  return all;
}

std::vector<uint8_t> serialize(const mocap::MessageType& type, const void* message) {
  std::vector<uint8_t> out(type.serialized_size(message));
  out.resize(type.serialize(message, out));
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const Types& all = types();
  const size_t index = data[0] % all.list.size();
  const mocap::MessageType& type = *all.list[index];
  const std::span<const uint8_t> cdr(data + 1, size - 1);

  try {
    mocap::format_cdr(all.schemas[index], type.name(), cdr);
  } catch (const mocap::SerializationError&) {
  }

  auto message = type.create();
  try {
    type.deserialize(cdr, message.get());
  } catch (const mocap::SerializationError&) {
    return 0;
  }
  const std::vector<uint8_t> once = serialize(type, message.get());
  auto again = type.create();
  type.deserialize(once, again.get());  // must not throw: these are our own bytes
  if (serialize(type, again.get()) != once) std::abort();
  mocap::format_cdr(all.schemas[index], type.name(), once);
  return 0;
}
