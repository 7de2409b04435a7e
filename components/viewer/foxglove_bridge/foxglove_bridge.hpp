// The Foxglove bridge's state, without the graph or the network: which topics it offers as
// channels, what each client subscribed to and publishes, and the frames queued for each.
// Every topic the graph declares, and every topic discovered with a type this process knows,
// is advertised with encoding "cdr" and its "ros2idl" schema; topics that come and go are
// advertised and unadvertised while clients are connected. A client that reads slowly loses
// its oldest messages (client_queue.hpp) and is disconnected if it stays behind: the graph never
// waits for a viewer. The foxglove_bridge plugin joins it to its component's context and the
// WebSocket server.
//
// Thread safety: the client handlers (opened .. refused) run on the server's thread, forward()
// on the graph's; the rest on the component's strand. One mutex guards the state, and the
// graph is never called with it held (a latched topic's message may arrive inside subscribe).
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <mocap/component.hpp>
#include <mocap/logger.hpp>

#include "viewer/foxglove_bridge/client_queue.hpp"
#include "viewer/foxglove_bridge/foxglove_protocol.hpp"
#include "viewer/foxglove_bridge/websocket_server.hpp"

namespace mocap::foxglove {

struct FoxgloveBridgeOptions {
  // A regular expression (ECMAScript) of the whole names of the topics to offer, and on which
  // clients may publish.
  std::string topics = ".*";
  // Most sensor_msgs/msg/Image messages a second per client and topic; 0: all.
  double max_image_rate_hz = 10;
  // Most messages a second per client and topic of the other types, on average; a topic slower
  // than that passes whole, however its messages bunch within a second (a second's worth pass
  // at once): /diagnostics, of every process, and /alerts lose nothing. 0: all.
  double max_rate_hz = 0;
  // Clients may publish (Foxglove's clientPublish) on offered topics, in CDR of a known type.
  bool client_publish = false;
  ClientQueueOptions queue = {};

  // Why these options cannot be used ("topics: '(' is not a regular expression: ..."), naming
  // the field (the queue's by its path: "queue.limit_bytes: ..."); nullopt when they can.
  // FoxgloveBridge's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// The graph as the bridge uses it (the plugin's component context).
class BridgeGraph {
 public:
  virtual ~BridgeGraph() = default;
  // From now on, `topic`'s messages go to FoxgloveBridge::forward.
  virtual void subscribe(const std::string& topic, const MessageType& type, const Qos& qos) = 0;
  virtual void unsubscribe(const std::string& topic) = 0;
  virtual void publish(const std::string& topic, const MessageType& type,
                       std::shared_ptr<void> message) = 0;
};

// The clients' connections (the plugin's WebSocket server).
class ClientLinks {
 public:
  virtual ~ClientLinks() = default;
  virtual bool send_text(ClientId client, const std::string& text) = 0;
  virtual bool send_binary(ClientId client, const void* data, size_t size) = 0;
  virtual size_t buffered_bytes(ClientId client) const = 0;
  virtual void close(ClientId client, const std::string& reason) = 0;
};

// What the bridge has done, for its closing line.
struct BridgeCounts {
  uint64_t clients_served = 0;
  uint64_t sent = 0;
  uint64_t dropped = 0;
  uint64_t client_messages = 0;
  uint64_t client_messages_dropped = 0;
  uint64_t refused_requests = 0;
};

class FoxgloveBridge {
 public:
  // Offers the `declared` topics (the launch file's), which stay offered. Throws
  // std::invalid_argument for options that do not check.
  FoxgloveBridge(FoxgloveBridgeOptions options, const std::vector<KnownTopic>& declared,
                 std::string graph_name, BridgeGraph& graph, ClientLinks& links, const Logger& log);

  // The topics discovered now: new ones offered, gone ones (never declared) unadvertised.
  void update_topics(std::vector<KnownTopic> discovered);
  // The bridge's turn: subscriptions asked for or no longer watched, queued frames handed to
  // the links, clients too slow disconnected, clients' messages published.
  void run_once();
  // A message of an offered topic, received at `received`.
  void forward(const std::string& topic, const std::shared_ptr<const void>& message,
               Clock::time_point received);

  // The clients, from the server's thread.
  void opened(ClientId client);
  void closed(ClientId client);
  void received(ClientId client, const std::string& text);
  void received_binary(ClientId client, const std::string& frame);
  // A request refused for its Host or Origin; each reason is logged once.
  void refused(const std::string& why);

  size_t channel_count() const;
  BridgeCounts counts() const;

 private:
  // A topic the bridge offers; advertised while it has a channel. Subscribed to when a client
  // first asks for it, and let go of when the last client that asked stops watching: a
  // volume's cameras would otherwise stream every frame of every camera to the bridge's host
  // with nobody watching, and the bridge read them on the cores the fusion needs. Latched
  // topics at once, so that their last message is there for the first client.
  struct TopicState {
    const MessageType* type = nullptr;
    bool latched = false;
    uint32_t channel_id = 0;  // 0: not advertised now
    bool subscribed = false;
  };
  struct ChannelState {
    Channel channel;
    const MessageType* type;
    bool latched;
    // A latched topic's last message as a Message Data frame, for clients subscribing later.
    std::string last_frame;
  };
  // A channel a client advertised to publish on.
  struct ClientChannelState {
    std::string topic;
    const MessageType* type;
  };
  // max_rate_hz's token bucket: a message passes with a whole token; tokens come at the rate, up
  // to a second's worth.
  struct RateBudget {
    double tokens = 0;
    Clock::time_point at{};
  };
  struct ClientState {
    explicit ClientState(ClientQueueOptions options) : queue(options) {}
    ClientQueue queue;
    std::map<uint32_t, uint32_t> subscription_of_channel;  // channel id -> subscription id
    std::map<uint32_t, Clock::time_point> last_image;      // channel id -> last image sent
    std::map<uint32_t, RateBudget> budget;                 // channel id -> its max_rate_hz
    std::map<uint32_t, ClientChannelState> published;      // client channel id -> topic
  };
  struct ClientMessageToPublish {
    std::string topic;
    const MessageType* type;
    std::shared_ptr<void> message;
  };

  bool offered(const KnownTopic& topic) const;
  void update(const std::vector<KnownTopic>& present, bool announce);
  void unsubscribe_unwatched();
  bool watched(uint32_t channel_id) const;
  void note_unwatched(const std::vector<uint32_t>& channels);
  void subscribe_first_asked();
  void subscribe(const std::string& name, const TopicState& topic);
  void refuse(ClientId client, const std::string& reason);
  void client_advertised(ClientId client, const ClientAdvertise& advertised);
  void publish_inbox();
  static std::string message_data(const ChannelState& channel, const void* message,
                                  Clock::time_point received);
  static void queue_frame(ClientState& state, const std::string& frame, uint32_t subscription);
  void pump(ClientId client, ClientState& state);
  void pump_all();

  const FoxgloveBridgeOptions options_;
  const std::string graph_name_;
  BridgeGraph& graph_;
  ClientLinks& links_;
  const Logger& log_;
  std::regex allowed_;
  Clock::duration image_period_{};
  double rate_burst_ = 0;               // max_rate_hz's second of messages, at least one
  std::set<std::string> declared_;      // offered topics of the launch file: always present
  std::set<std::string> warned_types_;  // topics published with two types, warned about once
  mutable std::mutex mutex_;            // guards what follows
  std::map<std::string, TopicState> topics_;
  std::set<std::string> first_asked_;  // topics a client asked for, not subscribed to yet
  std::set<std::string> unwatched_;    // topics the last watching client stopped watching
  std::map<uint32_t, ChannelState> channels_;
  uint32_t next_channel_id_ = 1;
  std::map<ClientId, ClientState> clients_;
  std::deque<ClientMessageToPublish> inbox_;
  BridgeCounts counts_;
  std::set<std::string> refused_reasons_;
};

}  // namespace mocap::foxglove
