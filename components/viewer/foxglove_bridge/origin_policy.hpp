// Who may open a WebSocket on the bridge, by the request's Host and Origin headers: against
// pages in a browser on this machine reading the graph (cross-site WebSocket hijacking) and
// against pages whose own name was made to point here (DNS rebinding).
//
// A browser always sends Origin with a WebSocket request, and a page cannot forge it. The
// bridge takes a request
// - whose Host names this server: a name or address it answers to (own_host_names) or one the
//   launch file lists. A page on attacker.example whose name now resolves to 127.0.0.1 sends
//   "Host: attacker.example:8765" and is refused;
// - and whose Origin is absent (a program, not a browser: Foxglove's and ROS's libraries send
//   none), the bridge's own page (http or https, a name above, the bridge's port), or one the
//   launch file lists exactly as the browser sends it. "null" (a file opened in a browser, a
//   sandboxed frame) is refused unless listed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::foxglove {

struct OriginPolicyOptions {
  uint16_t port = 8765;  // the bridge's
  bool tls = false;
  // The names and addresses the server answers to, without port (own_host_names), and the
  // launch file's; compared without regard to case.
  std::vector<std::string> hosts;
  // Origins accepted as they are ("https://app.foxglove.dev", "file://").
  std::vector<std::string> allowed_origins;
};

class OriginPolicy {
 public:
  explicit OriginPolicy(OriginPolicyOptions options);

  // Why a request with this Host header is refused, or nullopt when it is not.
  std::optional<std::string> refuse_host(std::string_view host) const;
  // Why a WebSocket request with these headers is refused, or nullopt when it is not. An empty
  // `origin`: the request had none.
  std::optional<std::string> refuse(std::string_view host, std::string_view origin) const;

 private:
  bool own_name(std::string_view name) const;

  OriginPolicyOptions options_;
};

// "name" and "port" of a Host header or an origin's authority ("[::1]:8765" -> "::1", 8765),
// the name in lower case; nullopt when it is not one.
struct Authority {
  std::string name;
  std::optional<uint16_t> port;
};
std::optional<Authority> parse_authority(std::string_view text);

// The names a server bound to `address` answers to: localhost and the loopback addresses, this
// machine's host name (and NAME.local), `address` itself or, for 0.0.0.0 and ::, every address
// of this machine's interfaces.
std::vector<std::string> own_host_names(const std::string& address);

}  // namespace mocap::foxglove
