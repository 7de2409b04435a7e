// Random but valid XCDR1 data for any type of an IdlSchema, for round-trip tests.
#pragma once

#include <cstdint>
#include <random>
#include <string_view>
#include <vector>

#include "messages/idl_schema.hpp"

namespace mocap::test {

// Encapsulated little-endian CDR of a `type` message with random values: sequences of 0 to 3
// elements, strings of 0 to 8 printable characters, padding bytes zero.
std::vector<uint8_t> random_cdr(const IdlSchema& schema, std::string_view type,
                                std::mt19937& random);

}  // namespace mocap::test
