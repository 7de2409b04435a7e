// A WebSocket server with plain HTTP on the same port, on a thread of its own: what the
// Foxglove bridge needs from the network, over websocketpp (Debian's libwebsocketpp-dev), with
// none of websocketpp's types in sight, so that its users need not build as it must (C++17).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mocap::foxglove {
namespace detail {
class WebSocketBackend;
}

struct HttpResponse {
  int status = 404;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body = "not found\n";
};

struct WebSocketServerOptions {
  std::string address = "127.0.0.1";  // an IPv4 or IPv6 address to listen on
  uint16_t port = 8765;               // 0: any free port (WebSocketServer::port() tells which)
  // Non-empty: a WebSocket client must present it ("Authorization: Bearer TOKEN", or
  // "?token=TOKEN" in the URL) or is refused with HTTP 401. Plain HTTP requests are served
  // without it.
  std::string token;
  // Both set: TLS (wss://, https://) with this certificate chain and private key (PEM files).
  std::string certificate_file;
  std::string key_file;
  // Accepted subprotocols, preferred first; a client offering none of them gets HTTP 400.
  std::vector<std::string> subprotocols;
  // Largest message a client may send; a larger one closes its connection.
  size_t max_incoming_message_bytes = 1 << 20;
  // Beyond the server's own names and page (origin_policy.hpp): Host names and Origins to
  // accept. A request with another Host is refused with HTTP 403, as is a WebSocket request
  // from another page.
  std::vector<std::string> allowed_hosts;
  std::vector<std::string> allowed_origins;

  // Why these options cannot be used, naming the field ("address: 'x' is not an IP address:
  // ..."); nullopt when they can. WebSocketServer's constructor throws std::invalid_argument
  // with it.
  std::optional<std::string> problem() const;
};

// Called on the server's thread. A ClientId is never reused within one server.
using ClientId = uint64_t;
struct WebSocketHandlers {
  std::function<void(ClientId, const std::string& subprotocol)> on_open;
  std::function<void(ClientId, const std::string& text)> on_text;
  std::function<void(ClientId, const std::string& bytes)> on_binary;
  // `protocol_error`: the close code and reason when the server closed the connection for a
  // frame the WebSocket protocol forbids (e.g. "1009 A message was too large"), else empty.
  std::function<void(ClientId, const std::string& protocol_error)> on_close;
  // GET requests that are not WebSocket upgrades: the resource ("/index.html?x") -> response.
  std::function<HttpResponse(const std::string& resource)> on_http;
  // A request refused for its Host or Origin header: why, in one line.
  std::function<void(const std::string& why)> on_refused;
};

class WebSocketServer {
 public:
  // Listens and starts the thread. Throws std::invalid_argument for options that cannot be
  // used (WebSocketServerOptions::problem), std::runtime_error naming address:port when the
  // address cannot be bound (in use, not an address of this machine), or the TLS file that
  // cannot be used.
  WebSocketServer(WebSocketServerOptions options, WebSocketHandlers handlers);
  // Closes every connection ("server stopping") and joins the thread.
  ~WebSocketServer();
  WebSocketServer(const WebSocketServer&) = delete;
  WebSocketServer& operator=(const WebSocketServer&) = delete;

  uint16_t port() const;
  // Whether only this machine can connect (a loopback address).
  bool loopback_only() const;

  // Thread-safe. Queue a frame to a client; false when it is gone.
  bool send_text(ClientId client, const std::string& text);
  bool send_binary(ClientId client, const void* data, size_t size);
  // Bytes queued for a client and not yet handed to the socket (0 when it is gone).
  size_t buffered_bytes(ClientId client) const;
  // Closes a client's connection with a reason (at most 123 bytes are sent). A client that
  // does not complete the closing handshake within a second (one that reads nothing cannot)
  // has its TCP connection cut.
  void close(ClientId client, const std::string& reason);

 private:
  std::unique_ptr<detail::WebSocketBackend> impl_;
};

}  // namespace mocap::foxglove
