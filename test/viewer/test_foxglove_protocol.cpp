// The Foxglove WebSocket protocol's frames (components/viewer/foxglove_bridge/
// foxglove_protocol.hpp): the server's JSON and binary frames byte for byte as the protocol
// specifies them, and the client's frames parsed or refused with the reason.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <mocap/message_type.hpp>
#include <nlohmann/json.hpp>

#include "viewer/foxglove_bridge/foxglove_protocol.hpp"

namespace mocap::foxglove {
namespace {

using nlohmann::json;

TEST(FoxgloveProtocol, ServerInfoNamesTheServerAndItsCapabilities) {
  json info = json::parse(
      server_info("mocap-graph", {"clientPublish"}, {"cdr"}, {{"host", "compute"}}, "42"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["name"], "mocap-graph");
  EXPECT_EQ(info["capabilities"], json::array({"clientPublish"}));
  EXPECT_EQ(info["supportedEncodings"], json::array({"cdr"}));
  EXPECT_EQ(info["metadata"]["host"], "compute");
  EXPECT_EQ(info["sessionId"], "42");
  // A read-only server: no capabilities, and no supportedEncodings (only for clientPublish).
  json plain = json::parse(server_info("s", {}, {}, {}, "1"));
  EXPECT_EQ(plain["capabilities"], json::array());
  EXPECT_FALSE(plain.contains("supportedEncodings"));
}

TEST(FoxgloveProtocol, AdvertiseCarriesEveryChannelField) {
  json frame = json::parse(advertise(
      {{7, "/mocap/poses", "cdr", "mocap_msgs/msg/X", "module mocap_msgs {};", "ros2idl"}}));
  EXPECT_EQ(frame["op"], "advertise");
  ASSERT_EQ(frame["channels"].size(), 1u);
  const json& c = frame["channels"][0];
  EXPECT_EQ(c["id"], 7);
  EXPECT_EQ(c["topic"], "/mocap/poses");
  EXPECT_EQ(c["encoding"], "cdr");
  EXPECT_EQ(c["schemaName"], "mocap_msgs/msg/X");
  EXPECT_EQ(c["schema"], "module mocap_msgs {};");
  EXPECT_EQ(c["schemaEncoding"], "ros2idl");
  EXPECT_EQ(json::parse(unadvertise({7, 9})),
            json::parse(R"({"op":"unadvertise","channelIds":[7,9]})"));
  EXPECT_EQ(json::parse(status(StatusLevel::Warning, "slow", "queue")),
            json::parse(R"({"op":"status","level":1,"message":"slow","id":"queue"})"));
  EXPECT_FALSE(json::parse(status(StatusLevel::Error, "x")).contains("id"));
}

TEST(FoxgloveProtocol, Ros2idlSchemaHasTheRootsDelimiterAndNoIncludeGuards) {
  const std::string definition =
      "#ifndef A_\n#define A_\n#include \"b/msg/B.idl\"\nmodule a { module msg { struct A "
      "{ b::msg::B b; }; }; };\n#endif  // A_\n\n" +
      std::string(80, '=') +
      "\nIDL: b/msg/B\n#ifndef B_\nmodule b { module msg { struct B "
      "{ double x; }; }; };\n#endif\n";
  EXPECT_EQ(ros2idl_schema("a/msg/A", definition),
            std::string(80, '=') +
                "\nIDL: a/msg/A\n#include \"b/msg/B.idl\"\nmodule a { module "
                "msg { struct A { b::msg::B b; }; }; };\n\n" +
                std::string(80, '=') +
                "\nIDL: b/msg/B\nmodule b { module msg { struct B { double x; }; }; };\n");
}

TEST(FoxgloveProtocol, MessageDataHeaderIsLittleEndian) {
  std::array<uint8_t, kMessageDataHeaderSize> header{};
  write_message_data_header(0x04030201u, 0x0c0b0a0908070605ull, header);
  EXPECT_EQ(header, (std::array<uint8_t, 13>{0x01, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,
                                             0x09, 0x0a, 0x0b, 0x0c}));
}

TEST(FoxgloveProtocol, ClientRequestsAreParsed) {
  auto subscribe = parse_client_text(
      R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":7},{"id":2,"channelId":9}]})");
  ASSERT_TRUE(subscribe && std::holds_alternative<Subscribe>(*subscribe));
  const auto& subscriptions = std::get<Subscribe>(*subscribe).subscriptions;
  ASSERT_EQ(subscriptions.size(), 2u);
  EXPECT_EQ(subscriptions[1].id, 2u);
  EXPECT_EQ(subscriptions[1].channel_id, 9u);

  auto unsubscribe = parse_client_text(R"({"op":"unsubscribe","subscriptionIds":[1,2]})");
  ASSERT_TRUE(unsubscribe && std::holds_alternative<Unsubscribe>(*unsubscribe));
  EXPECT_EQ(std::get<Unsubscribe>(*unsubscribe).subscription_ids, (std::vector<uint32_t>{1, 2}));

  auto advertise = parse_client_text(
      R"({"op":"advertise","channels":[{"id":3,"topic":"/cmd_vel","encoding":"cdr",)"
      R"("schemaName":"geometry_msgs/msg/Twist"}]})");
  ASSERT_TRUE(advertise && std::holds_alternative<ClientAdvertise>(*advertise));
  const ClientChannel& channel = std::get<ClientAdvertise>(*advertise).channels.at(0);
  EXPECT_EQ(channel.id, 3u);
  EXPECT_EQ(channel.topic, "/cmd_vel");
  EXPECT_EQ(channel.schema_name, "geometry_msgs/msg/Twist");

  auto unadvertise = parse_client_text(R"({"op":"unadvertise","channelIds":[3]})");
  ASSERT_TRUE(unadvertise && std::holds_alternative<ClientUnadvertise>(*unadvertise));
  // Ops of capabilities this server does not offer are ignored, not errors.
  EXPECT_FALSE(parse_client_text(R"({"op":"getParameters","parameterNames":[]})"));
}

// The message of the ProtocolError `parse` throws ("" if none).
template <class Parse>
std::string refusal(Parse&& parse) {
  try {
    parse();
  } catch (const ProtocolError& e) {
    return e.what();
  }
  return "";
}

TEST(FoxgloveProtocol, BadClientTextIsRefusedWithTheReason) {
  auto text = [](const char* frame) { return refusal([&] { parse_client_text(frame); }); };
  EXPECT_EQ(text("{not json"), "malformed JSON");
  EXPECT_EQ(text("[1,2]"), "a text frame must be a JSON object");
  EXPECT_EQ(text(R"({"subscriptions":[]})"), "a text frame needs an \"op\" string");
  EXPECT_EQ(text(R"({"op":"explode"})"), "unknown op \"explode\"");
  EXPECT_EQ(text(R"({"op":"subscribe"})"), "subscribe: missing field \"subscriptions\"");
  EXPECT_EQ(text(R"({"op":"subscribe","subscriptions":{}})"),
            "subscribe: \"subscriptions\" must be an array");
  EXPECT_EQ(text(R"({"op":"subscribe","subscriptions":[1]})"),
            "subscribe: \"subscriptions\" must hold objects");
  EXPECT_EQ(text(R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})"),
            "subscribe: \"id\" must be an unsigned 32-bit integer");
  EXPECT_EQ(text(R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})"),
            "subscribe: \"id\" must be an unsigned 32-bit integer");
  EXPECT_EQ(text(R"({"op":"unsubscribe","subscriptionIds":["1"]})"),
            "unsubscribe: \"subscriptionIds\" must hold unsigned 32-bit integers");
  EXPECT_EQ(text(R"({"op":"advertise","channels":[{"id":1,"topic":5,"encoding":"cdr",)"
                 R"("schemaName":"x"}]})"),
            "advertise: \"topic\" must be a string");
}

TEST(FoxgloveProtocol, ClientBinaryFramesAreParsedOrRefused) {
  const std::vector<uint8_t> frame = {0x01, 0x03, 0x00, 0x00, 0x00, 0xaa, 0xbb};
  ClientMessage message = parse_client_binary(frame);
  EXPECT_EQ(message.channel_id, 3u);
  EXPECT_EQ(std::vector<uint8_t>(message.payload.begin(), message.payload.end()),
            (std::vector<uint8_t>{0xaa, 0xbb}));
  auto binary = [](std::vector<uint8_t> bytes) {
    return refusal([&] { parse_client_binary(bytes); });
  };
  EXPECT_EQ(binary({}), "empty binary frame");
  EXPECT_EQ(binary({0x02, 0, 0, 0, 0}), "binary opcode 2 is not client Message Data (1)");
  EXPECT_EQ(binary({0x01, 0, 0}), "binary Message Data shorter than its 5-byte header");
}

}  // namespace
}  // namespace mocap::foxglove
