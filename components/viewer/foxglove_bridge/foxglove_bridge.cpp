#include "viewer/foxglove_bridge/foxglove_bridge.hpp"

#include <algorithm>
#include <span>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace mocap::foxglove {
namespace {

// Frames handed to the socket while this many bytes are still unsent: enough to keep the link
// busy, little enough that the client queue, which drops oldest first, holds the backlog.
constexpr size_t kInFlightBytes = 1 << 20;
constexpr const char* kImageType = "sensor_msgs/msg/Image";
// Best effort, never waited for; deep enough for the bursts of many-camera topics while the
// bridge's strand is busy serializing an image.
const Qos kForwardQos{Reliability::BestEffort, Durability::Volatile, History::KeepLast, 100};
// Client-published messages waiting for the bridge's next turn; beyond, the oldest go.
constexpr size_t kInboxLimit = 1000;
// Distinct reasons for refusing a request that are logged; the rest are counted.
constexpr size_t kRefusalsLogged = 20;

uint64_t nanoseconds(Clock::time_point time) {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count());
}

bool valid_topic(const std::string& topic) {
  static const std::regex name("(/[A-Za-z_][A-Za-z0-9_]*)+");
  return std::regex_match(topic, name);
}

}  // namespace

std::optional<std::string> FoxgloveBridgeOptions::problem() const {
  try {
    std::regex(topics, std::regex::ECMAScript);
  } catch (const std::regex_error& e) {
    return fmt::format("topics: '{}' is not a regular expression: {}", topics, e.what());
  }
  if (!(max_image_rate_hz >= 0)) {
    return fmt::format("max_image_rate_hz: {} is not a rate (0: every image)", max_image_rate_hz);
  }
  if (!(max_rate_hz >= 0)) {
    return fmt::format("max_rate_hz: {} is not a rate (0: every message)", max_rate_hz);
  }
  if (auto problem = queue.problem()) return "queue." + *problem;
  return std::nullopt;
}

FoxgloveBridge::FoxgloveBridge(FoxgloveBridgeOptions options,
                               const std::vector<KnownTopic>& declared, std::string graph_name,
                               BridgeGraph& graph, ClientLinks& links, const Logger& log)
    : options_(std::move(options)),
      graph_name_(std::move(graph_name)),
      graph_(graph),
      links_(links),
      log_(log) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("FoxgloveBridgeOptions::" + *problem);
  }
  allowed_ = std::regex(options_.topics, std::regex::ECMAScript);
  if (options_.max_image_rate_hz > 0) {
    image_period_ = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(1.0 / options_.max_image_rate_hz));
  }
  rate_burst_ = std::max(1.0, options_.max_rate_hz);
  for (const KnownTopic& topic : declared) {
    if (offered(topic)) declared_.insert(topic.topic);
  }
  update(declared, false);
}

void FoxgloveBridge::update_topics(std::vector<KnownTopic> discovered) {
  for (const std::string& name : declared_) discovered.push_back({name, nullptr, {}});
  update(discovered, true);
}

void FoxgloveBridge::run_once() {
  unsubscribe_unwatched();
  subscribe_first_asked();
  pump_all();
  publish_inbox();
}

void FoxgloveBridge::refused(const std::string& why) {
  std::lock_guard lock(mutex_);
  ++counts_.refused_requests;
  if (refused_reasons_.size() < kRefusalsLogged && refused_reasons_.insert(why).second) {
    log_.warn("refused a request: {}", why);
  }
}

size_t FoxgloveBridge::channel_count() const {
  std::lock_guard lock(mutex_);
  return channels_.size();
}

BridgeCounts FoxgloveBridge::counts() const {
  std::lock_guard lock(mutex_);
  BridgeCounts counts = counts_;
  for (const auto& [client, state] : clients_) counts.dropped += state.queue.dropped();
  return counts;
}

bool FoxgloveBridge::offered(const KnownTopic& topic) const {
  return topic.type != nullptr && topic.topic.find('{') == std::string::npos &&
         std::regex_match(topic.topic, allowed_);
}

// Subscribes to topics seen for the first time, advertises those present and not
// advertised, unadvertises those advertised and gone. `present` holds the declared topics
// (their type may be left out once subscribed) and the discovered ones.
void FoxgloveBridge::update(const std::vector<KnownTopic>& present, bool announce) {
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
          std::all_of(topic.publishers.begin(), topic.publishers.end(),
                      [](const Qos& qos) { return qos.durability == Durability::TransientLocal; });
      auto [known, added] = topics_.emplace(topic.topic, TopicState{topic.type, latched, 0});
      // A latched topic's last message waits here for the clients to come; the others are
      // read only while a client watches them (subscribe_first_asked).
      if (added && latched) {
        known->second.subscribed = true;
        new_topics.emplace_back(topic.topic, known->second);
      } else if (known->second.type != topic.type && warned_types_.insert(topic.topic).second) {
        log_.warn("{} is published as {} and as {}; offered as {}", topic.topic,
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
        state.budget.erase(topic.channel_id);
      }
      topic.channel_id = 0;
    }
  }
  if (appeared.empty() && gone.empty()) return;
  if (announce) {
    for (const Channel& channel : appeared) log_.info("offers {} now", channel.topic);
    if (!gone.empty()) log_.info("{} topic(s) gone", gone.size());
  }
  for (const auto& [client, state] : clients_) {
    if (!gone.empty()) links_.send_text(client, unadvertise(gone));
    if (!appeared.empty()) links_.send_text(client, advertise(appeared));
  }
}

// Topics whose last watching client unsubscribed or left (`unwatched_`): let go of, unless a
// client asked for them again since.
void FoxgloveBridge::unsubscribe_unwatched() {
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
    graph_.unsubscribe(name);
    log_.info("lets go of {}: no client watches it", name);
  }
}

// Requires mutex_.
bool FoxgloveBridge::watched(uint32_t channel_id) const {
  return channel_id != 0 && std::any_of(clients_.begin(), clients_.end(), [&](const auto& c) {
           return c.second.subscription_of_channel.contains(channel_id);
         });
}

// Requires mutex_. The topics among `channels`, latched ones aside, that nobody watches now,
// for the timer.
void FoxgloveBridge::note_unwatched(const std::vector<uint32_t>& channels) {
  for (uint32_t id : channels) {
    auto channel = channels_.find(id);
    if (channel == channels_.end() || channel->second.latched) continue;
    if (!watched(id)) unwatched_.insert(channel->second.channel.topic);
  }
}

void FoxgloveBridge::subscribe_first_asked() {
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

void FoxgloveBridge::subscribe(const std::string& name, const TopicState& topic) {
  graph_.subscribe(name, *topic.type, topic.latched ? Qos::latched() : kForwardQos);
}

void FoxgloveBridge::opened(ClientId client) {
  std::string session = std::to_string(getpid());
  std::vector<std::string> capabilities;
  if (options_.client_publish) capabilities.push_back("clientPublish");
  std::lock_guard lock(mutex_);
  links_.send_text(
      client, server_info("mocap-graph", capabilities, {"cdr"}, {{"graph", graph_name_}}, session));
  std::vector<Channel> list;
  for (const auto& [id, state] : channels_) list.push_back(state.channel);
  links_.send_text(client, advertise(list));
  clients_.emplace(client, ClientState(options_.queue));
  ++counts_.clients_served;
}

void FoxgloveBridge::closed(ClientId client) {
  std::lock_guard lock(mutex_);
  auto found = clients_.find(client);
  if (found == clients_.end()) return;
  counts_.dropped += found->second.queue.dropped();
  std::vector<uint32_t> channels;
  for (const auto& [channel, subscription] : found->second.subscription_of_channel) {
    channels.push_back(channel);
  }
  clients_.erase(found);
  note_unwatched(channels);
}

void FoxgloveBridge::refuse(ClientId client, const std::string& reason) {
  log_.warn("foxglove client {}: {}; closing its connection", client, reason);
  links_.close(client, reason);
}

void FoxgloveBridge::received(ClientId client, const std::string& text) {
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
        links_.send_text(client,
                         status(StatusLevel::Error, "no channel " + std::to_string(s.channel_id)));
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
  } else if (!options_.client_publish) {
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
void FoxgloveBridge::client_advertised(ClientId client, const ClientAdvertise& advertised) {
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
      log_.warn("foxglove client {}: cannot publish: {}", client, refusal);
      links_.send_text(client, status(StatusLevel::Error, "cannot publish: " + refusal));
      continue;
    }
    state->second.published[channel.id] = {channel.topic, type};
    log_.info("foxglove client {} publishes {} ({})", client, channel.topic, type->name());
  }
}

// A client's Message Data: decoded here, so that a malformed payload closes that client,
// and published on the bridge's next turn.
void FoxgloveBridge::received_binary(ClientId client, const std::string& frame) {
  if (!options_.client_publish) {
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
        ++counts_.client_messages;
        if (inbox_.size() > kInboxLimit) {
          inbox_.pop_front();
          ++counts_.client_messages_dropped;
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
void FoxgloveBridge::publish_inbox() {
  std::deque<ClientMessageToPublish> inbox;
  {
    std::lock_guard lock(mutex_);
    inbox.swap(inbox_);
  }
  for (ClientMessageToPublish& message : inbox) {
    graph_.publish(message.topic, *message.type, std::move(message.message));
  }
}

// A message of `topic`: serialized once if any client wants it, then queued for each.
void FoxgloveBridge::forward(const std::string& topic, const std::shared_ptr<const void>& message,
                             Clock::time_point received) {
  std::lock_guard lock(mutex_);
  const uint32_t id = topics_.at(topic).channel_id;
  if (id == 0) return;  // unadvertised
  ChannelState& channel = channels_.at(id);
  const bool image = channel.channel.schema_name == kImageType;
  std::string frame;
  if (channel.latched) channel.last_frame = frame = message_data(channel, message.get(), received);
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
    } else if (!image && options_.max_rate_hz > 0) {
      // A new subscriber starts with a full bucket: its first messages pass at once.
      auto [budget, first] = state.budget.try_emplace(id, RateBudget{rate_burst_, received});
      RateBudget& b = budget->second;
      if (!first) {
        const double elapsed = std::chrono::duration<double>(received - b.at).count();
        b.tokens = std::min(rate_burst_, b.tokens + std::max(0.0, elapsed) * options_.max_rate_hz);
        b.at = std::max(b.at, received);
      }
      if (b.tokens < 1) continue;
      b.tokens -= 1;
    }
    if (frame.empty()) frame = message_data(channel, message.get(), received);
    queue_frame(state, frame, subscription->second);
    pump(client, state);
  }
}

// A Message Data frame of `message`, its subscription id left for queue_frame to write.
std::string FoxgloveBridge::message_data(const ChannelState& channel, const void* message,
                                         Clock::time_point received) {
  const size_t size = channel.type->serialized_size(message);
  std::string frame(kMessageDataHeaderSize + size, '\0');
  channel.type->serialize(
      message,
      std::span<uint8_t>(reinterpret_cast<uint8_t*>(frame.data()) + kMessageDataHeaderSize, size));
  write_message_data_header(0, nanoseconds(received),
                            std::span<uint8_t, kMessageDataHeaderSize>(
                                reinterpret_cast<uint8_t*>(frame.data()), kMessageDataHeaderSize));
  return frame;
}

// A copy of `frame` for one client's subscription. Requires mutex_.
void FoxgloveBridge::queue_frame(ClientState& state, const std::string& frame,
                                 uint32_t subscription) {
  std::string copy = frame;
  set_message_data_subscription(
      subscription, std::span<uint8_t, kMessageDataHeaderSize>(
                        reinterpret_cast<uint8_t*>(copy.data()), kMessageDataHeaderSize));
  state.queue.push(std::move(copy), std::chrono::steady_clock::now());
}

// Hands queued frames to the socket while little is in flight. Requires mutex_.
void FoxgloveBridge::pump(ClientId client, ClientState& state) {
  while (state.queue.frames() > 0 && links_.buffered_bytes(client) < kInFlightBytes) {
    std::string frame = *state.queue.pop();
    if (links_.send_binary(client, frame.data(), frame.size())) ++counts_.sent;
  }
}

void FoxgloveBridge::pump_all() {
  std::vector<std::pair<ClientId, uint64_t>> too_slow;  // and the messages it lost
  {
    std::lock_guard lock(mutex_);
    for (auto it = clients_.begin(); it != clients_.end();) {
      pump(it->first, it->second);
      if (it->second.queue.should_disconnect(std::chrono::steady_clock::now())) {
        // Forgotten at once: nothing more is queued for it while its connection closes.
        too_slow.emplace_back(it->first, it->second.queue.dropped());
        counts_.dropped += it->second.queue.dropped();
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

}  // namespace mocap::foxglove
