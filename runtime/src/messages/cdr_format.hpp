// Serialized messages as human-readable, YAML-like text.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "messages/idl_schema.hpp"

namespace mocap {

struct CdrFormatOptions {
  // Sequences and arrays of numbers longer than this are cut, with their length noted.
  size_t max_items = 32;
};

// Formats the encapsulated XCDR1 data of a `type` message (a struct of `schema`). Throws
// IdlError when the type is unknown and SerializationError when the data is malformed.
std::string format_cdr(const IdlSchema& schema, std::string_view type,
                       std::span<const uint8_t> data, const CdrFormatOptions& options = {});

}  // namespace mocap
