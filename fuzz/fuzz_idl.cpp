// IDL text, as `mocap_topic echo --idl` and bag metadata give it: the parser must accept it or
// throw IdlError, never crash or hang. What parses is then used to format bytes, as echo does.
#include <cstdint>
#include <span>
#include <string_view>

#include <mocap/message_type.hpp>
#include "messages/cdr_format.hpp"
#include "messages/idl_schema.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Text up to the first NUL is IDL; what follows is CDR to format with the last struct.
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const size_t split = input.find('\0');
  const std::string_view text = input.substr(0, split);
  mocap::IdlSchema schema;
  try {
    schema.parse(text);
  } catch (const mocap::IdlError&) {
    return 0;
  }
  if (split == std::string_view::npos) return 0;
  // The struct named right after the NUL, up to a second NUL, formats the rest.
  const std::string_view rest = input.substr(split + 1);
  const size_t name_end = rest.find('\0');
  if (name_end == std::string_view::npos) return 0;
  const std::string_view cdr = rest.substr(name_end + 1);
  try {
    mocap::format_cdr(schema, rest.substr(0, name_end),
                      std::span(reinterpret_cast<const uint8_t*>(cdr.data()), cdr.size()));
  } catch (const mocap::IdlError&) {
  } catch (const mocap::SerializationError&) {
  }
  return 0;
}
