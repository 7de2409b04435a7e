// Built as C++17: websocketpp 0.8.2 (Debian 12) does not compile as C++20 (its constructors
// are declared with template-ids, which C++20 forbids; fixed upstream only after 0.8.2).
#define ASIO_STANDALONE
#include "websocket_server.hpp"

#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace mocap::foxglove {
namespace {

using Endpoint = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;

// RFC 6455: a close frame's reason fits in 123 bytes.
std::string close_reason(const std::string& reason) { return reason.substr(0, 123); }

}  // namespace

struct WebSocketServer::Impl {
  WebSocketServerOptions options;
  WebSocketHandlers handlers;
  // Mutable: websocketpp's lookups are not const, though they change nothing.
  mutable Endpoint endpoint;
  std::thread thread;
  mutable std::mutex mutex;
  std::map<ClientId, Handle> clients;
  std::map<Handle, ClientId, std::owner_less<Handle>> ids;
  ClientId next_id = 1;
  uint16_t port = 0;

  Endpoint::connection_ptr connection(ClientId client) const {
    Handle handle;
    {
      std::lock_guard lock(mutex);
      auto found = clients.find(client);
      if (found == clients.end()) return nullptr;
      handle = found->second;
    }
    websocketpp::lib::error_code error;
    auto con = endpoint.get_con_from_hdl(handle, error);
    return error ? nullptr : con;
  }

  ClientId id_of(const Handle& handle) {
    std::lock_guard lock(mutex);
    auto found = ids.find(handle);
    return found == ids.end() ? 0 : found->second;
  }
};

WebSocketServer::WebSocketServer(WebSocketServerOptions options, WebSocketHandlers handlers)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = std::move(options);
  s.handlers = std::move(handlers);
  s.endpoint.clear_access_channels(websocketpp::log::alevel::all);
  s.endpoint.clear_error_channels(websocketpp::log::elevel::all);
  s.endpoint.init_asio();
  s.endpoint.set_reuse_addr(true);
  s.endpoint.set_max_message_size(s.options.max_incoming_message_bytes);
  // A client that never answers the close handshake (stopping, or closed for misbehaving) is
  // dropped after 1 s.
  s.endpoint.set_close_handshake_timeout(1000);

  s.endpoint.set_validate_handler([&s](Handle handle) {
    auto con = s.endpoint.get_con_from_hdl(handle);
    const std::vector<std::string>& offered = con->get_requested_subprotocols();
    for (const std::string& wanted : s.options.subprotocols) {
      for (const std::string& protocol : offered) {
        if (protocol == wanted) {
          con->select_subprotocol(protocol);
          return true;
        }
      }
    }
    con->set_status(websocketpp::http::status_code::bad_request);
    return false;
  });
  s.endpoint.set_http_handler([&s](Handle handle) {
    auto con = s.endpoint.get_con_from_hdl(handle);
    HttpResponse response;
    if (s.handlers.on_http) response = s.handlers.on_http(con->get_resource());
    con->set_status(static_cast<websocketpp::http::status_code::value>(response.status));
    con->append_header("Content-Type", response.content_type);
    con->append_header("Cache-Control", "no-cache");
    con->set_body(response.body);
  });
  s.endpoint.set_tcp_pre_init_handler([&s](Handle handle) {
    websocketpp::lib::error_code error;
    auto con = s.endpoint.get_con_from_hdl(handle, error);
    if (!error) con->get_raw_socket().set_option(asio::ip::tcp::no_delay(true), error);
  });
  s.endpoint.set_open_handler([&s](Handle handle) {
    ClientId id;
    {
      std::lock_guard lock(s.mutex);
      id = s.next_id++;
      s.clients[id] = handle;
      s.ids[handle] = id;
    }
    if (s.handlers.on_open) {
      s.handlers.on_open(id, s.endpoint.get_con_from_hdl(handle)->get_subprotocol());
    }
  });
  auto closed = [&s](Handle handle) {
    ClientId id = 0;
    {
      std::lock_guard lock(s.mutex);
      auto found = s.ids.find(handle);
      if (found == s.ids.end()) return;
      id = found->second;
      s.ids.erase(found);
      s.clients.erase(id);
    }
    // Closes websocketpp made for a broken frame (too large, not UTF-8, bad framing): the
    // client may never see the reason, its connection being cut while it still sends.
    std::string protocol_error;
    websocketpp::lib::error_code error;
    if (auto con = s.endpoint.get_con_from_hdl(handle, error); !error) {
      const auto code = con->get_local_close_code();
      if (code == websocketpp::close::status::protocol_error ||
          code == websocketpp::close::status::invalid_payload ||
          code == websocketpp::close::status::message_too_big) {
        protocol_error = std::to_string(code) + " " + con->get_local_close_reason();
      }
    }
    if (s.handlers.on_close) s.handlers.on_close(id, protocol_error);
  };
  s.endpoint.set_close_handler(closed);
  s.endpoint.set_fail_handler(closed);
  s.endpoint.set_message_handler([&s](Handle handle, Endpoint::message_ptr message) {
    ClientId id = s.id_of(handle);
    if (id == 0) return;
    if (message->get_opcode() == websocketpp::frame::opcode::text) {
      if (s.handlers.on_text) s.handlers.on_text(id, message->get_payload());
    } else if (s.handlers.on_binary) {
      s.handlers.on_binary(id, message->get_payload());
    }
  });

  websocketpp::lib::error_code error;
  asio::ip::address address = asio::ip::make_address(s.options.address, error);
  if (error) {
    throw std::runtime_error("address '" + s.options.address + "': " + error.message());
  }
  s.endpoint.listen(asio::ip::tcp::endpoint(address, s.options.port), error);
  if (!error) s.endpoint.start_accept(error);
  if (error) {
    throw std::runtime_error("cannot listen on " + s.options.address + ":" +
                             std::to_string(s.options.port) + ": " + error.message());
  }
  asio::error_code local_error;
  s.port = s.endpoint.get_local_endpoint(local_error).port();
  s.thread = std::thread([&s] { s.endpoint.run(); });
}

WebSocketServer::~WebSocketServer() {
  Impl& s = *impl_;
  asio::post(s.endpoint.get_io_service(), [&s] {
    websocketpp::lib::error_code error;
    s.endpoint.stop_listening(error);
    std::map<ClientId, Handle> clients;
    {
      std::lock_guard lock(s.mutex);
      clients = s.clients;
    }
    for (auto& [id, handle] : clients) {
      s.endpoint.close(handle, websocketpp::close::status::going_away, "server stopping", error);
    }
  });
  s.thread.join();
}

uint16_t WebSocketServer::port() const { return impl_->port; }

bool WebSocketServer::send_text(ClientId client, const std::string& text) {
  auto con = impl_->connection(client);
  if (!con) return false;
  return !con->send(text, websocketpp::frame::opcode::text);
}

bool WebSocketServer::send_binary(ClientId client, const void* data, size_t size) {
  auto con = impl_->connection(client);
  if (!con) return false;
  return !con->send(data, size, websocketpp::frame::opcode::binary);
}

size_t WebSocketServer::buffered_bytes(ClientId client) const {
  auto con = impl_->connection(client);
  return con ? con->get_buffered_amount() : 0;
}

void WebSocketServer::close(ClientId client, const std::string& reason) {
  auto con = impl_->connection(client);
  if (!con) return;
  websocketpp::lib::error_code error;
  con->close(websocketpp::close::status::policy_violation, close_reason(reason), error);
  Impl& s = *impl_;
  s.endpoint.set_timer(1000, [&s, client](const websocketpp::lib::error_code&) {
    auto lingering = s.connection(client);
    if (!lingering) return;
    asio::error_code ignored;
    lingering->get_raw_socket().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
    lingering->get_raw_socket().close(ignored);
  });
}

}  // namespace mocap::foxglove
