#include "dds/dds_options.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap {
namespace fs = std::filesystem;

namespace {

std::optional<unsigned> parse_number(std::string_view text, unsigned max) {
  unsigned value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || value > max) {
    return std::nullopt;
  }
  return value;
}

// Dotted-quad IPv4, or a host name: labels of letters, digits and '-', not all digits.
bool valid_host(std::string_view host) {
  if (host.empty() || host.size() > 253) return false;
  if (host.find_first_not_of("0123456789.") == std::string_view::npos) {
    int parts = 0;
    for (size_t start = 0;; ++parts) {
      size_t dot = std::min(host.find('.', start), host.size());
      if (!parse_number(host.substr(start, dot - start), 255)) return false;
      if (dot == host.size()) return parts == 3;
      start = dot + 1;
    }
  }
  for (size_t start = 0;;) {
    size_t dot = std::min(host.find('.', start), host.size());
    std::string_view label = host.substr(start, dot - start);
    if (label.empty() || label.size() > 63 || label.front() == '-' || label.back() == '-' ||
        !std::all_of(label.begin(), label.end(), [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '-';
        })) {
      return false;
    }
    if (dot == host.size()) return true;
    start = dot + 1;
  }
}

bool valid_identity(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

}  // namespace

Durability offered_durability(Durability announced, const std::vector<uint8_t>& user_data) {
  bool marked = std::equal(user_data.begin(), user_data.end(), kVolatileWriterMark.begin(),
                           kVolatileWriterMark.end());
  return marked ? Durability::Volatile : announced;
}

std::optional<HostPort> parse_host_port(std::string_view text) {
  size_t colon = text.rfind(':');
  if (colon == std::string_view::npos || !valid_host(text.substr(0, colon))) return std::nullopt;
  std::optional<unsigned> port = parse_number(text.substr(colon + 1), 65535);
  if (!port || *port == 0) return std::nullopt;
  return HostPort{std::string(text.substr(0, colon)), static_cast<uint16_t>(*port)};
}

SecurityFiles security_files(const fs::path& directory, const std::string& identity) {
  return {directory / "ca.cert.pem", directory / "governance.smime",
          directory / (identity + ".cert.pem"), directory / (identity + ".key.pem"),
          directory / (identity + ".permissions.smime")};
}

std::optional<SecurityProblem> check_security(const fs::path& directory,
                                              const std::string& identity) {
  std::error_code error;
  if (directory.empty()) return SecurityProblem{"directory", "no folder given"};
  if (!fs::is_directory(directory, error)) {
    return SecurityProblem{"directory", fmt::format("{} is not a folder", directory.string())};
  }
  if (identity.empty()) return SecurityProblem{"identity", "no identity given"};
  if (!valid_identity(identity)) {
    return SecurityProblem{"identity", fmt::format("'{}' is not an identity name (letters, "
                                                   "digits, '_' and '-')",
                                                   identity)};
  }
  SecurityFiles files = security_files(directory, identity);
  struct Expected {
    const char* key;
    const char* what;
    const fs::path& path;
  };
  const Expected expected[] = {{"directory", "CA certificate", files.ca},
                               {"directory", "signed governance", files.governance},
                               {"identity", "certificate", files.certificate},
                               {"identity", "private key", files.private_key},
                               {"identity", "signed permissions", files.permissions}};
  for (const Expected& file : expected) {
    if (!fs::is_regular_file(file.path, error)) {
      return SecurityProblem{
          file.key, fmt::format("no {} {} in {} (scripts/make_security.sh makes it)", file.what,
                                file.path.filename().string(), directory.string())};
    }
  }
  return std::nullopt;
}

DdsOptions with_environment(DdsOptions options) {
  auto variable = [](const char* name) -> std::optional<std::string> {
    const char* text = std::getenv(name);
    if (text == nullptr || *text == '\0') return std::nullopt;
    return std::string(text);
  };
  if (auto servers = variable("MOCAP_DISCOVERY_SERVER")) {
    options.discovery_servers.clear();
    for (size_t start = 0; start <= servers->size();) {
      size_t end = std::min(servers->find(';', start), servers->size());
      std::string server = servers->substr(start, end - start);
      if (!parse_host_port(server)) {
        throw std::runtime_error(fmt::format(
            "MOCAP_DISCOVERY_SERVER='{}': '{}' is not host:port (expected host:port;host:port..)",
            *servers, server));
      }
      options.discovery_servers.push_back(server);
      start = end + 1;
    }
  }
  if (auto directory = variable("MOCAP_SECURITY_DIRECTORY")) {
    options.security_directory = *directory;
  }
  if (auto identity = variable("MOCAP_SECURITY_IDENTITY")) {
    options.security_identity = *identity;
  }
  if (options.security_directory.empty() != options.security_identity.empty()) {
    throw std::runtime_error(
        options.security_directory.empty()
            ? "DDS Security: an identity but no folder (set MOCAP_SECURITY_DIRECTORY)"
            : "DDS Security: a folder but no identity (set MOCAP_SECURITY_IDENTITY)");
  }
  return options;
}

}  // namespace mocap
