#include "dds/fastdds/fastdds_qos.hpp"

#include <arpa/inet.h>
#include <netdb.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <regex>
#include <stdexcept>

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/common/Locator.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/config.h>
#include <fastrtps/utils/IPLocator.h>
#include <fmt/format.h>

#include "dds/dds_transport.hpp"
#include "dds/writer_backpressure.hpp"

namespace mocap {
namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
namespace fs = std::filesystem;

namespace {

// The IPv4 address of `host`: itself, or what the resolver says.
std::string ipv4_address(const std::string& host) {
  if (rtps::IPLocator::isIPv4(host)) return host;
  addrinfo hints{};
  hints.ai_family = AF_INET;
  addrinfo* found = nullptr;
  if (int error = getaddrinfo(host.c_str(), nullptr, &hints, &found); error != 0) {
    throw std::runtime_error(fmt::format("cannot resolve {}: {}", host, gai_strerror(error)));
  }
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(found->ai_addr)->sin_addr, text, sizeof text);
  freeaddrinfo(found);
  return text;
}

void set_discovery_servers(const std::vector<std::string>& servers,
                           rtps::DiscoverySettings& discovery) {
  // A super client rather than a plain client: the server then tells it about every endpoint,
  // not only those matching its own topics, as multicast discovery does. `mocap_topic list`
  // and `mocap_bag record` depend on that.
  discovery.discoveryProtocol = rtps::DiscoveryProtocol_t::SUPER_CLIENT;
  for (size_t id = 0; id < servers.size(); ++id) {
    std::optional<HostPort> address = parse_host_port(servers[id]);
    if (!address) {
      throw std::runtime_error(fmt::format("discovery server '{}' is not host:port", servers[id]));
    }
    rtps::RemoteServerAttributes server;
    if (!rtps::get_server_client_default_guidPrefix(static_cast<int>(id), server.guidPrefix)) {
      throw std::runtime_error(
          fmt::format("{} discovery servers: more than Fast DDS can number", servers.size()));
    }
    rtps::Locator_t locator;
    try {
      rtps::IPLocator::setIPv4(locator, ipv4_address(address->host));
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(fmt::format("discovery server '{}': {}", servers[id], e.what()));
    }
    locator.port = address->port;
    server.metatrafficUnicastLocatorList.push_back(locator);
    discovery.m_DiscoveryServers.push_back(server);
  }
}

// Fast DDS's builtin plugins: PKI-DH authentication, permissions, AES-GCM-GMAC encryption.
void set_security(const fs::path& directory, const std::string& identity,
                  dds::PropertyPolicyQos& properties) {
  fs::path absolute = fs::absolute(directory).lexically_normal();
  if (auto problem = check_security(absolute, identity)) {
    throw std::runtime_error(fmt::format("DDS Security: {}", problem->message));
  }
  SecurityFiles files = security_files(absolute, identity);
  if (auto problem = fastdds_governance_problem(files.governance)) {
    throw std::runtime_error(fmt::format("DDS Security: {}", *problem));
  }
  auto uri = [](const fs::path& path) { return "file://" + path.string(); };
  auto& list = properties.properties();
  list.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  list.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", uri(files.ca));
  list.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", uri(files.certificate));
  list.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", uri(files.private_key));
  list.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  list.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", uri(files.ca));
  list.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", uri(files.governance));
  list.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions",
                    uri(files.permissions));
  list.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

template <class EndpointQos>
void apply(const Qos& qos, EndpointQos& out) {
  out.reliability().kind = qos.reliability == Reliability::Reliable
                               ? dds::RELIABLE_RELIABILITY_QOS
                               : dds::BEST_EFFORT_RELIABILITY_QOS;
  out.reliability().max_blocking_time = {0, static_cast<uint32_t>(kWriteWaitSlice.count())};
  out.durability().kind = qos.durability == Durability::TransientLocal
                              ? dds::TRANSIENT_LOCAL_DURABILITY_QOS
                              : dds::VOLATILE_DURABILITY_QOS;
  if (qos.history == History::KeepLast) {
    out.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    out.history().depth = qos.depth;
  } else {
    out.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    out.history().depth = qos.depth;
    out.resource_limits().max_samples = qos.depth;
    out.resource_limits().max_instances = 1;
    out.resource_limits().max_samples_per_instance = qos.depth;
  }
  out.resource_limits().allocated_samples = std::min(qos.depth, 32);
  // Message sizes are unbounded: payloads start small and grow to what the topic carries.
  out.endpoint().history_memory_policy =
      eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  out.data_sharing().off();
}

}  // namespace

std::optional<std::string> fastdds_governance_problem(const fs::path& governance) {
#if FASTRTPS_VERSION_MAJOR > 2 || (FASTRTPS_VERSION_MAJOR == 2 && FASTRTPS_VERSION_MINOR > 10) || \
    (FASTRTPS_VERSION_MAJOR == 2 && FASTRTPS_VERSION_MINOR == 10 && FASTRTPS_VERSION_MICRO >= 3)
  (void)governance;
  return std::nullopt;  // fixed in Fast DDS 2.10.3
#else
  std::ifstream in(governance);
  if (!in) return std::nullopt;
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  static const std::regex kSetting(
      R"(<rtps_protection_kind>\s*([A-Za-z_]+)\s*</rtps_protection_kind>)");
  for (auto match = std::sregex_iterator(text.begin(), text.end(), kSetting);
       match != std::sregex_iterator(); ++match) {
    const std::string kind = (*match)[1].str();
    if (kind == "NONE") continue;
    const auto line = 1 + std::count(text.begin(), text.begin() + match->position(0), '\n');
    return fmt::format(
        "{}:{}: rtps_protection_kind {} would make Fast DDS {}.{}.{} abort when a protected "
        "message outgrows its buffer (fixed in 2.10.3); set it to NONE and protect each "
        "submessage with metadata_protection_kind and data_protection_kind ENCRYPT, as "
        "scripts/make_security.sh does",
        governance.string(), line, kind, FASTRTPS_VERSION_MAJOR, FASTRTPS_VERSION_MINOR,
        FASTRTPS_VERSION_MICRO);
  }
  return std::nullopt;
#endif
}

dds::DataWriterQos to_writer_qos(const Qos& qos) {
  dds::DataWriterQos out;
  apply(qos, out);
  // A sample lost in transit is repaired when the reader answers a heartbeat. Fast DDS's
  // default period, 3 s, would hold a waiting publisher up that long after a loss; heartbeats
  // are only sent while samples are unacknowledged, so a short period costs nothing when idle.
  out.reliable_writer_qos().times.heartbeatPeriod = {0, 25000000u};
  if (qos.history == History::KeepAll && qos.durability == Durability::Volatile) {
    // The samples a subscriber may fall behind wait in its reader's history (`depth`); the
    // writer keeps only those in flight. A reader whose history is full rejects what arrives
    // and asks for it again at every heartbeat, and the writer sends again all it holds: with
    // the whole depth in the writer too, a subscriber slower than its publisher costs both
    // processes about twice the CPU time in resends (bench/backpressure_bench).
    int in_flight = std::min(qos.depth, kWriterSamplesInFlight);
    out.history().depth = in_flight;
    out.resource_limits().max_samples = in_flight;
    out.resource_limits().max_samples_per_instance = in_flight;
  }
  if (qos.reliability == Reliability::Reliable && qos.durability == Durability::Volatile) {
    // Fast DDS 2.9.1 can deadlock a volatile reliable writer when a reader leaves while samples
    // wait to be sent to it again (as a slow subscriber's always do): the writer then removes
    // the samples every remaining reader has, holding its locator-selector locks while it takes
    // the flow controller's, whose thread holds the flow controller's lock while it takes a
    // locator selector's (eProsima/Fast-DDS#5432, fixed in later releases). Only a volatile
    // writer removes samples there; a transient-local one keeps them until its history needs
    // the room, and then removes one while it writes, without those locks. So the writer is
    // transient-local on the wire: a volatile reader still gets only what is written after it
    // joins (Fast DDS sends it a gap for the history), and the mark tells our transient-local
    // readers and tools that the publisher is volatile.
    out.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    out.user_data().setValue(
        std::vector<uint8_t>(kVolatileWriterMark.begin(), kVolatileWriterMark.end()));
  }
  return out;
}

dds::DataReaderQos to_reader_qos(const Qos& qos) {
  dds::DataReaderQos out;
  apply(qos, out);
  // Acknowledge at once: a writer with few samples in flight waits for each acknowledgement,
  // and Fast DDS's default 5 ms delay would cap a stream at kWriterSamplesInFlight per 5 ms.
  out.reliable_reader_qos().times.heartbeatResponseDelay = {0, 0u};
  return out;
}

dds::DomainParticipantQos to_participant_qos(const DdsOptions& given, const std::string& name) {
  DdsOptions options = with_environment(given);
  dds::DomainParticipantQos out;
  out.name(name);
  // A crashed peer is forgotten after 5 s instead of Fast DDS's 20 s: until then a reliable
  // publisher keeps samples for it and may wait on it.
  auto& discovery = out.wire_protocol().builtin.discovery_config;
  discovery.leaseDuration = {5, 0};
  discovery.leaseDuration_announcementperiod = {1, 0};
  if (!options.discovery_servers.empty()) {
    set_discovery_servers(options.discovery_servers, discovery);
  }
  if (!options.security_directory.empty()) {
    set_security(options.security_directory, options.security_identity, out.properties());
  }
  out.transport().use_builtin_transports = false;
  if (options.shared_memory) {
    // Fast DDS's default 512 KiB segment cannot hold a camera image, which then goes over
    // UDP in fragments: 20 times slower for 1280x720 mono8 (bench/transport_bench).
    auto shared_memory = std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>();
    shared_memory->segment_size(kSharedMemorySegmentBytes);
    out.transport().user_transports.push_back(shared_memory);
  }
  // Fast DDS otherwise keeps the system's default socket buffers (dds_transport.hpp says why
  // that is too small).
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->receiveBufferSize = kUdpSocketBufferBytes;
  udp->sendBufferSize = kUdpSocketBufferBytes;
  out.transport().user_transports.push_back(udp);
  return out;
}

}  // namespace mocap
