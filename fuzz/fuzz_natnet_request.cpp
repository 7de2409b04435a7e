// A datagram on the NatNet server's command port, where anything may come from anyone: the
// parser never throws and never reads past the datagram; what it accepts has the size its header
// says (one NUL more allowed), a version it reads is one a client can ask for, and a Bitstream
// command's version reads back as it was written.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "outputs/natnet_server/natnet_protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mocap::natnet;
  const std::string datagram(reinterpret_cast<const char*>(data), size);
  std::string problem;
  const std::optional<Request> request = parse_request(datagram, &problem);
  if (!request) {
    if (problem.empty()) std::abort();
    return 0;
  }
  const size_t payload = size - kHeaderSize;
  if (request->payload.size() != payload && request->payload.size() + 1 != payload) std::abort();
  if (request->id == kConnect) {
    if (const std::optional<Version> version = requested_version(*request)) {
      if (version->major == 0 && version->minor == 0) std::abort();
    }
  }
  const std::string text = command_text(*request);
  if (text.find('\0') != std::string::npos || text.size() > request->payload.size()) std::abort();
  if (const size_t comma = text.find(','); comma != std::string::npos) {
    if (const std::optional<Version> version = parse_version(text.substr(comma + 1))) {
      const std::string again = fmt::format("{}.{}", version->major, version->minor);
      if (parse_version(again) != version) std::abort();
    }
  }
  return 0;
}
