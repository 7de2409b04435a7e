// Delivery between components of one process: the publisher's shared pointer itself, no copy
// and no serialization, with the same QoS rules as DDS (including transient local).
#pragma once

#include <deque>
#include <map>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <vector>

#include "transport.hpp"

namespace mocap {

class IntraProcessTransport final : public Transport {
 public:
  class Publisher;
  class Subscription;

  IntraProcessTransport() = default;
  ~IntraProcessTransport() override;

  // Throws std::invalid_argument when the topic already carries another type.
  std::unique_ptr<TransportPublisher> advertise(const Endpoint& endpoint) override;
  std::unique_ptr<TransportSubscription> subscribe(const Endpoint& endpoint,
                                                   std::function<void()> on_data) override;

 private:
  struct Topic {
    const MessageType* type = nullptr;
    std::string first_user;
    std::vector<Publisher*> publishers;
    std::vector<Subscription*> subscriptions;
  };

  Topic& topic_for(const Endpoint& endpoint);  // requires the exclusive lock
  void connect(Publisher& publisher, Subscription& subscription);
  void remove(Publisher* publisher);
  void remove(Subscription* subscription);

  // Shared by publish(); exclusive while endpoints come and go.
  std::shared_mutex mutex_;
  std::map<std::string, Topic, std::less<>> topics_;
};

}  // namespace mocap
