// Our QoS and host options as Fast DDS QoS. Shared by the transport and the benchmark's raw
// Fast DDS reference, so both run with the very same settings; and the checks the launch file
// makes of its `dds:` settings.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include <mocap/component_host.hpp>
#include <mocap/qos.hpp>

namespace mocap {

// Shared memory of each participant for messages to processes on the same host.
constexpr uint32_t kSharedMemorySegmentBytes = 8 * 1024 * 1024;

// The longest one DDS write waits for room in a full keep-all history (the writer's
// max_blocking_time). A publisher that must wait longer writes again (FastDdsTransport), so
// that it sees the process stopping and Qos::max_blocking in time.
constexpr std::chrono::nanoseconds kWriteWaitSlice = std::chrono::milliseconds(5);

// Samples a reliable keep-all (volatile) writer keeps unacknowledged: its window. The depth of
// such a topic is kept by the readers (to_writer_qos says why).
constexpr int kWriterSamplesInFlight = 32;

// The user data of a reliable writer that is volatile although it announces transient_local
// durability (to_writer_qos says why). Our readers and tools take it for volatile.
constexpr std::string_view kVolatileWriterMark = "mocap:durability=volatile";

eprosima::fastdds::dds::DataWriterQos to_writer_qos(const Qos& qos);
eprosima::fastdds::dds::DataReaderQos to_reader_qos(const Qos& qos);
// The durability a discovered writer offers, `announced` on the wire, with its `user_data`.
Durability offered_durability(Durability announced, const std::vector<uint8_t>& user_data);
// With `options` as with_environment() amends them. Throws std::runtime_error for a bad
// environment variable, security files that are missing, or a server host that does not resolve.
eprosima::fastdds::dds::DomainParticipantQos to_participant_qos(const DdsOptions& options,
                                                                const std::string& name);

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
