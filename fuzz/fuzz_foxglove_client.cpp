// Frames from Foxglove WebSocket clients (foxglove_protocol.hpp): anyone who reaches the
// bridge's port sends them. Every input is tried as a text frame and as a binary frame; each
// parser returns a request or throws ProtocolError, nothing else, and a binary frame's channel
// id and payload are its bytes after the opcode.
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>

#include "viewer/foxglove_bridge/foxglove_protocol.hpp"

using namespace mocap::foxglove;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    parse_client_text(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const ProtocolError&) {
  }
  ClientMessage message;
  try {
    message = parse_client_binary(std::span(data, size));
  } catch (const ProtocolError&) {
    return 0;
  }
  uint32_t id = 0;
  for (int i = 0; i < 4; ++i) id |= static_cast<uint32_t>(data[1 + i]) << (8 * i);
  if (message.channel_id != id || message.payload.data() != data + 5 ||
      message.payload.size() != size - 5) {
    std::abort();
  }
  return 0;
}
