// Delivery between processes and hosts over Eclipse Cyclone DDS, one participant per process:
// the same wire, QoS and semantics as FastDdsTransport, so either can carry any group of a
// graph, and processes on the two exchange every message.
//
// Samples written by this process are never delivered back to it (the in-process transport
// already did): readers and writers ignore their own participant's (Cyclone's ignore_local).
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <dds/dds.h>

#include "dds/dds_transport.hpp"

namespace mocap {

class CycloneDdsTransport final : public DdsTransport {
 public:
  // Throws std::runtime_error when the domain or the participant cannot be created.
  CycloneDdsTransport(const DdsOptions& options, const std::string& participant_name);
  ~CycloneDdsTransport() override;

  std::unique_ptr<TransportPublisher> advertise(const Endpoint& endpoint) override;
  std::unique_ptr<TransportSubscription> subscribe(const Endpoint& endpoint,
                                                   DataNotification on_data) override;
  void stop_waiting() override;

  std::string_view implementation() const override { return "cyclonedds"; }
  int domain_id() const override { return domain_id_; }
  std::vector<DiscoveredEndpoint> discovered_endpoints() const override;

  class Domain;
  class Writer;
  class Reader;

 private:
  friend class Writer;
  friend class Reader;
  // A topic entity for `endpoint`; throws when this process uses the topic with another type.
  dds_entity_t create_topic(const Endpoint& endpoint);
  void delete_topic(const Endpoint& endpoint, dds_entity_t topic);
  // Why creating an endpoint to `action` ("publish") a topic failed with `error`.
  std::string access_hint(std::string_view action, dds_return_t error) const;
  // The name participant `key` announced, or its GUID while it is not known.
  std::string participant_name(const dds_guid_t& key) const;

  int domain_id_;
  std::shared_ptr<Domain> domain_;
  dds_entity_t participant_ = 0;
  bool secure_ = false;
  dds_guid_t own_guid_{};
  dds_entity_t participants_ = 0;  // readers of the builtin discovery topics
  dds_entity_t publications_ = 0;
  dds_entity_t subscriptions_ = 0;
  std::mutex mutex_;
  std::map<std::string, std::pair<std::string, int>> topic_types_;  // DDS name -> type, users
  std::atomic<bool> stopped_waiting_{false};
};

}  // namespace mocap
