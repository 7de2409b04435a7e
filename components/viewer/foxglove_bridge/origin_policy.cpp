#include "viewer/foxglove_bridge/origin_policy.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>

namespace mocap::foxglove {
namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::optional<uint16_t> port_number(std::string_view text) {
  if (text.empty() || text.size() > 5) return std::nullopt;
  unsigned value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + static_cast<unsigned>(c - '0');
  }
  if (value > 65535) return std::nullopt;
  return static_cast<uint16_t>(value);
}

// A header value as it may be quoted in a message: printable, at most 100 characters.
std::string quoted(std::string_view text) {
  std::string out;
  for (char c : text.substr(0, 100)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return "'" + out + (text.size() > 100 ? "...'" : "'");
}

}  // namespace

std::optional<Authority> parse_authority(std::string_view text) {
  Authority authority;
  std::string_view rest;
  if (!text.empty() && text.front() == '[') {
    const size_t close = text.find(']');
    if (close == std::string_view::npos || close == 1) return std::nullopt;
    authority.name = lower(text.substr(1, close - 1));
    rest = text.substr(close + 1);
  } else {
    const size_t colon = text.find(':');
    authority.name = lower(text.substr(0, colon));
    rest = colon == std::string_view::npos ? std::string_view() : text.substr(colon);
  }
  if (authority.name.empty()) return std::nullopt;
  for (char c : authority.name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '_' &&
        c != ':' && c != '%') {
      return std::nullopt;
    }
  }
  if (!rest.empty()) {
    if (rest.front() != ':' || !(authority.port = port_number(rest.substr(1)))) return std::nullopt;
  }
  return authority;
}

OriginPolicy::OriginPolicy(OriginPolicyOptions options) : options_(std::move(options)) {
  for (std::string& host : options_.hosts) {
    if (auto authority = parse_authority(host)) host = authority->name;
  }
}

bool OriginPolicy::own_name(std::string_view name) const {
  return std::find(options_.hosts.begin(), options_.hosts.end(), name) != options_.hosts.end();
}

std::optional<std::string> OriginPolicy::refuse_host(std::string_view host) const {
  const std::optional<Authority> authority = parse_authority(host);
  if (!authority) return "Host " + quoted(host) + " is not a host name";
  if (!own_name(authority->name)) {
    return "Host " + quoted(host) + " is not a name of this server (a page whose name was made " +
           "to point here?); if it is yours, list '" + authority->name + "' in allowed_hosts";
  }
  return std::nullopt;
}

std::optional<std::string> OriginPolicy::refuse(std::string_view host,
                                                std::string_view origin) const {
  if (auto problem = refuse_host(host)) return problem;
  if (origin.empty()) return std::nullopt;
  if (std::find(options_.allowed_origins.begin(), options_.allowed_origins.end(), origin) !=
      options_.allowed_origins.end()) {
    return std::nullopt;
  }
  const std::string scheme = lower(origin.substr(0, origin.find("://")));
  if ((scheme == "http" || scheme == "https") && origin.find("://") != std::string_view::npos) {
    const std::string_view rest = origin.substr(scheme.size() + 3);
    if (auto authority = parse_authority(rest)) {
      const uint16_t port = authority->port.value_or(scheme == "https" ? 443 : 80);
      if (own_name(authority->name) && port == options_.port) return std::nullopt;
    }
  }
  return "Origin " + quoted(origin) + " is not this bridge's page (another page in a browser " +
         "here?); if it is yours, list it in allowed_origins";
}

std::vector<std::string> own_host_names(const std::string& address) {
  std::vector<std::string> names = {"localhost", "127.0.0.1", "::1"};
  char hostname[256] = {};
  if (gethostname(hostname, sizeof hostname - 1) == 0 && hostname[0] != '\0') {
    names.push_back(lower(hostname));
    names.push_back(lower(hostname) + ".local");
  }
  if (address != "0.0.0.0" && address != "::") {
    names.push_back(lower(address));
  } else if (ifaddrs* interfaces = nullptr; getifaddrs(&interfaces) == 0) {
    for (ifaddrs* i = interfaces; i != nullptr; i = i->ifa_next) {
      if (i->ifa_addr == nullptr) continue;
      char text[INET6_ADDRSTRLEN] = {};
      if (i->ifa_addr->sa_family == AF_INET) {
        inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(i->ifa_addr)->sin_addr, text,
                  sizeof text);
      } else if (i->ifa_addr->sa_family == AF_INET6) {
        inet_ntop(AF_INET6, &reinterpret_cast<sockaddr_in6*>(i->ifa_addr)->sin6_addr, text,
                  sizeof text);
      } else {
        continue;
      }
      names.push_back(lower(text));
    }
    freeifaddrs(interfaces);
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

}  // namespace mocap::foxglove
