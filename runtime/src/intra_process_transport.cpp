#include "intra_process_transport.hpp"

#include <algorithm>
#include <condition_variable>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap {

class IntraProcessTransport::Subscription final : public TransportSubscription {
 public:
  Subscription(IntraProcessTransport& transport, const Endpoint& endpoint,
               std::function<void()> on_data)
      : transport_(transport),
        endpoint_(endpoint),
        on_data_(std::move(on_data)),
        drops_(endpoint, "in-process subscriber") {}

  ~Subscription() override { transport_.remove(this); }

  bool take(ReceivedMessage& out) override {
    {
      std::lock_guard lock(mutex_);
      if (queue_.empty()) return false;
      out = std::move(queue_.front());
      queue_.pop_front();
    }
    room_.notify_one();
    return true;
  }

  // Keep last: the oldest sample makes room. Keep all: the publisher waits for room, as a
  // reliable DDS writer does, and drops the sample if none comes in time.
  void push(const ReceivedMessage& message) {
    {
      std::unique_lock lock(mutex_);
      size_t depth = static_cast<size_t>(endpoint_.qos.depth);
      if (queue_.size() >= depth) {
        if (endpoint_.qos.history == History::KeepLast) {
          queue_.pop_front();
          drops_.count(1, "the subscriber is slower than the publisher (keep_last queue full)");
        } else if (!room_.wait_for(lock, std::chrono::milliseconds(kReliableBlockingMilliseconds),
                                   [&] { return queue_.size() < depth; })) {
          drops_.count(1, fmt::format("the subscriber is {} samples behind and did not catch up "
                                      "within {} ms",
                                      queue_.size(), kReliableBlockingMilliseconds));
          return;
        }
      }
      queue_.push_back(message);
    }
    on_data_();
  }

  const Endpoint& endpoint() const { return endpoint_; }

 private:
  IntraProcessTransport& transport_;
  Endpoint endpoint_;
  std::function<void()> on_data_;
  std::mutex mutex_;
  std::condition_variable room_;
  std::deque<ReceivedMessage> queue_;
  DropReport drops_;
};

class IntraProcessTransport::Publisher final : public TransportPublisher {
 public:
  Publisher(IntraProcessTransport& transport, const Endpoint& endpoint)
      : transport_(transport), endpoint_(endpoint) {}

  ~Publisher() override { transport_.remove(this); }

  void publish(const std::shared_ptr<const void>& message, Clock::time_point now) override {
    ReceivedMessage sample{message, now};
    std::shared_lock lock(transport_.mutex_);
    for (Subscription* subscription : matched_) subscription->push(sample);
    // Under the same lock as delivery, so a subscription connecting now gets the sample
    // exactly once: either delivered above or from the history.
    if (endpoint_.qos.durability == Durability::TransientLocal) {
      std::lock_guard history_lock(history_mutex_);
      history_.push_back(std::move(sample));
      while (history_.size() > static_cast<size_t>(endpoint_.qos.depth)) history_.pop_front();
    }
  }

  size_t matched_subscribers() const override {
    std::shared_lock lock(transport_.mutex_);
    return matched_.size();
  }

  const Endpoint& endpoint() const { return endpoint_; }

 private:
  friend class IntraProcessTransport;
  IntraProcessTransport& transport_;
  Endpoint endpoint_;
  std::vector<Subscription*> matched_;  // guarded by transport_.mutex_
  std::mutex history_mutex_;
  std::deque<ReceivedMessage> history_;
};

IntraProcessTransport::~IntraProcessTransport() = default;

IntraProcessTransport::Topic& IntraProcessTransport::topic_for(const Endpoint& endpoint) {
  Topic& topic = topics_[endpoint.topic];
  if (topic.type == nullptr) {
    topic.type = endpoint.type;
    topic.first_user = endpoint.owner;
  } else if (topic.type != endpoint.type) {
    throw std::invalid_argument(fmt::format(
        "topic '{}' carries {} (as used by '{}'), but '{}' uses it with {}", endpoint.topic,
        topic.type->name(), topic.first_user, endpoint.owner, endpoint.type->name()));
  }
  return topic;
}

void IntraProcessTransport::connect(Publisher& publisher, Subscription& subscription) {
  const Endpoint& offered = publisher.endpoint();
  const Endpoint& requested = subscription.endpoint();
  if (auto why = qos_mismatch(offered.qos, requested.qos)) {
    Logger(requested.owner)
        .warn("{}: not connected to the publisher in '{}': {}", requested.topic, offered.owner,
              *why);
    return;
  }
  publisher.matched_.push_back(&subscription);
  if (requested.qos.durability == Durability::TransientLocal) {
    std::lock_guard history_lock(publisher.history_mutex_);
    for (const ReceivedMessage& sample : publisher.history_) subscription.push(sample);
  }
}

std::unique_ptr<TransportPublisher> IntraProcessTransport::advertise(const Endpoint& endpoint) {
  std::unique_lock lock(mutex_);
  Topic& topic = topic_for(endpoint);
  auto publisher = std::make_unique<Publisher>(*this, endpoint);
  for (Subscription* subscription : topic.subscriptions) connect(*publisher, *subscription);
  topic.publishers.push_back(publisher.get());
  return publisher;
}

std::unique_ptr<TransportSubscription> IntraProcessTransport::subscribe(
    const Endpoint& endpoint, std::function<void()> on_data) {
  std::unique_lock lock(mutex_);
  Topic& topic = topic_for(endpoint);
  auto subscription = std::make_unique<Subscription>(*this, endpoint, std::move(on_data));
  for (Publisher* publisher : topic.publishers) connect(*publisher, *subscription);
  topic.subscriptions.push_back(subscription.get());
  return subscription;
}

void IntraProcessTransport::remove(Publisher* publisher) {
  std::unique_lock lock(mutex_);
  auto it = topics_.find(publisher->endpoint().topic);
  if (it == topics_.end()) return;
  std::erase(it->second.publishers, publisher);
}

void IntraProcessTransport::remove(Subscription* subscription) {
  std::unique_lock lock(mutex_);
  auto it = topics_.find(subscription->endpoint().topic);
  if (it == topics_.end()) return;
  std::erase(it->second.subscriptions, subscription);
  for (Publisher* publisher : it->second.publishers) std::erase(publisher->matched_, subscription);
}

}  // namespace mocap
