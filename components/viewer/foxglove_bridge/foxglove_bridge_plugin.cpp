// foxglove_bridge: the graph's topics over the Foxglove WebSocket protocol, for Foxglove,
// Lichtblick and any client of the protocol (foxglove_protocol.hpp). Every topic the launch
// file's components declare is advertised with encoding "cdr" and its "ros2idl" schema from
// idl/; a client's subscription receives the CDR as it travels on DDS. A client that reads
// slowly loses its oldest messages (client_queue.hpp) and is disconnected if it stays behind:
// the graph never waits for a viewer.
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <mocap/component.hpp>

#include "client_queue.hpp"
#include "foxglove_protocol.hpp"
#include "viewer_assets.hpp"
#include "websocket_server.hpp"

namespace mocap::foxglove {
namespace {

// Frames handed to the socket while this many bytes are still unsent: enough to keep the link
// busy, little enough that the client queue, which drops oldest first, holds the backlog.
constexpr size_t kInFlightBytes = 1 << 20;
constexpr const char* kImageType = "sensor_msgs/msg/Image";

uint64_t nanoseconds(Clock::time_point time) {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count());
}

class FoxgloveBridge final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Serves the graph's topics over the Foxglove WebSocket protocol (ws://ADDRESS:PORT, "
        "subprotocol foxglove.websocket.v1) to Foxglove, Lichtblick or any client of the "
        "protocol: CDR payloads with ros2idl schemas. Slow clients lose their oldest messages, "
        "never slow the graph.");
    spec.parameter("address", std::string("0.0.0.0"), "the address to listen on");
    spec.parameter("port", int64_t{8765}, "the TCP port (0: any free port, logged)")
        .range(0, 65535);
    spec.parameter("topics", std::string(".*"),
                   "regular expression (ECMAScript, whole name) of the topics to offer");
    spec.parameter("max_image_rate_hz", 10.0,
                   "most sensor_msgs/msg/Image messages a second per client and topic (0: all)")
        .range(0.0, 1000.0);
    spec.parameter("send_buffer_limit_bytes", int64_t{10'000'000},
                   "bytes a client may have queued; beyond, its oldest messages are dropped, "
                   "and after 5 s of dropping it is disconnected")
        .range(1'000'000, 1'000'000'000);
    spec.subscribes_any("the offered topics, with their declared types");
  }

  explicit FoxgloveBridge(Context& context) : Component(context) {
    const std::string pattern = param<std::string>("topics");
    std::regex allowed;
    try {
      allowed = std::regex(pattern, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      throw std::invalid_argument("topics: '" + pattern +
                                  "' is not a regular expression: " + e.what());
    }
    const double image_rate = param<double>("max_image_rate_hz");
    if (image_rate > 0) {
      image_period_ = std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / image_rate));
    }
    queue_options_.limit_bytes = static_cast<size_t>(param<int64_t>("send_buffer_limit_bytes"));

    for (const KnownTopic& topic : context.known_topics()) {
      if (topic.type == nullptr || topic.topic.find('{') != std::string::npos) continue;
      if (!std::regex_match(topic.topic, allowed)) continue;
      Channel channel{static_cast<uint32_t>(channels_.size() + 1),
                      topic.topic,
                      "cdr",
                      topic.type->name(),
                      ros2idl_schema(topic.type->name(), full_definition(*topic.type)),
                      "ros2idl"};
      channels_.emplace(channel.id, ChannelState{channel, topic.type});
    }
    for (auto& [id, state] : channels_) {
      context.subscribe_any(
          state.channel.topic, *state.type, Qos::sensor_data(),
          [this, id = id](const std::shared_ptr<const void>& message) { forward(id, message); });
    }

    WebSocketServerOptions options;
    options.address = param<std::string>("address");
    options.port = static_cast<uint16_t>(param<int64_t>("port"));
    options.subprotocols = {std::string(kSubprotocol), std::string(kSdkSubprotocol)};
    WebSocketHandlers handlers;
    handlers.on_open = [this](ClientId client, const std::string&) { opened(client); };
    handlers.on_text = [this](ClientId client, const std::string& text) { received(client, text); };
    handlers.on_binary = [this](ClientId client, const std::string&) {
      refuse(client, "client publishing is not offered by this server");
    };
    handlers.on_close = [this](ClientId client) { closed(client); };
    handlers.on_http = [](const std::string& resource) { return serve(resource); };
    try {
      server_ = std::make_unique<WebSocketServer>(options, handlers);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(std::string("address/port: ") + e.what());
    }
    create_timer(std::chrono::milliseconds(20), [this] { pump_all(); });
    log().info(
        "Foxglove WebSocket server on ws://{0}:{1} offering {2} topic(s); the viewer: "
        "http://{0}:{1}/",
        options.address, server_->port(), channels_.size());
  }

  ~FoxgloveBridge() override {
    server_.reset();  // joins the server's thread: no handler runs after this
    log().info("foxglove bridge: {} client(s) served, {} message(s) sent, {} dropped",
               clients_served_, sent_, dropped_);
  }

 private:
  struct ChannelState {
    Channel channel;
    const MessageType* type;
  };
  struct ClientState {
    explicit ClientState(ClientQueueOptions options) : queue(options) {}
    ClientQueue queue;
    std::map<uint32_t, uint32_t> subscription_of_channel;  // channel id -> subscription id
    std::map<uint32_t, Clock::time_point> last_image;      // channel id -> last image sent
  };

  // The built-in viewer's files; "/" is its page.
  static HttpResponse serve(const std::string& resource) {
    std::string path = resource.substr(0, resource.find_first_of("?#"));
    if (path == "/") path = "/index.html";
    for (const ViewerAsset& asset : viewer_assets()) {
      if (asset.path == path) {
        return {200, std::string(asset.content_type), std::string(asset.body)};
      }
    }
    return {};
  }

  void opened(ClientId client) {
    std::string session = std::to_string(getpid());
    server_->send_text(client,
                       server_info("mocap-graph", {}, {}, {{"graph", context().name()}}, session));
    std::vector<Channel> list;
    for (const auto& [id, state] : channels_) list.push_back(state.channel);
    server_->send_text(client, advertise(list));
    std::lock_guard lock(mutex_);
    clients_.emplace(client, ClientState(queue_options_));
    ++clients_served_;
  }

  void closed(ClientId client) {
    std::lock_guard lock(mutex_);
    auto found = clients_.find(client);
    if (found == clients_.end()) return;
    dropped_ += found->second.queue.dropped();
    clients_.erase(found);
  }

  void refuse(ClientId client, const std::string& reason) {
    log().warn("foxglove client {}: {}; closing its connection", client, reason);
    server_->close(client, reason);
  }

  void received(ClientId client, const std::string& text) {
    std::optional<ClientRequest> request;
    try {
      request = parse_client_text(text);
    } catch (const ProtocolError& e) {
      refuse(client, e.what());
      return;
    }
    if (!request) return;
    if (auto* subscribe = std::get_if<Subscribe>(&*request)) {
      std::lock_guard lock(mutex_);
      auto state = clients_.find(client);
      if (state == clients_.end()) return;
      for (const Subscription& s : subscribe->subscriptions) {
        if (!channels_.contains(s.channel_id)) {
          server_->send_text(
              client, status(StatusLevel::Error, "no channel " + std::to_string(s.channel_id)));
          continue;
        }
        state->second.subscription_of_channel[s.channel_id] = s.id;
      }
    } else if (auto* unsubscribe = std::get_if<Unsubscribe>(&*request)) {
      std::lock_guard lock(mutex_);
      auto state = clients_.find(client);
      if (state == clients_.end()) return;
      std::set<uint32_t> ids(unsubscribe->subscription_ids.begin(),
                             unsubscribe->subscription_ids.end());
      std::erase_if(state->second.subscription_of_channel,
                    [&](const auto& entry) { return ids.contains(entry.second); });
    } else {
      refuse(client, "client publishing is not offered by this server");
    }
  }

  // A message of channel `id`: serialized once if any client wants it, then queued for each.
  void forward(uint32_t id, const std::shared_ptr<const void>& message) {
    const Clock::time_point received = now();
    std::lock_guard lock(mutex_);
    const ChannelState& channel = channels_.at(id);
    const bool image = channel.channel.schema_name == kImageType;
    std::string frame;
    for (auto& [client, state] : clients_) {
      auto subscription = state.subscription_of_channel.find(id);
      if (subscription == state.subscription_of_channel.end()) continue;
      if (image && image_period_.count() > 0) {
        auto last = state.last_image.find(id);
        // A camera at exactly the limit still gets through: frames come with some jitter.
        const Clock::duration tolerance =
            std::min<Clock::duration>(image_period_ / 4, std::chrono::milliseconds(5));
        if (last != state.last_image.end() && received - last->second < image_period_ - tolerance) {
          continue;
        }
        state.last_image[id] = received;
      }
      if (frame.empty()) {
        const size_t size = channel.type->serialized_size(message.get());
        frame.resize(kMessageDataHeaderSize + size);
        channel.type->serialize(
            message.get(),
            std::span<uint8_t>(reinterpret_cast<uint8_t*>(frame.data()) + kMessageDataHeaderSize,
                               size));
      }
      std::string copy = frame;
      write_message_data_header(
          subscription->second, nanoseconds(received),
          std::span<uint8_t, kMessageDataHeaderSize>(reinterpret_cast<uint8_t*>(copy.data()),
                                                     kMessageDataHeaderSize));
      state.queue.push(std::move(copy), std::chrono::steady_clock::now());
      pump(client, state);
    }
  }

  // Hands queued frames to the socket while little is in flight. Requires mutex_.
  void pump(ClientId client, ClientState& state) {
    while (state.queue.frames() > 0 && server_->buffered_bytes(client) < kInFlightBytes) {
      std::string frame = *state.queue.pop();
      if (server_->send_binary(client, frame.data(), frame.size())) ++sent_;
    }
  }

  void pump_all() {
    std::vector<std::pair<ClientId, uint64_t>> too_slow;  // and the messages it lost
    {
      std::lock_guard lock(mutex_);
      for (auto it = clients_.begin(); it != clients_.end();) {
        pump(it->first, it->second);
        if (it->second.queue.should_disconnect(std::chrono::steady_clock::now())) {
          // Forgotten at once: nothing more is queued for it while its connection closes.
          too_slow.emplace_back(it->first, it->second.queue.dropped());
          dropped_ += it->second.queue.dropped();
          it = clients_.erase(it);
        } else {
          ++it;
        }
      }
    }
    for (auto [client, lost] : too_slow) {
      refuse(client, fmt::format("too slow: behind for 5 s, {} message(s) dropped "
                                 "(send_buffer_limit_bytes)",
                                 lost));
    }
  }

  std::map<uint32_t, ChannelState> channels_;  // fixed after construction
  Clock::duration image_period_{};
  ClientQueueOptions queue_options_;
  std::mutex mutex_;
  std::map<ClientId, ClientState> clients_;
  uint64_t clients_served_ = 0;
  uint64_t sent_ = 0;
  uint64_t dropped_ = 0;
  std::unique_ptr<WebSocketServer> server_;  // last: stopped first
};

}  // namespace
}  // namespace mocap::foxglove

MOCAP_REGISTER_COMPONENT(mocap::foxglove::FoxgloveBridge, "foxglove_bridge")
