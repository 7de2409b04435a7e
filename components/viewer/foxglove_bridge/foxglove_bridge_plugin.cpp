// foxglove_bridge: the graph's topics over the Foxglove WebSocket protocol, for Foxglove,
// Lichtblick and any client of the protocol. The bridge's state is the library of the same
// name (foxglove_bridge.hpp); this plugin joins it to the component's context (subscriptions,
// publishers, timers) and to the WebSocket server, which also serves the built-in viewer.
#include <chrono>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <mocap/component.hpp>

#include "viewer/foxglove_bridge/foxglove_bridge.hpp"
#include "viewer/foxglove_bridge/websocket_server.hpp"
#include "viewer/web/viewer_assets.hpp"

namespace mocap::foxglove {
namespace {

// How often the bridge looks for topics that appeared or disappeared on the domain.
constexpr std::chrono::seconds kDiscoveryPeriod{1};
// How often queued frames go out and clients' messages are published.
constexpr std::chrono::milliseconds kTurnPeriod{20};

// The server's options and the bridge's.
struct Settings {
  WebSocketServerOptions server;
  FoxgloveBridgeOptions bridge;
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
             &Settings::bridge, &FoxgloveBridgeOptions::topics)
        .add("max_image_rate_hz",
             "most sensor_msgs/msg/Image messages a second per client and topic (0: all)",
             &Settings::bridge, &FoxgloveBridgeOptions::max_image_rate_hz)
        .range(0.0, 1000.0)
        .add("max_rate_hz",
             "most messages a second per client and topic of the other types, on average: a "
             "topic slower than that (/diagnostics, /alerts) passes whole (0: all)",
             &Settings::bridge, &FoxgloveBridgeOptions::max_rate_hz)
        .range(0.0, 10000.0)
        .add("send_buffer_limit_bytes",
             "bytes a client may have queued; beyond, its oldest messages are dropped, "
             "and after 5 s of dropping it is disconnected",
             &Settings::bridge, &FoxgloveBridgeOptions::queue, &ClientQueueOptions::limit_bytes)
        .range(1'000'000, 1'000'000'000)
        .add("client_publish",
             "let clients publish (Foxglove's clientPublish) on topics that `topics` "
             "allows, in CDR of a type this process knows",
             &Settings::bridge, &FoxgloveBridgeOptions::client_publish);

// The built-in viewer's files; "/" is its page.
HttpResponse serve(const std::string& resource) {
  std::string path = resource.substr(0, resource.find_first_of("?#"));
  if (path == "/") path = "/index.html";
  for (const ViewerAsset& asset : viewer_assets()) {
    if (asset.path == path) return {200, std::string(asset.content_type), std::string(asset.body)};
  }
  return {};
}

class FoxgloveBridgeComponent final : public Component, BridgeGraph, ClientLinks {
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

  explicit FoxgloveBridgeComponent(Context& context)
      : Component(context),
        bridge_(settings_.bridge, context.known_topics(), context.name(), *this, *this, log()) {
    WebSocketServerOptions options = settings_.server;
    options.subprotocols = {std::string(kSubprotocol), std::string(kSdkSubprotocol)};
    WebSocketHandlers handlers;
    handlers.on_open = [this](ClientId client, const std::string&) { bridge_.opened(client); };
    handlers.on_text = [this](ClientId client, const std::string& text) {
      bridge_.received(client, text);
    };
    handlers.on_binary = [this](ClientId client, const std::string& frame) {
      bridge_.received_binary(client, frame);
    };
    handlers.on_close = [this](ClientId client, const std::string& protocol_error) {
      if (!protocol_error.empty()) {
        log().warn("foxglove client {}: closed for a broken frame: {}", client, protocol_error);
      }
      bridge_.closed(client);
    };
    handlers.on_http = [](const std::string& resource) { return serve(resource); };
    handlers.on_refused = [this](const std::string& why) { bridge_.refused(why); };
    try {
      server_ = std::make_unique<WebSocketServer>(options, handlers);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(e.what());  // names the parameter at fault
    }
    create_timer(kTurnPeriod, [this] { bridge_.run_once(); });
    create_timer(kDiscoveryPeriod,
                 [this] { bridge_.update_topics(this->context().discovered_topics()); });
    const bool tls = !options.certificate_file.empty();
    const std::string served = fmt::format(
        "Foxglove WebSocket server on {0}://{1}:{2} offering {3} topic(s){4}{5}; the viewer: "
        "{6}://{1}:{2}/",
        tls ? "wss" : "ws", options.address, server_->port(), bridge_.channel_count(),
        settings_.bridge.client_publish ? ", clients may publish" : "",
        options.token.empty() ? "" : ", token required", tls ? "https" : "http");
    if (server_->loopback_only()) {
      log().info("{} (this machine only)", served);
    } else {
      log().warn("{}. Open to the network: any host that reaches port {} may connect{}{}", served,
                 server_->port(), options.token.empty() ? ", no token asked (see token)" : "",
                 tls ? "" : ", unencrypted (see certificate_file)");
    }
  }

  ~FoxgloveBridgeComponent() override {
    server_.reset();  // joins the server's thread: no handler runs after this
    const BridgeCounts counts = bridge_.counts();
    log().info(
        "foxglove bridge: {} client(s) served, {} message(s) sent, {} dropped; {} received "
        "from clients, {} dropped; {} request(s) refused for their Host or Origin",
        counts.clients_served, counts.sent, counts.dropped, counts.client_messages,
        counts.client_messages_dropped, counts.refused_requests);
  }

 private:
  // BridgeGraph: the component's context.
  void subscribe(const std::string& topic, const MessageType& type, const Qos& qos) override {
    context().subscribe_any(topic, type, qos,
                            [this, topic](const std::shared_ptr<const void>& message) {
                              bridge_.forward(topic, message, now());
                            });
  }
  void unsubscribe(const std::string& topic) override { context().unsubscribe_any(topic); }
  void publish(const std::string& topic, const MessageType& type,
               std::shared_ptr<void> message) override {
    auto publisher = publishers_.find(topic);
    if (publisher == publishers_.end()) {
      // Reliable, volatile, keep last: matches every subscriber and never waits.
      Qos qos = Qos::sensor_data();
      qos.reliability = Reliability::Reliable;
      publisher = publishers_.emplace(topic, context().advertise_any(topic, type, qos)).first;
    }
    publisher->second->publish(std::move(message));
  }

  // ClientLinks: the WebSocket server, once it exists (no client before).
  bool send_text(ClientId client, const std::string& text) override {
    return server_->send_text(client, text);
  }
  bool send_binary(ClientId client, const void* data, size_t size) override {
    return server_->send_binary(client, data, size);
  }
  size_t buffered_bytes(ClientId client) const override { return server_->buffered_bytes(client); }
  void close(ClientId client, const std::string& reason) override {
    server_->close(client, reason);
  }

  std::map<std::string, std::shared_ptr<PublisherPort>> publishers_;  // for clients, by topic
  FoxgloveBridge bridge_;
  std::unique_ptr<WebSocketServer> server_;  // last: stopped first
};

}  // namespace
}  // namespace mocap::foxglove

MOCAP_REGISTER_COMPONENT(mocap::foxglove::FoxgloveBridgeComponent, "foxglove_bridge")
