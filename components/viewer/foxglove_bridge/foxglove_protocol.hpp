// The Foxglove WebSocket protocol, v1 (subprotocol "foxglove.websocket.v1", also offered as
// "foxglove.sdk.v1"): what Foxglove, Lichtblick and @foxglove/ws-protocol clients speak to a
// robot. Text frames are JSON objects with an "op"; binary frames start with a one-byte opcode
// and carry little-endian integers. This file builds the server's frames and parses the
// client's, with no network and no middleware.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace mocap::foxglove {

// The subprotocols a server accepts, preferred first.
inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";
inline constexpr std::string_view kSdkSubprotocol = "foxglove.sdk.v1";

// A topic as the server advertises it. For our messages: encoding "cdr", schema_name the ROS 2
// type ("geometry_msgs/msg/Pose"), schema the "ros2idl" text (root definition first).
struct Channel {
  uint32_t id = 0;
  std::string topic;
  std::string encoding;
  std::string schema_name;
  std::string schema;
  std::string schema_encoding;
};

enum class StatusLevel { Info = 0, Warning = 1, Error = 2 };

// --- server -> client ----------------------------------------------------------------------

// {"op":"serverInfo",...}: the first frame of every connection.
std::string server_info(std::string_view name, const std::vector<std::string>& capabilities,
                        const std::vector<std::string>& supported_encodings,
                        const std::map<std::string, std::string>& metadata,
                        std::string_view session_id);
std::string advertise(const std::vector<Channel>& channels);
std::string unadvertise(const std::vector<uint32_t>& channel_ids);
std::string status(StatusLevel level, std::string_view message, std::string_view id = {});

// Binary Message Data: opcode 0x01, subscription id (u32), receive time in ns (u64), payload.
inline constexpr size_t kMessageDataHeaderSize = 1 + 4 + 8;
// Writes the 13-byte header in front of a payload the caller places after it.
void write_message_data_header(uint32_t subscription_id, uint64_t receive_time_ns,
                               std::span<uint8_t, kMessageDataHeaderSize> out);
// Rewrites the subscription id of a header write_message_data_header wrote: one serialized
// message, copied for each subscriber.
void set_message_data_subscription(uint32_t subscription_id,
                                   std::span<uint8_t, kMessageDataHeaderSize> header);

// --- client -> server ----------------------------------------------------------------------

struct Subscription {
  uint32_t id = 0;  // chosen by the client
  uint32_t channel_id = 0;
};
struct Subscribe {
  std::vector<Subscription> subscriptions;
};
struct Unsubscribe {
  std::vector<uint32_t> subscription_ids;
};
// A channel the client will publish on ("advertise" from the client; needs clientPublish).
struct ClientChannel {
  uint32_t id = 0;
  std::string topic;
  std::string encoding;
  std::string schema_name;
};
struct ClientAdvertise {
  std::vector<ClientChannel> channels;
};
struct ClientUnadvertise {
  std::vector<uint32_t> channel_ids;
};
using ClientRequest = std::variant<Subscribe, Unsubscribe, ClientAdvertise, ClientUnadvertise>;

// A frame the protocol does not allow; the message says what is wrong, for the close reason.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses a client's text frame. Throws ProtocolError for malformed JSON, a missing or unknown
// "op", or fields of the wrong type. Ops a server may ignore (parameters, services, connection
// graph, assets) come back as std::nullopt.
std::optional<ClientRequest> parse_client_text(std::string_view text);

// A client's binary Message Data frame: opcode 0x01, client channel id (u32), payload.
struct ClientMessage {
  uint32_t channel_id = 0;
  std::span<const uint8_t> payload;  // a view into the frame
};
// Throws ProtocolError for an empty or short frame or an opcode other than 0x01.
ClientMessage parse_client_binary(std::span<const uint8_t> frame);

}  // namespace mocap::foxglove
