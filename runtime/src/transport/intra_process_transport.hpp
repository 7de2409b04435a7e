// Delivery between components of one process: the publisher's shared pointer itself, no copy
// and no serialization, with the same QoS rules as DDS (including transient local and the
// wait of a reliable keep-all publisher for a subscriber without room).
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <vector>

#include "transport/transport.hpp"

namespace mocap {

class IntraProcessTransport final : public Transport {
 public:
  class Publisher;
  class Subscription;
  class Queue;

  IntraProcessTransport() = default;
  ~IntraProcessTransport() override;

  // Throws std::invalid_argument when the topic already carries another type.
  std::unique_ptr<TransportPublisher> advertise(const Endpoint& endpoint) override;
  std::unique_ptr<TransportSubscription> subscribe(const Endpoint& endpoint,
                                                   DataNotification on_data) override;
  void stop_waiting() override;

 private:
  struct Topic {
    const MessageType* type = nullptr;
    std::string first_user;
    std::vector<Publisher*> publishers;
    std::vector<std::shared_ptr<Queue>> subscriptions;
  };

  Topic& topic_for(const Endpoint& endpoint);  // requires the exclusive lock
  void connect(Publisher& publisher, const std::shared_ptr<Queue>& subscription);
  void remove(Publisher* publisher);
  void remove(const std::shared_ptr<Queue>& subscription);

  // Components that wait for one another's room, to see a wait that could never end coming:
  // `publisher` waiting for `subscriber` when `subscriber` already waits, directly or through
  // others, for `publisher`. Returns false (and records nothing) for such a cycle.
  bool begin_wait(const std::string& publisher, const std::string& subscriber);
  void end_wait(const std::string& publisher, const std::string& subscriber);

  // Guards the topics and who is connected to whom; never held while a publisher waits.
  std::shared_mutex mutex_;
  std::map<std::string, Topic, std::less<>> topics_;
  std::atomic<bool> stopped_waiting_{false};
  std::mutex waits_mutex_;
  std::multimap<std::string, std::string> waiting_for_;  // publisher -> subscriber
};

}  // namespace mocap
