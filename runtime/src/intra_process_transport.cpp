#include "intra_process_transport.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap {

// A subscription's queue. Shared, so that a publisher can fill it (and wait for room)
// without holding the transport's lock, even while the subscription goes away.
class IntraProcessTransport::Queue {
 public:
  Queue(const Endpoint& endpoint, DataNotification on_data)
      : endpoint_(endpoint),
        on_data_(std::move(on_data)),
        drops_(endpoint, "in-process subscriber") {}

  const Endpoint& endpoint() const { return endpoint_; }

  bool take(ReceivedMessage& out) {
    {
      std::lock_guard lock(mutex_);
      if (messages_.empty()) return false;
      out = std::move(messages_.front());
      messages_.pop_front();
    }
    room_.notify_one();
    return true;
  }

  // Keep last: the oldest sample makes room. Keep all: the publisher waits for room, as a
  // reliable DDS writer does, and drops the sample if none comes in time.
  void push(const ReceivedMessage& message) {
    {
      std::unique_lock lock(mutex_);
      if (closed_) return;
      size_t depth = static_cast<size_t>(endpoint_.qos.depth);
      if (messages_.size() >= depth) {
        if (endpoint_.qos.history == History::KeepLast) {
          messages_.pop_front();
          drops_.count(1, "the subscriber is slower than the publisher (keep_last queue full)");
        } else if (!room_.wait_for(lock, std::chrono::milliseconds(kReliableBlockingMilliseconds),
                                   [&] { return closed_ || messages_.size() < depth; })) {
          drops_.count(1, fmt::format("the subscriber is {} samples behind and did not catch up "
                                      "within {} ms",
                                      messages_.size(), kReliableBlockingMilliseconds));
          return;
        }
        if (closed_) return;
      }
      messages_.push_back(message);
    }
    // Publishing runs no subscriber code: the subscriber's callbacks run elsewhere.
    on_data_(false);
  }

  // The subscription is gone: publishers stop waiting and delivering.
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
      messages_.clear();
    }
    room_.notify_all();
  }

 private:
  Endpoint endpoint_;
  DataNotification on_data_;
  std::mutex mutex_;
  std::condition_variable room_;
  std::deque<ReceivedMessage> messages_;
  bool closed_ = false;
  DropReport drops_;
};

class IntraProcessTransport::Subscription final : public TransportSubscription {
 public:
  Subscription(IntraProcessTransport& transport, std::shared_ptr<Queue> queue)
      : transport_(transport), queue_(std::move(queue)) {}
  ~Subscription() override {
    queue_->close();
    transport_.remove(queue_);
  }
  bool take(ReceivedMessage& out) override { return queue_->take(out); }

 private:
  IntraProcessTransport& transport_;
  std::shared_ptr<Queue> queue_;
};

class IntraProcessTransport::Publisher final : public TransportPublisher {
 public:
  Publisher(IntraProcessTransport& transport, const Endpoint& endpoint)
      : transport_(transport), endpoint_(endpoint) {}

  ~Publisher() override { transport_.remove(this); }

  void publish(const std::shared_ptr<const void>& message, Clock::time_point now) override {
    ReceivedMessage sample{message, now};
    std::vector<std::shared_ptr<Queue>> matched;
    {
      std::shared_lock lock(transport_.mutex_);
      matched = matched_;
      // Under the same lock as the snapshot: a subscription connecting now gets the sample
      // exactly once, either from the snapshot or from the history.
      if (endpoint_.qos.durability == Durability::TransientLocal) {
        std::lock_guard history_lock(history_mutex_);
        history_.push_back(sample);
        while (history_.size() > static_cast<size_t>(endpoint_.qos.depth)) history_.pop_front();
      }
    }
    for (const auto& queue : matched) queue->push(sample);
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
  std::vector<std::shared_ptr<Queue>> matched_;  // guarded by transport_.mutex_
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

void IntraProcessTransport::connect(Publisher& publisher,
                                    const std::shared_ptr<Queue>& subscription) {
  const Endpoint& offered = publisher.endpoint();
  const Endpoint& requested = subscription->endpoint();
  if (auto why = qos_mismatch(offered.qos, requested.qos)) {
    Logger(requested.owner)
        .warn("{}: not connected to the publisher in '{}': {}", requested.topic, offered.owner,
              *why);
    return;
  }
  publisher.matched_.push_back(subscription);
  if (requested.qos.durability == Durability::TransientLocal) {
    std::lock_guard history_lock(publisher.history_mutex_);
    for (const ReceivedMessage& sample : publisher.history_) subscription->push(sample);
  }
}

std::unique_ptr<TransportPublisher> IntraProcessTransport::advertise(const Endpoint& endpoint) {
  std::unique_lock lock(mutex_);
  Topic& topic = topic_for(endpoint);
  auto publisher = std::make_unique<Publisher>(*this, endpoint);
  for (const auto& subscription : topic.subscriptions) connect(*publisher, subscription);
  topic.publishers.push_back(publisher.get());
  return publisher;
}

std::unique_ptr<TransportSubscription> IntraProcessTransport::subscribe(const Endpoint& endpoint,
                                                                        DataNotification on_data) {
  std::unique_lock lock(mutex_);
  Topic& topic = topic_for(endpoint);
  auto queue = std::make_shared<Queue>(endpoint, std::move(on_data));
  for (Publisher* publisher : topic.publishers) connect(*publisher, queue);
  topic.subscriptions.push_back(queue);
  return std::make_unique<Subscription>(*this, std::move(queue));
}

void IntraProcessTransport::remove(Publisher* publisher) {
  std::unique_lock lock(mutex_);
  auto it = topics_.find(publisher->endpoint().topic);
  if (it != topics_.end()) std::erase(it->second.publishers, publisher);
}

void IntraProcessTransport::remove(const std::shared_ptr<Queue>& subscription) {
  std::unique_lock lock(mutex_);
  auto it = topics_.find(subscription->endpoint().topic);
  if (it == topics_.end()) return;
  std::erase(it->second.subscriptions, subscription);
  for (Publisher* publisher : it->second.publishers) std::erase(publisher->matched_, subscription);
}

}  // namespace mocap
