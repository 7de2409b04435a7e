// Our QoS and host options in Cyclone DDS's terms, as FastDdsTransport sets them
// (fastdds_qos.hpp). Shared by the transport and the benchmark's raw Cyclone DDS reference.
#pragma once

#include <string>

#include <dds/dds.h>

#include <mocap/component_host.hpp>
#include <mocap/qos.hpp>

namespace mocap {

// Owns a dds_qos_t.
struct QosHandle {
  QosHandle() : qos(dds_create_qos()) {}
  ~QosHandle() { dds_delete_qos(qos); }
  QosHandle(const QosHandle&) = delete;
  QosHandle& operator=(const QosHandle&) = delete;
  dds_qos_t* qos;
};

void to_cyclone_reader_qos(const Qos& qos, dds_qos_t* out);
void to_cyclone_writer_qos(const Qos& qos, dds_qos_t* out);
// What a discovered reader or writer announces, as our QoS (history is not announced).
Qos qos_from_cyclone(const dds_qos_t* qos);

// Cyclone's configuration (CYCLONEDDS_URI's XML) for `options`: the same discovery lease as
// Fast DDS's, the same socket buffers and fragment size, and DDS Security from the same files.
// Throws std::runtime_error when the security files do not check.
std::string domain_configuration(const DdsOptions& options);

}  // namespace mocap
