// Built as C++17: websocketpp 0.8.2 (Debian 12) does not compile as C++20 (its constructors
// are declared with template-ids, which C++20 forbids; fixed upstream only after 0.8.2).
#define ASIO_STANDALONE
#include "viewer/foxglove_bridge/websocket_server.hpp"

#include "viewer/foxglove_bridge/origin_policy.hpp"

#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <type_traits>

#include <fmt/format.h>
#include <websocketpp/config/asio.hpp>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace mocap::foxglove {
namespace {

using Handle = websocketpp::connection_hdl;
using Plain = websocketpp::config::asio;
using Tls = websocketpp::config::asio_tls;

// RFC 6455: a close frame's reason fits in 123 bytes.
std::string close_reason(const std::string& reason) { return reason.substr(0, 123); }

// Equal without telling, by its time, how much of a guess was right.
bool same_secret(const std::string& given, const std::string& expected) {
  unsigned char difference = given.size() == expected.size() ? 0 : 1;
  for (size_t i = 0; i < given.size(); ++i) {
    difference |= static_cast<unsigned char>(given[i] ^ expected[i % expected.size()]);
  }
  return difference == 0;
}

// `text` with its %XX escapes (and '+', a space in a query) decoded; a broken escape is kept.
std::string percent_decoded(std::string_view text) {
  auto hex = [](char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
  };
  std::string decoded;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%' && i + 2 < text.size() && hex(text[i + 1]) >= 0 && hex(text[i + 2]) >= 0) {
      decoded += static_cast<char>(hex(text[i + 1]) * 16 + hex(text[i + 2]));
      i += 2;
    } else {
      decoded += text[i] == '+' ? ' ' : text[i];
    }
  }
  return decoded;
}

// The token a client presents: "Authorization: Bearer TOKEN", or "token=TOKEN" in the query of
// the resource it asks for (a browser's WebSocket cannot set headers).
std::string presented_token(const std::string& authorization, const std::string& resource) {
  constexpr std::string_view kBearer = "Bearer ";
  if (authorization.compare(0, kBearer.size(), kBearer) == 0) {
    return authorization.substr(kBearer.size());
  }
  const size_t query = resource.find('?');
  if (query == std::string::npos) return "";
  for (size_t start = query + 1; start < resource.size();) {
    const size_t end = std::min(resource.find('&', start), resource.size());
    const std::string_view pair(resource.data() + start, end - start);
    if (pair.substr(0, 6) == "token=") return percent_decoded(pair.substr(6));
    start = end + 1;
  }
  return "";
}

}  // namespace

// What the server does, whatever websocketpp config carries it.
class detail::WebSocketBackend {
 public:
  virtual ~WebSocketBackend() = default;
  virtual uint16_t port() const = 0;
  virtual bool loopback_only() const = 0;
  virtual bool send(ClientId client, const void* data, size_t size, bool text) = 0;
  virtual size_t buffered_bytes(ClientId client) const = 0;
  virtual void close(ClientId client, const std::string& reason) = 0;
};

namespace {

template <class Config>
class Server final : public detail::WebSocketBackend {
 public:
  using Endpoint = websocketpp::server<Config>;

  Server(WebSocketServerOptions options, WebSocketHandlers handlers)
      : options_(std::move(options)), handlers_(std::move(handlers)) {
    endpoint_.clear_access_channels(websocketpp::log::alevel::all);
    endpoint_.clear_error_channels(websocketpp::log::elevel::all);
    endpoint_.init_asio();
    endpoint_.set_reuse_addr(true);
    endpoint_.set_max_message_size(options_.max_incoming_message_bytes);
    // A client that never answers the close handshake (stopping, or closed for misbehaving) is
    // dropped after 1 s.
    endpoint_.set_close_handshake_timeout(1000);
    if constexpr (std::is_same_v<Config, Tls>) set_up_tls();

    endpoint_.set_validate_handler([this](Handle handle) { return validate(handle); });
    endpoint_.set_http_handler([this](Handle handle) {
      auto con = endpoint_.get_con_from_hdl(handle);
      HttpResponse response;
      if (auto why = policy_->refuse_host(con->get_request_header("Host"))) {
        refused(*why);
        response = {403, "text/plain; charset=utf-8", "forbidden: " + *why + "\n"};
      } else if (handlers_.on_http) {
        response = handlers_.on_http(con->get_resource());
      }
      con->set_status(static_cast<websocketpp::http::status_code::value>(response.status));
      con->append_header("Content-Type", response.content_type);
      con->append_header("Cache-Control", "no-cache");
      con->set_body(response.body);
    });
    endpoint_.set_tcp_pre_init_handler([this](Handle handle) {
      websocketpp::lib::error_code error;
      auto con = endpoint_.get_con_from_hdl(handle, error);
      if (!error) con->get_raw_socket().set_option(asio::ip::tcp::no_delay(true), error);
    });
    endpoint_.set_open_handler([this](Handle handle) {
      ClientId id;
      {
        std::lock_guard lock(mutex_);
        id = next_id_++;
        clients_[id] = handle;
        ids_[handle] = id;
      }
      if (handlers_.on_open) {
        handlers_.on_open(id, endpoint_.get_con_from_hdl(handle)->get_subprotocol());
      }
    });
    endpoint_.set_close_handler([this](Handle handle) { closed(handle); });
    endpoint_.set_fail_handler([this](Handle handle) { closed(handle); });
    endpoint_.set_message_handler([this](Handle handle, typename Endpoint::message_ptr message) {
      ClientId id = id_of(handle);
      if (id == 0) return;
      if (message->get_opcode() == websocketpp::frame::opcode::text) {
        if (handlers_.on_text) handlers_.on_text(id, message->get_payload());
      } else if (handlers_.on_binary) {
        handlers_.on_binary(id, message->get_payload());
      }
    });

    websocketpp::lib::error_code error;
    const asio::ip::address address = asio::ip::make_address(options_.address);  // checked
    loopback_ = address.is_loopback();
    endpoint_.listen(asio::ip::tcp::endpoint(address, options_.port), error);
    if (!error) endpoint_.start_accept(error);
    if (error) {
      throw std::runtime_error("address/port: cannot listen on " + options_.address + ":" +
                               std::to_string(options_.port) + ": " + error.message());
    }
    asio::error_code local_error;
    port_ = endpoint_.get_local_endpoint(local_error).port();
    OriginPolicyOptions policy{port_, std::is_same_v<Config, Tls>, own_host_names(options_.address),
                               options_.allowed_origins};
    policy.hosts.insert(policy.hosts.end(), options_.allowed_hosts.begin(),
                        options_.allowed_hosts.end());
    policy_ = std::make_unique<OriginPolicy>(std::move(policy));
    thread_ = std::thread([this] { endpoint_.run(); });
  }

  // Closes every connection ("server stopping") and joins the thread.
  ~Server() override {
    asio::post(endpoint_.get_io_service(), [this] {
      websocketpp::lib::error_code error;
      endpoint_.stop_listening(error);
      std::map<ClientId, Handle> clients;
      {
        std::lock_guard lock(mutex_);
        clients = clients_;
      }
      for (auto& [id, handle] : clients) {
        endpoint_.close(handle, websocketpp::close::status::going_away, "server stopping", error);
      }
    });
    thread_.join();
  }

  uint16_t port() const override { return port_; }
  bool loopback_only() const override { return loopback_; }

  bool send(ClientId client, const void* data, size_t size, bool text) override {
    auto con = connection(client);
    if (!con) return false;
    return !con->send(data, size,
                      text ? websocketpp::frame::opcode::text : websocketpp::frame::opcode::binary);
  }

  size_t buffered_bytes(ClientId client) const override {
    auto con = connection(client);
    return con ? con->get_buffered_amount() : 0;
  }

  void close(ClientId client, const std::string& reason) override {
    auto con = connection(client);
    if (!con) return;
    websocketpp::lib::error_code error;
    con->close(websocketpp::close::status::policy_violation, close_reason(reason), error);
    endpoint_.set_timer(1000, [this, client](const websocketpp::lib::error_code&) {
      auto lingering = connection(client);
      if (!lingering) return;
      asio::error_code ignored;
      lingering->get_raw_socket().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
      lingering->get_raw_socket().close(ignored);
    });
  }

 private:
  // The certificate and key are read now, so that a bad file fails the constructor; each
  // connection shares the context.
  void set_up_tls() {
    auto context = std::make_shared<asio::ssl::context>(asio::ssl::context::tls_server);
    context->set_options(asio::ssl::context::default_workarounds | asio::ssl::context::no_sslv2 |
                         asio::ssl::context::no_sslv3 | asio::ssl::context::no_tlsv1 |
                         asio::ssl::context::no_tlsv1_1 | asio::ssl::context::single_dh_use);
    asio::error_code error;
    context->use_certificate_chain_file(options_.certificate_file, error);
    if (error) {
      throw std::runtime_error("certificate_file: '" + options_.certificate_file +
                               "': " + error.message());
    }
    context->use_private_key_file(options_.key_file, asio::ssl::context::pem, error);
    if (error) {
      throw std::runtime_error("key_file: '" + options_.key_file + "': " + error.message());
    }
    endpoint_.set_tls_init_handler([context](Handle) { return context; });
  }

  bool validate(Handle handle) {
    auto con = endpoint_.get_con_from_hdl(handle);
    if (auto why =
            policy_->refuse(con->get_request_header("Host"), con->get_request_header("Origin"))) {
      refused(*why);
      con->set_status(websocketpp::http::status_code::forbidden);
      return false;
    }
    if (!options_.token.empty() &&
        !same_secret(presented_token(con->get_request_header("Authorization"), con->get_resource()),
                     options_.token)) {
      con->set_status(websocketpp::http::status_code::unauthorized);
      return false;
    }
    const std::vector<std::string>& offered = con->get_requested_subprotocols();
    for (const std::string& wanted : options_.subprotocols) {
      for (const std::string& protocol : offered) {
        if (protocol == wanted) {
          con->select_subprotocol(protocol);
          return true;
        }
      }
    }
    con->set_status(websocketpp::http::status_code::bad_request);
    return false;
  }

  void refused(const std::string& why) {
    if (handlers_.on_refused) handlers_.on_refused(why);
  }

  void closed(Handle handle) {
    ClientId id = 0;
    {
      std::lock_guard lock(mutex_);
      auto found = ids_.find(handle);
      if (found == ids_.end()) return;
      id = found->second;
      ids_.erase(found);
      clients_.erase(id);
    }
    // Closes websocketpp made for a broken frame (too large, not UTF-8, bad framing): the
    // client may never see the reason, its connection being cut while it still sends.
    std::string protocol_error;
    websocketpp::lib::error_code error;
    if (auto con = endpoint_.get_con_from_hdl(handle, error); !error) {
      const auto code = con->get_local_close_code();
      if (code == websocketpp::close::status::protocol_error ||
          code == websocketpp::close::status::invalid_payload ||
          code == websocketpp::close::status::message_too_big) {
        protocol_error = std::to_string(code) + " " + con->get_local_close_reason();
      }
    }
    if (handlers_.on_close) handlers_.on_close(id, protocol_error);
  }

  typename Endpoint::connection_ptr connection(ClientId client) const {
    Handle handle;
    {
      std::lock_guard lock(mutex_);
      auto found = clients_.find(client);
      if (found == clients_.end()) return nullptr;
      handle = found->second;
    }
    websocketpp::lib::error_code error;
    auto con = endpoint_.get_con_from_hdl(handle, error);
    return error ? nullptr : con;
  }

  ClientId id_of(const Handle& handle) {
    std::lock_guard lock(mutex_);
    auto found = ids_.find(handle);
    return found == ids_.end() ? 0 : found->second;
  }

  WebSocketServerOptions options_;
  WebSocketHandlers handlers_;
  std::unique_ptr<OriginPolicy> policy_;  // made once the port is known
  // Mutable: websocketpp's lookups are not const, though they change nothing.
  mutable Endpoint endpoint_;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::map<ClientId, Handle> clients_;
  std::map<Handle, ClientId, std::owner_less<Handle>> ids_;
  ClientId next_id_ = 1;
  uint16_t port_ = 0;
  bool loopback_ = false;
};

}  // namespace

std::optional<std::string> WebSocketServerOptions::problem() const {
  asio::error_code error;
  asio::ip::make_address(address, error);
  if (error) return fmt::format("address: '{}' is not an IP address: {}", address, error.message());
  if (certificate_file.empty() != key_file.empty()) {
    return fmt::format("{}: empty while {} is set; TLS needs both (or neither, for plain ws://)",
                       key_file.empty() ? "key_file" : "certificate_file",
                       key_file.empty() ? "certificate_file" : "key_file");
  }
  if (subprotocols.empty()) return "subprotocols: none; every WebSocket client would be refused";
  if (max_incoming_message_bytes == 0) {
    return "max_incoming_message_bytes: 0 leaves no room for a message";
  }
  return std::nullopt;
}

WebSocketServer::WebSocketServer(WebSocketServerOptions options, WebSocketHandlers handlers) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("WebSocketServerOptions::" + *problem);
  }
  if (options.certificate_file.empty()) {
    impl_ = std::make_unique<Server<Plain>>(std::move(options), std::move(handlers));
  } else {
    impl_ = std::make_unique<Server<Tls>>(std::move(options), std::move(handlers));
  }
}

WebSocketServer::~WebSocketServer() = default;

uint16_t WebSocketServer::port() const { return impl_->port(); }

bool WebSocketServer::loopback_only() const { return impl_->loopback_only(); }

bool WebSocketServer::send_text(ClientId client, const std::string& text) {
  return impl_->send(client, text.data(), text.size(), true);
}

bool WebSocketServer::send_binary(ClientId client, const void* data, size_t size) {
  return impl_->send(client, data, size, false);
}

size_t WebSocketServer::buffered_bytes(ClientId client) const {
  return impl_->buffered_bytes(client);
}

void WebSocketServer::close(ClientId client, const std::string& reason) {
  impl_->close(client, reason);
}

}  // namespace mocap::foxglove
