// The Foxglove bridge's state on its own: a recording graph and recording client links stand
// in for the component's context and the WebSocket server.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <mocap/logger.hpp>
#include <mocap_msgs/msg/alert.hpp>
#include <nlohmann/json.hpp>

#include "viewer/foxglove_bridge/foxglove_bridge.hpp"

namespace mocap::foxglove {
namespace {

using nlohmann::json;

struct RecordingGraph final : BridgeGraph {
  void subscribe(const std::string& topic, const MessageType&, const Qos& qos) override {
    subscribed[topic] = qos;
  }
  void unsubscribe(const std::string& topic) override { subscribed.erase(topic); }
  void publish(const std::string& topic, const MessageType&, std::shared_ptr<void>) override {
    published.push_back(topic);
  }
  std::map<std::string, Qos> subscribed;
  std::vector<std::string> published;
};

struct RecordingLinks final : ClientLinks {
  bool send_text(ClientId client, const std::string& text) override {
    texts[client].push_back(json::parse(text));
    return true;
  }
  bool send_binary(ClientId client, const void* data, size_t size) override {
    binaries[client].emplace_back(static_cast<const char*>(data), size);
    return true;
  }
  size_t buffered_bytes(ClientId) const override { return 0; }
  void close(ClientId client, const std::string& reason) override { closed[client] = reason; }
  std::map<ClientId, std::vector<json>> texts;
  std::map<ClientId, std::vector<std::string>> binaries;
  std::map<ClientId, std::string> closed;
};

const MessageType& alert_type() { return message_type<mocap_msgs::msg::Alert>(); }

struct BridgeTest : ::testing::Test {
  RecordingGraph graph;
  RecordingLinks links;
  Logger log{"bridge_test"};
  std::vector<KnownTopic> declared{{"/alerts", &alert_type(), {Qos::latched()}},
                                   {"/hidden/alerts", &alert_type(), {}}};

  FoxgloveBridge make(FoxgloveBridgeOptions options = {.topics = "/alerts"}) {
    return FoxgloveBridge(options, declared, "graph", graph, links, log);
  }
};

TEST_F(BridgeTest, OffersTheAllowedTopicsAndSendsALatchedMessageToALateSubscriber) {
  FoxgloveBridge bridge = make();
  EXPECT_EQ(bridge.channel_count(), 1u);
  ASSERT_TRUE(graph.subscribed.contains("/alerts"));
  EXPECT_FALSE(graph.subscribed.contains("/hidden/alerts"));  // not offered (topics)
  EXPECT_EQ(graph.subscribed.at("/alerts").durability, Durability::TransientLocal);

  auto alert = std::make_shared<mocap_msgs::msg::Alert>();
  alert->text("camera cam_1 silent");
  bridge.forward("/alerts", alert, Clock::time_point(std::chrono::seconds(3)));

  bridge.opened(7);
  ASSERT_EQ(links.texts[7].size(), 2u);
  EXPECT_EQ(links.texts[7][0]["op"], "serverInfo");
  EXPECT_EQ(links.texts[7][0]["metadata"]["graph"], "graph");
  const json& channel = links.texts[7][1]["channels"][0];
  EXPECT_EQ(channel["topic"], "/alerts");
  EXPECT_EQ(channel["schemaName"], "mocap_msgs/msg/Alert");
  EXPECT_EQ(channel["encoding"], "cdr");

  bridge.received(
      7, json{{"op", "subscribe"}, {"subscriptions", {{{"id", 42}, {"channelId", channel["id"]}}}}}
             .dump());
  ASSERT_EQ(links.binaries[7].size(), 1u);  // the latched message, at once
  const std::string& frame = links.binaries[7][0];
  ASSERT_GT(frame.size(), kMessageDataHeaderSize);
  EXPECT_EQ(static_cast<uint8_t>(frame[0]), 0x01);  // Message Data
  uint32_t subscription = 0;
  std::memcpy(&subscription, frame.data() + 1, 4);
  EXPECT_EQ(subscription, 42u);
  uint64_t received_ns = 0;
  std::memcpy(&received_ns, frame.data() + 5, 8);
  EXPECT_EQ(received_ns, 3'000'000'000u);
  auto decoded = std::static_pointer_cast<mocap_msgs::msg::Alert>(alert_type().create());
  alert_type().deserialize(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(frame.data()) +
                                                        kMessageDataHeaderSize,
                                                    frame.size() - kMessageDataHeaderSize),
                           decoded.get());
  EXPECT_EQ(decoded->text(), "camera cam_1 silent");

  bridge.closed(7);
  EXPECT_EQ(bridge.counts().clients_served, 1u);
  EXPECT_EQ(bridge.counts().sent, 1u);
}

TEST_F(BridgeTest, ATopicGoneFromTheDomainIsUnadvertisedAndADeclaredOneStays) {
  FoxgloveBridge bridge = make({.topics = ".*"});
  bridge.opened(1);
  bridge.update_topics({{"/other/alerts", &alert_type(), {}}});
  const json& advertised = links.texts[1].back();
  EXPECT_EQ(advertised["op"], "advertise");
  EXPECT_EQ(advertised["channels"][0]["topic"], "/other/alerts");
  const uint32_t id = advertised["channels"][0]["id"];
  bridge.update_topics({});
  EXPECT_EQ(links.texts[1].back()["op"], "unadvertise");
  EXPECT_EQ(links.texts[1].back()["channelIds"][0], id);
  EXPECT_EQ(bridge.channel_count(), 2u);  // the two declared ones
}

// A topic that is not latched is read only while a client watches it: with nobody watching,
// a volume's every camera topic would be read on the cores its fusion needs.
TEST_F(BridgeTest, ATopicThatIsNotLatchedIsReadOnlyWhileAClientWatchesIt) {
  FoxgloveBridge bridge = make({.topics = ".*"});
  EXPECT_TRUE(graph.subscribed.contains("/alerts"));  // latched: its last message waits
  EXPECT_FALSE(graph.subscribed.contains("/hidden/alerts"));
  bridge.opened(1);
  uint32_t id = 0;
  for (const json& channel : links.texts[1][1]["channels"]) {
    if (channel["topic"] == "/hidden/alerts") id = channel["id"];
  }
  ASSERT_NE(id, 0u) << "offered, though nobody reads it yet";
  bridge.received(
      1, json{{"op", "subscribe"}, {"subscriptions", {{{"id", 5}, {"channelId", id}}}}}.dump());
  EXPECT_FALSE(graph.subscribed.contains("/hidden/alerts")) << "subscribed on the server's thread";
  bridge.run_once();
  ASSERT_TRUE(graph.subscribed.contains("/hidden/alerts"));
  EXPECT_EQ(graph.subscribed.at("/hidden/alerts").durability, Durability::Volatile);

  bridge.received(1, json{{"op", "unsubscribe"}, {"subscriptionIds", {5}}}.dump());
  bridge.run_once();
  EXPECT_FALSE(graph.subscribed.contains("/hidden/alerts"));
  EXPECT_TRUE(graph.subscribed.contains("/alerts")) << "a latched topic is kept";
}

// max_rate_hz: a topic at 240 Hz reaches a client at about that rate (after a second's worth
// at once); a slower one loses nothing, however its messages bunch: ten processes' statuses
// coming together once a second.
TEST_F(BridgeTest, MaxRateThinsAFastTopicAndPassesASlowOneWhole) {
  FoxgloveBridge bridge = make({.topics = ".*", .max_rate_hz = 30});
  bridge.opened(1);
  std::map<std::string, uint32_t> ids;
  for (const json& channel : links.texts[1][1]["channels"]) ids[channel["topic"]] = channel["id"];
  bridge.received(1, json{{"op", "subscribe"},
                          {"subscriptions",
                           {{{"id", 1}, {"channelId", ids.at("/hidden/alerts")}},
                            {{"id", 2}, {"channelId", ids.at("/alerts")}}}}}
                         .dump());
  bridge.run_once();
  auto alert = std::make_shared<mocap_msgs::msg::Alert>();
  std::map<uint32_t, int> sent;  // subscription -> messages
  auto count = [&] {
    for (const std::string& frame : links.binaries[1]) {
      uint32_t subscription = 0;
      std::memcpy(&subscription, frame.data() + 1, 4);
      ++sent[subscription];
    }
    links.binaries[1].clear();
  };
  const Clock::time_point start(std::chrono::seconds(100));
  for (int i = 0; i < 480; ++i) {
    bridge.forward("/hidden/alerts", alert, start + std::chrono::microseconds(i * 1'000'000 / 240));
  }
  count();
  EXPECT_GE(sent[1], 30 + 55) << "a second's worth at once, then 30 a second";
  EXPECT_LE(sent[1], 30 + 61);
  for (int second = 0; second < 3; ++second) {
    for (int process = 0; process < 10; ++process) {
      bridge.forward("/alerts", alert, start + std::chrono::seconds(second));
    }
  }
  count();
  EXPECT_EQ(sent[2], 30);
}

TEST_F(BridgeTest, AClientPublishingWhileItIsOffIsClosed) {
  FoxgloveBridge bridge = make();
  bridge.opened(3);
  bridge.received_binary(3, std::string("\x01\x00\x00\x00\x00", 5));
  EXPECT_EQ(links.closed[3], "client publishing is off (client_publish: false)");
  bridge.run_once();
  EXPECT_TRUE(graph.published.empty());
}

TEST(FoxgloveBridgeOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(FoxgloveBridgeOptions{}.problem(), std::nullopt);
  EXPECT_EQ(FoxgloveBridgeOptions{.topics = "("}.problem()->rfind("topics: '(' is not a regular "
                                                                  "expression: ",
                                                                  0),
            0u);
  EXPECT_EQ(FoxgloveBridgeOptions{.max_image_rate_hz = -1}.problem(),
            "max_image_rate_hz: -1 is not a rate (0: every image)");
  EXPECT_EQ(FoxgloveBridgeOptions{.max_rate_hz = -1}.problem(),
            "max_rate_hz: -1 is not a rate (0: every message)");
  FoxgloveBridgeOptions no_room;
  no_room.queue.limit_bytes = 0;
  EXPECT_EQ(no_room.problem(), "queue.limit_bytes: 0 leaves no room for a message");
  RecordingGraph graph;
  RecordingLinks links;
  Logger log("bridge_test");
  try {
    FoxgloveBridge bridge(no_room, {}, "graph", graph, links, log);
    ADD_FAILURE() << "a queue without room accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "FoxgloveBridgeOptions::queue.limit_bytes: 0 leaves no room for a message");
  }
  EXPECT_THROW(FoxgloveBridge({.topics = "("}, {}, "graph", graph, links, log),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::foxglove
