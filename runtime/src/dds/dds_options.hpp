// The DDS settings every implementation shares: the environment's overrides of DdsOptions,
// the checks of security files and server addresses, and the conventions of the runtime's
// writers on the wire.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/component_host.hpp>
#include <mocap/qos.hpp>

namespace mocap {

// The user data of a reliable writer that is volatile although it announces transient_local
// durability (fastdds_qos.cpp, to_writer_qos, says why). Our readers and tools take it for
// volatile.
constexpr std::string_view kVolatileWriterMark = "mocap:durability=volatile";

// The durability a discovered writer offers, `announced` on the wire, with its `user_data`.
Durability offered_durability(Durability announced, const std::vector<uint8_t>& user_data);

// `options` with the environment's overrides: MOCAP_DISCOVERY_SERVER ("host:port;host:port"),
// MOCAP_SECURITY_DIRECTORY and MOCAP_SECURITY_IDENTITY. (MOCAP_DOMAIN_ID: resolve_domain_id.)
// Throws std::runtime_error naming the variable for a bad value.
DdsOptions with_environment(DdsOptions options);

// A Discovery Server address.
struct HostPort {
  std::string host;  // an IPv4 address or a host name
  uint16_t port = 0;
};
// "host:port" with port 1..65535, or nullopt.
std::optional<HostPort> parse_host_port(std::string_view text);

// The files of DDS Security identity `identity` in `directory`, named as
// scripts/make_security.sh makes them.
struct SecurityFiles {
  std::filesystem::path ca;           // ca.cert.pem: identity and permissions CA
  std::filesystem::path governance;   // governance.smime
  std::filesystem::path certificate;  // IDENTITY.cert.pem
  std::filesystem::path private_key;  // IDENTITY.key.pem
  std::filesystem::path permissions;  // IDENTITY.permissions.smime
};
SecurityFiles security_files(const std::filesystem::path& directory, const std::string& identity);

// What makes security settings unusable, or nullopt. `key` says which setting is at fault:
// "directory" (not a folder, no CA or governance) or "identity" (bad name, files missing).
struct SecurityProblem {
  std::string key;
  std::string message;  // "no certificate alice.cert.pem in /path"
};
std::optional<SecurityProblem> check_security(const std::filesystem::path& directory,
                                              const std::string& identity);

}  // namespace mocap
