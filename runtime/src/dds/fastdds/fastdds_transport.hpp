// Delivery between processes and hosts over Fast DDS, one participant per process.
//
// Topic and type names follow ROS 2 ("rt/a/b", "pkg::msg::dds_::Type_"). Samples written by
// this process are never delivered back to it (the in-process transport already did): Fast
// DDS 2.9 matches a participant's own readers and writers, so readers drop their own
// participant's samples before deserializing them, and writers skip writing volatile samples
// when no reader of another participant is matched.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <mocap/component_host.hpp>

#include "dds/dds_transport.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class Publisher;
class Subscriber;
class Topic;
}  // namespace eprosima::fastdds::dds

namespace mocap {

class FastDdsTransport final : public DdsTransport {
 public:
  // Throws std::runtime_error when the participant cannot be created.
  FastDdsTransport(const DdsOptions& options, const std::string& participant_name);
  ~FastDdsTransport() override;

  std::unique_ptr<TransportPublisher> advertise(const Endpoint& endpoint) override;
  std::unique_ptr<TransportSubscription> subscribe(const Endpoint& endpoint,
                                                   DataNotification on_data) override;
  void stop_waiting() override;

  std::string_view implementation() const override { return "fastdds"; }
  int domain_id() const override { return domain_id_; }
  std::vector<DiscoveredEndpoint> discovered_endpoints() const override;

  class Listener;  // discovery
  class Writer;
  class Reader;

 private:
  friend class Writer;
  friend class Reader;
  struct TopicUse {
    eprosima::fastdds::dds::Topic* topic = nullptr;
    int users = 0;
    // Writers of this process on the topic: only then can its readers see their own samples.
    std::shared_ptr<std::atomic<int>> local_writers = std::make_shared<std::atomic<int>>(0);
  };
  const TopicUse& acquire_topic(const Endpoint& endpoint);
  void release_topic(eprosima::fastdds::dds::Topic* topic);

  int domain_id_;
  std::unique_ptr<Listener> listener_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::mutex mutex_;
  std::map<std::string, TopicUse> topics_;
  std::atomic<bool> stopped_waiting_{false};
};

}  // namespace mocap
