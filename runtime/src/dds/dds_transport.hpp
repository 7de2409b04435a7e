// Delivery between processes and hosts over DDS, whichever implementation carries it: the
// interface the host, tools and benchmarks use, and the choice of implementation.
//
// Every implementation puts the same wire on the network: topics "rt/a/b", types
// "pkg::msg::dds_::Type_", XCDR1 data, the runtime's QoS. So processes on different
// implementations in one graph exchange every message both ways.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/component_host.hpp>

#include "transport/transport.hpp"

namespace mocap {

// A reader or writer of another participant, as discovery reports it.
struct DiscoveredEndpoint {
  std::string topic;  // ROS name when the DDS name is a ROS one ("rt/a" -> "/a")
  std::string type;   // DDS type name
  bool is_publisher = false;
  Qos qos;  // reliability and durability as announced; history is not announced
  std::string participant;
};

class DdsTransport : public Transport {
 public:
  // Its name in the table of implementations (DdsImplementation::name).
  virtual std::string_view implementation() const = 0;
  virtual int domain_id() const = 0;
  // Endpoints of other participants seen so far (alive ones only).
  virtual std::vector<DiscoveredEndpoint> discovered_endpoints() const = 0;
};

// MOCAP_DOMAIN_ID if set (validated), otherwise `configured`.
int resolve_domain_id(int configured);

// The UDP socket buffers, sending and receiving, both implementations ask for. A 1280x720 mono8
// image is 0.9 MB that leave in one burst of fragments: with Linux's default 208 KiB the
// receiver's buffer overflows and each image waits for repairs (Fast DDS to Fast DDS over UDP:
// 16.6 ms median at 100 Hz; with 4 MiB, 0.51 ms; security_bench).
constexpr uint32_t kUdpSocketBufferBytes = 4 * 1024 * 1024;

// Why this machine gives smaller buffers than kUdpSocketBufferBytes (the kernel caps a
// socket's buffers at net.core.rmem_max and wmem_max, read from `sysctl_directory`), with the
// command that lifts the cap; nullopt when it does not.
std::optional<std::string> udp_buffer_problem(
    const std::filesystem::path& sysctl_directory = "/proc/sys/net/core");

}  // namespace mocap
