#include "fastdds_qos.hpp"

#include <memory>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

namespace mocap {
namespace dds = eprosima::fastdds::dds;

namespace {

template <class EndpointQos>
void apply(const Qos& qos, EndpointQos& out) {
  out.reliability().kind = qos.reliability == Reliability::Reliable
                               ? dds::RELIABLE_RELIABILITY_QOS
                               : dds::BEST_EFFORT_RELIABILITY_QOS;
  out.reliability().max_blocking_time = {0, kReliableBlockingMilliseconds * 1000000u};
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

dds::DataWriterQos to_writer_qos(const Qos& qos) {
  dds::DataWriterQos out;
  apply(qos, out);
  // A sample lost in transit is repaired when the reader answers a heartbeat. Fast DDS's
  // default period, 3 s, would outlast a reliable publisher's wait for room; heartbeats are
  // only sent while samples are unacknowledged, so a short period costs nothing when idle.
  out.reliable_writer_qos().times.heartbeatPeriod = {0, 25000000u};
  return out;
}

dds::DataReaderQos to_reader_qos(const Qos& qos) {
  dds::DataReaderQos out;
  apply(qos, out);
  return out;
}

dds::DomainParticipantQos to_participant_qos(const DdsOptions& options, const std::string& name) {
  dds::DomainParticipantQos out;
  out.name(name);
  // A crashed peer is forgotten after 5 s instead of Fast DDS's 20 s: until then a reliable
  // publisher keeps samples for it and may wait on it.
  auto& discovery = out.wire_protocol().builtin.discovery_config;
  discovery.leaseDuration = {5, 0};
  discovery.leaseDuration_announcementperiod = {1, 0};
  out.transport().use_builtin_transports = false;
  if (options.shared_memory) {
    // Fast DDS's default 512 KiB segment cannot hold a camera image, which then goes over
    // UDP in fragments: 20 times slower for 1280x720 mono8 (bench/transport_bench).
    auto shared_memory = std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>();
    shared_memory->segment_size(kSharedMemorySegmentBytes);
    out.transport().user_transports.push_back(shared_memory);
  }
  out.transport().user_transports.push_back(
      std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
  return out;
}

}  // namespace mocap
