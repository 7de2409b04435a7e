// Our QoS and host options as Fast DDS QoS. Shared by the transport and the benchmark's raw
// Fast DDS reference, so both run with the very same settings.
#pragma once

#include <cstdint>
#include <string>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include <mocap/component_host.hpp>
#include <mocap/qos.hpp>

#include "dds_options.hpp"

namespace mocap {

// Shared memory of each participant for messages to processes on the same host.
constexpr uint32_t kSharedMemorySegmentBytes = 8 * 1024 * 1024;

// Samples a reliable keep-all (volatile) writer keeps unacknowledged: its window. The depth of
// such a topic is kept by the readers (to_writer_qos says why).
constexpr int kWriterSamplesInFlight = 32;

eprosima::fastdds::dds::DataWriterQos to_writer_qos(const Qos& qos);
eprosima::fastdds::dds::DataReaderQos to_reader_qos(const Qos& qos);
// With `options` as with_environment() amends them. Throws std::runtime_error for a bad
// environment variable, security files that are missing, or a server host that does not resolve.
eprosima::fastdds::dds::DomainParticipantQos to_participant_qos(const DdsOptions& options,
                                                                const std::string& name);

}  // namespace mocap
