// foxglove_bridge: the graph's topics over the Foxglove WebSocket protocol, for Foxglove,
// Lichtblick and any client of the protocol (foxglove_protocol.hpp). Every topic the launch
// file's components declare, and every topic other processes on the DDS domain publish with
// a type this process knows, is advertised with encoding "cdr" and its "ros2idl" schema from
// idl/; topics that come and go are advertised and unadvertised while clients are connected.
// A client's subscription receives the CDR as it travels on DDS. A client that reads slowly
// loses its oldest messages (client_queue.hpp) and is disconnected if it stays behind: the
// graph never waits for a viewer. With client_publish, clients publish on allowed topics.
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <mocap/component.hpp>

#include "viewer/foxglove_bridge/client_queue.hpp"
#include "viewer/foxglove_bridge/foxglove_protocol.hpp"
#include "viewer/foxglove_bridge/websocket_server.hpp"
#include "viewer/web/viewer_assets.hpp"

namespace mocap::foxglove {
namespace {

// Frames handed to the socket while this many bytes are still unsent: enough to keep the link
// busy, little enough that the client queue, which drops oldest first, holds the backlog.
constexpr size_t kInFlightBytes = 1 << 20;
constexpr const char* kImageType = "sensor_msgs/msg/Image";
// Best effort, never waited for; deep enough for the bursts of many-camera topics while the
// bridge's strand is busy serializing an image.
const Qos kForwardQos{Reliability::BestEffort, Durability::Volatile, History::KeepLast, 100};
// How often the bridge looks for topics that appeared or disappeared on the domain.
constexpr std::chrono::seconds kDiscoveryPeriod{1};
// Client-published messages waiting for the bridge's next turn; beyond, the oldest go.
constexpr size_t kInboxLimit = 1000;
// Distinct reasons for refusing a request that are logged; the rest are counted.
constexpr size_t kRefusalsLogged = 20;

uint64_t nanoseconds(Clock::time_point time) {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count());
}

// The server's and the client queues' options with what only the plugin reads.
struct Settings {
  WebSocketServerOptions server;
  ClientQueueOptions queue;
  std::string topics = ".*";  // a regular expression
  double max_image_rate_hz = 10;
  bool client_publish = false;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("address",
             "the address to listen on: this machine only by default; 0.0.0.0 (or one "
             "interface's address) serves the network",
             &Settings::server, &WebSocketServerOptions::address)
        .add("token",
             "when set, WebSocket clients must present it (Authorization: Bearer TOKEN, or "
             "?token=TOKEN in the URL, as the viewer page passes on its own) or are refused "
             "with HTTP 401",
             &Settings::server, &WebSocketServerOptions::token)
        .add("certificate_file",
             "with key_file: serve TLS (wss://, https://) with this PEM certificate chain",
             &Settings::server, &WebSocketServerOptions::certificate_file)
        .add("key_file", "the PEM private key of certificate_file", &Settings::server,
             &WebSocketServerOptions::key_file)
        .add("allowed_origins",
             "WebSocket clients are taken when their Origin header is absent (programs), is "
             "this bridge's own page, or is listed here exactly as the browser sends it: "
             "https://app.foxglove.dev (Foxglove's web app), file:// (Foxglove's and "
             "Lichtblick's desktop apps), a self-hosted Lichtblick's own, e.g. "
             "http://localhost:8080; 'null' (a file opened in a browser) only when listed",
             &Settings::server, &WebSocketServerOptions::allowed_origins)
        .add("allowed_hosts",
             "names the bridge answers to beyond localhost, its addresses and this machine's "
             "host name (a DNS name of the machine, a proxy's): any other Host header is "
             "refused, so that a page whose name was made to point here cannot read it",
             &Settings::server, &WebSocketServerOptions::allowed_hosts)
        .add("port", "the TCP port (0: any free port, logged)", &Settings::server,
             &WebSocketServerOptions::port)
        .range(0, 65535)
        .add("topics", "regular expression (ECMAScript, whole name) of the topics to offer",
             &Settings::topics)
        .add("max_image_rate_hz",
             "most sensor_msgs/msg/Image messages a second per client and topic (0: all)",
             &Settings::max_image_rate_hz)
        .range(0.0, 1000.0)
        .add("send_buffer_limit_bytes",
             "bytes a client may have queued; beyond, its oldest messages are dropped, "
             "and after 5 s of dropping it is disconnected",
             &Settings::queue, &ClientQueueOptions::limit_bytes)
        .range(1'000'000, 1'000'000'000)
        .add("client_publish",
             "let clients publish (Foxglove's clientPublish) on topics that `topics` "
             "allows, in CDR of a type this process knows",
             &Settings::client_publish);

class FoxgloveBridge final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Serves the graph's topics over the Foxglove WebSocket protocol (ws://ADDRESS:PORT, "
        "subprotocol foxglove.websocket.v1) to Foxglove, Lichtblick or any client of the "
        "protocol: CDR payloads with ros2idl schemas. Slow clients lose their oldest messages, "
        "never slow the graph.");
    kParameters.declare(spec);
    spec.subscribes_any("the offered topics, with their declared or discovered types");
    spec.publishes_any("what clients publish, when client_publish is on");
  }

  explicit FoxgloveBridge(Context& context) : Component(context) {
    const std::string pattern = settings_.topics;
    try {
      allowed_ = std::regex(pattern, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      throw std::invalid_argument("topics: '" + pattern +
                                  "' is not a regular expression: " + e.what());
    }
    const double image_rate = settings_.max_image_rate_hz;
    if (image_rate > 0) {
      image_period_ = std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / image_rate));
    }
    const std::vector<KnownTopic> declared = context.known_topics();
    for (const KnownTopic& topic : declared) {
      if (offered(topic)) declared_.insert(topic.topic);
    }
    update_topics(declared);

    WebSocketServerOptions options = settings_.server;
    options.subprotocols = {std::string(kSubprotocol), std::string(kSdkSubprotocol)};
    WebSocketHandlers handlers;
    handlers.on_open = [this](ClientId client, const std::string&) { opened(client); };
    handlers.on_text = [this](ClientId client, const std::string& text) { received(client, text); };
    handlers.on_binary = [this](ClientId client, const std::string& frame) {
      received_binary(client, frame);
    };
    handlers.on_close = [this](ClientId client, const std::string& protocol_error) {
      if (!protocol_error.empty()) {
        log().warn("foxglove client {}: closed for a broken frame: {}", client, protocol_error);
      }
      closed(client);
    };
    handlers.on_http = [](const std::string& resource) { return serve(resource); };
    handlers.on_refused = [this](const std::string& why) { refused(why); };
    try {
      server_ = std::make_unique<WebSocketServer>(options, handlers);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(e.what());  // names the parameter at fault
    }
    create_timer(std::chrono::milliseconds(20), [this] {
      unsubscribe_unwatched();
      subscribe_first_asked();
      pump_all();
      publish_inbox();
    });
    create_timer(kDiscoveryPeriod, [this] {
      std::vector<KnownTopic> present = this->context().discovered_topics();
      for (const std::string& name : declared_) present.push_back({name, nullptr, {}});
      update_topics(present);
    });
    const bool tls = !options.certificate_file.empty();
    const std::string served = fmt::format(
        "Foxglove WebSocket server on {0}://{1}:{2} offering {3} topic(s){4}{5}; the viewer: "
        "{6}://{1}:{2}/",
        tls ? "wss" : "ws", options.address, server_->port(), channels_.size(),
        settings_.client_publish ? ", clients may publish" : "",
        options.token.empty() ? "" : ", token required", tls ? "https" : "http");
    if (server_->loopback_only()) {
      log().info("{} (this machine only)", served);
    } else {
      log().warn("{}. Open to the network: any host that reaches port {} may connect{}{}", served,
                 server_->port(), options.token.empty() ? ", no token asked (see token)" : "",
                 tls ? "" : ", unencrypted (see certificate_file)");
    }
  }

  ~FoxgloveBridge() override {
    server_.reset();  // joins the server's thread: no handler runs after this
    log().info(
        "foxglove bridge: {} client(s) served, {} message(s) sent, {} dropped; {} received "
        "from clients, {} dropped; {} request(s) refused for their Host or Origin",
        clients_served_, sent_, dropped_, client_messages_, client_messages_dropped_,
        refused_requests_);
  }

 private:
  // A topic the bridge offers; advertised while it has a channel. Images are subscribed to
  // when a client first asks for them, and let go of when the last client that asked stops
  // watching: a volume's cameras would otherwise stream every frame of every camera to the
  // bridge's host with nobody watching. The rest at once, so that a latched topic's last
  // message is there for the first client.
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
  struct ClientState {
    explicit ClientState(ClientQueueOptions options) : queue(options) {}
    ClientQueue queue;
    std::map<uint32_t, uint32_t> subscription_of_channel;  // channel id -> subscription id
    std::map<uint32_t, Clock::time_point> last_image;      // channel id -> last image sent
    std::map<uint32_t, ClientChannelState> published;      // client channel id -> topic
  };
  struct ClientMessageToPublish {
    std::string topic;
    const MessageType* type;
    std::shared_ptr<void> message;
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

  // On the server's thread. Each reason is logged once (a page may retry without end).
  void refused(const std::string& why) {
    std::lock_guard lock(refused_mutex_);
    ++refused_requests_;
    if (refused_reasons_.size() < kRefusalsLogged && refused_reasons_.insert(why).second) {
      log().warn("refused a request: {}", why);
    }
  }

  bool offered(const KnownTopic& topic) const {
    return topic.type != nullptr && topic.topic.find('{') == std::string::npos &&
           std::regex_match(topic.topic, allowed_);
  }

  // Subscribes to topics seen for the first time, advertises those present and not
  // advertised, unadvertises those advertised and gone. `present` holds the declared topics
  // (their type may be left out once subscribed) and the discovered ones.
  void update_topics(const std::vector<KnownTopic>& present) {
    std::set<std::string> names;
    std::vector<std::pair<std::string, TopicState>> new_topics;
    {
      std::lock_guard lock(mutex_);
      for (const KnownTopic& topic : present) {
        names.insert(topic.topic);
        if (topic.type == nullptr || !offered(topic)) continue;
        // Latched when every publisher keeps its last sample: then so does the bridge.
        const bool latched =
            !topic.publishers.empty() &&
            std::all_of(topic.publishers.begin(), topic.publishers.end(), [](const Qos& qos) {
              return qos.durability == Durability::TransientLocal;
            });
        auto [known, added] = topics_.emplace(topic.topic, TopicState{topic.type, latched, 0});
        if (added && topic.type->name() != kImageType) {
          known->second.subscribed = true;
          new_topics.emplace_back(topic.topic, known->second);
        } else if (known->second.type != topic.type && warned_types_.insert(topic.topic).second) {
          log().warn("{} is published as {} and as {}; offered as {}", topic.topic,
                     known->second.type->name(), topic.type->name(), known->second.type->name());
        }
      }
    }
    for (const auto& [name, topic] : new_topics) subscribe(name, topic);
    std::vector<Channel> appeared;
    std::vector<uint32_t> gone;
    std::lock_guard lock(mutex_);
    for (auto& [name, topic] : topics_) {
      const bool is_present = names.contains(name);
      if (is_present && topic.channel_id == 0) {
        topic.channel_id = next_channel_id_++;
        Channel channel{topic.channel_id,
                        name,
                        "cdr",
                        topic.type->name(),
                        ros2idl_schema(topic.type->name(), full_definition(*topic.type)),
                        "ros2idl"};
        channels_.emplace(channel.id, ChannelState{channel, topic.type, topic.latched, {}});
        appeared.push_back(std::move(channel));
      } else if (!is_present && topic.channel_id != 0) {
        gone.push_back(topic.channel_id);
        channels_.erase(topic.channel_id);
        for (auto& [client, state] : clients_) {
          state.subscription_of_channel.erase(topic.channel_id);
          state.last_image.erase(topic.channel_id);
        }
        topic.channel_id = 0;
      }
    }
    if (appeared.empty() && gone.empty()) return;
    if (server_) {
      for (const Channel& channel : appeared) log().info("offers {} now", channel.topic);
      if (!gone.empty()) log().info("{} topic(s) gone", gone.size());
    }
    for (const auto& [client, state] : clients_) {
      if (!gone.empty()) server_->send_text(client, unadvertise(gone));
      if (!appeared.empty()) server_->send_text(client, advertise(appeared));
    }
  }

  // Images whose last watching client unsubscribed or left (`unwatched_`): let go of, unless a
  // client asked for them again since.
  void unsubscribe_unwatched() {
    std::vector<std::string> names;
    {
      std::lock_guard lock(mutex_);
      for (const std::string& name : unwatched_) {
        TopicState& topic = topics_.at(name);
        if (!topic.subscribed || first_asked_.contains(name) || watched(topic.channel_id)) {
          continue;
        }
        topic.subscribed = false;
        names.push_back(name);
      }
      unwatched_.clear();
    }
    for (const std::string& name : names) {
      context().unsubscribe_any(name);
      log().info("lets go of {}: no client watches it", name);
    }
  }

  // Requires mutex_.
  bool watched(uint32_t channel_id) const {
    return channel_id != 0 && std::any_of(clients_.begin(), clients_.end(), [&](const auto& c) {
             return c.second.subscription_of_channel.contains(channel_id);
           });
  }

  // Requires mutex_. The images among `channels` that nobody watches now, for the timer.
  void note_unwatched(const std::vector<uint32_t>& channels) {
    for (uint32_t id : channels) {
      auto channel = channels_.find(id);
      if (channel == channels_.end() || channel->second.type->name() != kImageType) continue;
      if (!watched(id)) unwatched_.insert(channel->second.channel.topic);
    }
  }

  void subscribe_first_asked() {
    std::vector<std::pair<std::string, TopicState>> asked;
    {
      std::lock_guard lock(mutex_);
      for (const std::string& name : first_asked_) {
        TopicState& topic = topics_.at(name);
        if (topic.subscribed) continue;
        topic.subscribed = true;
        asked.emplace_back(name, topic);
      }
      first_asked_.clear();
    }
    for (const auto& [name, topic] : asked) subscribe(name, topic);
  }

  void subscribe(const std::string& name, const TopicState& topic) {
    context().subscribe_any(
        name, *topic.type, topic.latched ? Qos::latched() : kForwardQos,
        [this, name](const std::shared_ptr<const void>& message) { forward(name, message); });
  }

  void opened(ClientId client) {
    std::string session = std::to_string(getpid());
    std::vector<std::string> capabilities;
    if (settings_.client_publish) capabilities.push_back("clientPublish");
    std::lock_guard lock(mutex_);
    server_->send_text(client, server_info("mocap-graph", capabilities, {"cdr"},
                                           {{"graph", context().name()}}, session));
    std::vector<Channel> list;
    for (const auto& [id, state] : channels_) list.push_back(state.channel);
    server_->send_text(client, advertise(list));
    clients_.emplace(client, ClientState(settings_.queue));
    ++clients_served_;
  }

  void closed(ClientId client) {
    std::lock_guard lock(mutex_);
    auto found = clients_.find(client);
    if (found == clients_.end()) return;
    dropped_ += found->second.queue.dropped();
    std::vector<uint32_t> channels;
    for (const auto& [channel, subscription] : found->second.subscription_of_channel) {
      channels.push_back(channel);
    }
    clients_.erase(found);
    note_unwatched(channels);
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
    if (auto* subscription = std::get_if<Subscribe>(&*request)) {
      std::lock_guard lock(mutex_);
      auto state = clients_.find(client);
      if (state == clients_.end()) return;
      for (const Subscription& s : subscription->subscriptions) {
        if (!channels_.contains(s.channel_id)) {
          server_->send_text(
              client, status(StatusLevel::Error, "no channel " + std::to_string(s.channel_id)));
          continue;
        }
        state->second.subscription_of_channel[s.channel_id] = s.id;
        const ChannelState& channel = channels_.at(s.channel_id);
        if (!channel.last_frame.empty()) queue_frame(state->second, channel.last_frame, s.id);
        // Subscribed by the timer: this is the server's thread, not the component's.
        if (!topics_.at(channel.channel.topic).subscribed) {
          first_asked_.insert(channel.channel.topic);
        }
      }
      pump(client, state->second);
    } else if (auto* unsubscribe = std::get_if<Unsubscribe>(&*request)) {
      std::lock_guard lock(mutex_);
      auto state = clients_.find(client);
      if (state == clients_.end()) return;
      std::set<uint32_t> ids(unsubscribe->subscription_ids.begin(),
                             unsubscribe->subscription_ids.end());
      std::vector<uint32_t> channels;
      std::erase_if(state->second.subscription_of_channel, [&](const auto& entry) {
        if (!ids.contains(entry.second)) return false;
        channels.push_back(entry.first);
        return true;
      });
      note_unwatched(channels);
    } else if (!settings_.client_publish) {
      refuse(client, "client publishing is off (client_publish: false)");
    } else if (auto* advertised = std::get_if<ClientAdvertise>(&*request)) {
      client_advertised(client, *advertised);
    } else if (auto* unadvertised = std::get_if<ClientUnadvertise>(&*request)) {
      std::lock_guard lock(mutex_);
      auto state = clients_.find(client);
      if (state == clients_.end()) return;
      for (uint32_t id : unadvertised->channel_ids) state->second.published.erase(id);
    }
  }

  // A client's channels to publish on: accepted when the topic is offered (`topics`), the
  // encoding is CDR and the type is one this process knows; each refused one gets a status.
  void client_advertised(ClientId client, const ClientAdvertise& advertised) {
    std::lock_guard lock(mutex_);
    auto state = clients_.find(client);
    if (state == clients_.end()) return;
    for (const ClientChannel& channel : advertised.channels) {
      const MessageType* type = find_message_type(channel.schema_name);
      std::string refusal;
      if (!valid_topic(channel.topic) || !std::regex_match(channel.topic, allowed_)) {
        refusal = "topic '" + channel.topic + "' is not offered (topics)";
      } else if (channel.encoding != "cdr") {
        refusal = "encoding '" + channel.encoding + "' of " + channel.topic + ": only cdr";
      } else if (type == nullptr) {
        refusal = "type '" + channel.schema_name + "' of " + channel.topic + " is unknown here";
      } else if (auto topic = topics_.find(channel.topic);
                 topic != topics_.end() && topic->second.type != type) {
        refusal = channel.topic + " has type " + topic->second.type->name() + ", not " +
                  channel.schema_name;
      }
      if (!refusal.empty()) {
        log().warn("foxglove client {}: cannot publish: {}", client, refusal);
        server_->send_text(client, status(StatusLevel::Error, "cannot publish: " + refusal));
        continue;
      }
      state->second.published[channel.id] = {channel.topic, type};
      log().info("foxglove client {} publishes {} ({})", client, channel.topic, type->name());
    }
  }

  static bool valid_topic(const std::string& topic) {
    static const std::regex name("(/[A-Za-z_][A-Za-z0-9_]*)+");
    return std::regex_match(topic, name);
  }

  // A client's Message Data: decoded here, so that a malformed payload closes that client,
  // and published on the bridge's next turn.
  void received_binary(ClientId client, const std::string& frame) {
    if (!settings_.client_publish) {
      refuse(client, "client publishing is off (client_publish: false)");
      return;
    }
    ClientMessage message;
    try {
      message = parse_client_binary(
          std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(frame.data()), frame.size()));
    } catch (const ProtocolError& e) {
      refuse(client, e.what());
      return;
    }
    std::string refusal;
    {
      std::lock_guard lock(mutex_);
      auto state = clients_.find(client);
      if (state == clients_.end()) return;
      auto channel = state->second.published.find(message.channel_id);
      if (channel == state->second.published.end()) {
        refusal = fmt::format("message on channel {}, which this client has not advertised",
                              message.channel_id);
      } else {
        const MessageType& type = *channel->second.type;
        std::shared_ptr<void> decoded = type.create();
        try {
          type.deserialize(message.payload, decoded.get());
          inbox_.push_back({channel->second.topic, &type, std::move(decoded)});
          ++client_messages_;
          if (inbox_.size() > kInboxLimit) {
            inbox_.pop_front();
            ++client_messages_dropped_;
          }
        } catch (const SerializationError& e) {
          refusal = fmt::format("message on {} is not CDR of {}: {}", channel->second.topic,
                                type.name(), e.what());
        }
      }
    }
    if (!refusal.empty()) refuse(client, refusal);
  }

  // Publishes what clients sent, on this component's strand like every other publication.
  void publish_inbox() {
    std::deque<ClientMessageToPublish> inbox;
    {
      std::lock_guard lock(mutex_);
      inbox.swap(inbox_);
    }
    for (ClientMessageToPublish& message : inbox) {
      auto publisher = publishers_.find(message.topic);
      if (publisher == publishers_.end()) {
        // Reliable, volatile, keep last: matches every subscriber and never waits.
        Qos qos = Qos::sensor_data();
        qos.reliability = Reliability::Reliable;
        publisher =
            publishers_
                .emplace(message.topic, context().advertise_any(message.topic, *message.type, qos))
                .first;
      }
      publisher->second->publish(std::move(message.message));
    }
  }

  // A message of `topic`: serialized once if any client wants it, then queued for each.
  void forward(const std::string& topic, const std::shared_ptr<const void>& message) {
    const Clock::time_point received = now();
    std::lock_guard lock(mutex_);
    const uint32_t id = topics_.at(topic).channel_id;
    if (id == 0) return;  // unadvertised
    ChannelState& channel = channels_.at(id);
    const bool image = channel.channel.schema_name == kImageType;
    std::string frame;
    if (channel.latched)
      channel.last_frame = frame = message_data(channel, message.get(), received);
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
      if (frame.empty()) frame = message_data(channel, message.get(), received);
      queue_frame(state, frame, subscription->second);
      pump(client, state);
    }
  }

  // A Message Data frame of `message`, its subscription id left for queue_frame to write.
  static std::string message_data(const ChannelState& channel, const void* message,
                                  Clock::time_point received) {
    const size_t size = channel.type->serialized_size(message);
    std::string frame(kMessageDataHeaderSize + size, '\0');
    channel.type->serialize(
        message, std::span<uint8_t>(
                     reinterpret_cast<uint8_t*>(frame.data()) + kMessageDataHeaderSize, size));
    write_message_data_header(
        0, nanoseconds(received),
        std::span<uint8_t, kMessageDataHeaderSize>(reinterpret_cast<uint8_t*>(frame.data()),
                                                   kMessageDataHeaderSize));
    return frame;
  }

  // A copy of `frame` for one client's subscription. Requires mutex_.
  static void queue_frame(ClientState& state, const std::string& frame, uint32_t subscription) {
    std::string copy = frame;
    set_message_data_subscription(
        subscription, std::span<uint8_t, kMessageDataHeaderSize>(
                          reinterpret_cast<uint8_t*>(copy.data()), kMessageDataHeaderSize));
    state.queue.push(std::move(copy), std::chrono::steady_clock::now());
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

  std::regex allowed_;
  std::set<std::string> declared_;      // offered topics of the launch file: always present
  std::set<std::string> warned_types_;  // topics published with two types, warned about once
  Clock::duration image_period_{};
  std::map<std::string, std::shared_ptr<PublisherPort>> publishers_;  // for clients, by topic
  std::mutex mutex_;                                                  // guards what follows
  std::map<std::string, TopicState> topics_;
  std::set<std::string> first_asked_;  // images a client asked for, not subscribed to yet
  std::set<std::string> unwatched_;    // images the last watching client stopped watching
  std::map<uint32_t, ChannelState> channels_;
  uint32_t next_channel_id_ = 1;
  std::map<ClientId, ClientState> clients_;
  std::deque<ClientMessageToPublish> inbox_;
  uint64_t clients_served_ = 0;
  uint64_t sent_ = 0;
  uint64_t dropped_ = 0;
  uint64_t client_messages_ = 0;
  uint64_t client_messages_dropped_ = 0;
  std::mutex refused_mutex_;  // guards what follows
  std::set<std::string> refused_reasons_;
  uint64_t refused_requests_ = 0;
  std::unique_ptr<WebSocketServer> server_;  // last: stopped first
};

}  // namespace
}  // namespace mocap::foxglove

MOCAP_REGISTER_COMPONENT(mocap::foxglove::FoxgloveBridge, "foxglove_bridge")
