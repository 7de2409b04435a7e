#include "viewer/foxglove_bridge/foxglove_protocol.hpp"

#include <limits>

#include <nlohmann/json.hpp>

namespace mocap::foxglove {
namespace {

using nlohmann::json;

// A JSON field as T, or ProtocolError naming the op and field.
template <class T>
T field(const json& object, std::string_view op, const char* name) {
  auto found = object.find(name);
  if (found == object.end()) {
    throw ProtocolError(std::string(op) + ": missing field \"" + name + "\"");
  }
  if constexpr (std::is_same_v<T, uint32_t>) {
    if (!found->is_number_unsigned() ||
        found->get<uint64_t>() > std::numeric_limits<uint32_t>::max()) {
      throw ProtocolError(std::string(op) + ": \"" + name +
                          "\" must be an unsigned 32-bit integer");
    }
    return found->get<uint32_t>();
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!found->is_string()) {
      throw ProtocolError(std::string(op) + ": \"" + name + "\" must be a string");
    }
    return found->get<std::string>();
  } else {
    if (!found->is_array()) {
      throw ProtocolError(std::string(op) + ": \"" + name + "\" must be an array");
    }
    return *found;
  }
}

std::vector<uint32_t> id_list(const json& object, std::string_view op, const char* name) {
  std::vector<uint32_t> ids;
  for (const json& id : field<json>(object, op, name)) {
    if (!id.is_number_unsigned() || id.get<uint64_t>() > std::numeric_limits<uint32_t>::max()) {
      throw ProtocolError(std::string(op) + ": \"" + name +
                          "\" must hold unsigned 32-bit integers");
    }
    ids.push_back(id.get<uint32_t>());
  }
  return ids;
}

const json& object_in(const json& item, std::string_view op, const char* name) {
  if (!item.is_object()) {
    throw ProtocolError(std::string(op) + ": \"" + name + "\" must hold objects");
  }
  return item;
}

void put_u32(uint8_t* out, uint32_t value) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<uint8_t>(value >> (8 * i));
}

}  // namespace

std::string server_info(std::string_view name, const std::vector<std::string>& capabilities,
                        const std::vector<std::string>& supported_encodings,
                        const std::map<std::string, std::string>& metadata,
                        std::string_view session_id) {
  json info = {{"op", "serverInfo"},
               {"name", name},
               {"capabilities", capabilities},
               {"metadata", metadata},
               {"sessionId", session_id}};
  if (!supported_encodings.empty()) info["supportedEncodings"] = supported_encodings;
  return info.dump();
}

std::string advertise(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const Channel& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertise(const std::vector<uint32_t>& channel_ids) {
  return json{{"op", "unadvertise"}, {"channelIds", channel_ids}}.dump();
}

std::string status(StatusLevel level, std::string_view message, std::string_view id) {
  json out = {{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}};
  if (!id.empty()) out["id"] = id;
  return out.dump();
}

void write_message_data_header(uint32_t subscription_id, uint64_t receive_time_ns,
                               std::span<uint8_t, kMessageDataHeaderSize> out) {
  out[0] = 0x01;
  put_u32(out.data() + 1, subscription_id);
  for (int i = 0; i < 8; ++i) out[5 + i] = static_cast<uint8_t>(receive_time_ns >> (8 * i));
}

void set_message_data_subscription(uint32_t subscription_id,
                                   std::span<uint8_t, kMessageDataHeaderSize> header) {
  put_u32(header.data() + 1, subscription_id);
}

std::optional<ClientRequest> parse_client_text(std::string_view text) {
  json frame = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (frame.is_discarded()) throw ProtocolError("malformed JSON");
  if (!frame.is_object()) throw ProtocolError("a text frame must be a JSON object");
  auto op_field = frame.find("op");
  if (op_field == frame.end() || !op_field->is_string()) {
    throw ProtocolError("a text frame needs an \"op\" string");
  }
  const std::string op = op_field->get<std::string>();
  if (op == "subscribe") {
    Subscribe request;
    for (const json& item : field<json>(frame, op, "subscriptions")) {
      const json& s = object_in(item, op, "subscriptions");
      request.subscriptions.push_back(
          {field<uint32_t>(s, op, "id"), field<uint32_t>(s, op, "channelId")});
    }
    return request;
  }
  if (op == "unsubscribe") return Unsubscribe{id_list(frame, op, "subscriptionIds")};
  if (op == "advertise") {
    ClientAdvertise request;
    for (const json& item : field<json>(frame, op, "channels")) {
      const json& c = object_in(item, op, "channels");
      request.channels.push_back({field<uint32_t>(c, op, "id"), field<std::string>(c, op, "topic"),
                                  field<std::string>(c, op, "encoding"),
                                  field<std::string>(c, op, "schemaName")});
    }
    return request;
  }
  if (op == "unadvertise") return ClientUnadvertise{id_list(frame, op, "channelIds")};
  static const char* const kIgnored[] = {"getParameters",
                                         "setParameters",
                                         "subscribeParameterUpdates",
                                         "unsubscribeParameterUpdates",
                                         "subscribeConnectionGraph",
                                         "unsubscribeConnectionGraph",
                                         "fetchAsset"};
  for (const char* ignored : kIgnored) {
    if (op == ignored) return std::nullopt;
  }
  throw ProtocolError("unknown op \"" + op + "\"");
}

ClientMessage parse_client_binary(std::span<const uint8_t> frame) {
  if (frame.empty()) throw ProtocolError("empty binary frame");
  if (frame[0] != 0x01) {
    throw ProtocolError("binary opcode " + std::to_string(frame[0]) +
                        " is not client Message Data (1)");
  }
  if (frame.size() < 5) throw ProtocolError("binary Message Data shorter than its 5-byte header");
  uint32_t channel = 0;
  for (int i = 0; i < 4; ++i) channel |= static_cast<uint32_t>(frame[1 + i]) << (8 * i);
  return {channel, frame.subspan(5)};
}

}  // namespace mocap::foxglove
