// Our QoS and host options as Fast DDS QoS. Shared by the transport and the benchmark's raw
// Fast DDS reference, so both run with the very same settings.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include <mocap/component_host.hpp>
#include <mocap/qos.hpp>

#include "dds/dds_options.hpp"

namespace mocap {

// Shared memory of each participant for messages to processes on the same host.
constexpr uint32_t kSharedMemorySegmentBytes = 8 * 1024 * 1024;

// Samples a reliable keep-all (volatile) writer keeps unacknowledged: its window. The depth of
// such a topic is kept by the readers (to_writer_qos says why).
constexpr int kWriterSamplesInFlight = 32;

// Why this Fast DDS cannot take the signed governance `governance` (a governance.smime in clear
// text), or nullopt: "PATH:LINE: rtps_protection_kind ENCRYPT ...". Fast DDS before 2.10.3
// aborts when a whole RTPS message it protects (rtps_protection_kind ENCRYPT or SIGN) outgrows
// the room it kept (`add_statistics_submessage: Assertion ... failed`); protecting each
// submessage (metadata_ and data_protection_kind) encrypts as much and is safe. A file that
// cannot be read gets nullopt: check_security names it.
std::optional<std::string> fastdds_governance_problem(const std::filesystem::path& governance);

eprosima::fastdds::dds::DataWriterQos to_writer_qos(const Qos& qos);
eprosima::fastdds::dds::DataReaderQos to_reader_qos(const Qos& qos);
// With `options` as with_environment() amends them. Throws std::runtime_error for a bad
// environment variable, security files that are missing, or a server host that does not resolve.
eprosima::fastdds::dds::DomainParticipantQos to_participant_qos(const DdsOptions& options,
                                                                const std::string& name);

}  // namespace mocap
