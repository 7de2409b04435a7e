#include "transport/intra_process_transport.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <stdexcept>

#include <fmt/format.h>

#include "core/executor.hpp"

namespace mocap {

// A subscription's queue. Shared, so that a publisher can fill it (and wait for room)
// without holding the transport's lock, even while the subscription goes away.
class IntraProcessTransport::Queue {
 public:
  Queue(IntraProcessTransport& transport, const Endpoint& endpoint, DataNotification on_data)
      : transport_(transport),
        endpoint_(endpoint),
        on_data_(std::move(on_data)),
        drops_(endpoint, "in-process subscriber") {}

  const Endpoint& endpoint() const { return endpoint_; }
  uint64_t dropped() const { return drops_.total(); }
  size_t waiting() const {
    std::lock_guard lock(mutex_);
    return messages_.size();
  }

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

  // When the queue is full: keep last (on either side) drops the oldest sample; reliable keep
  // all waits for room as long as the subscription exists (or Qos::max_blocking), as a
  // reliable DDS writer waits for acknowledgements. `wait` false: never waits, the queue
  // grows instead (a late joiner's transient-local history).
  void push(const ReceivedMessage& message, const Endpoint& publisher, PublisherReport& report,
            bool wait = true) {
    {
      std::unique_lock lock(mutex_);
      if (closed_) return;
      if (full()) {
        if (!publisher_may_wait(publisher.qos, endpoint_.qos)) {
          messages_.pop_front();
          drops_.count(1, "the subscriber is slower than the publisher (keep_last queue full)");
        } else if (wait && !wait_for_room(lock, publisher, report)) {
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

  // Publishers waiting here look again at IntraProcessTransport::stopped_waiting_.
  void wake_publishers() {
    { std::lock_guard lock(mutex_); }  // a publisher between its check and its wait is waiting
    room_.notify_all();
  }

 private:
  bool full() const { return messages_.size() >= static_cast<size_t>(endpoint_.qos.depth); }

  // Returns true when there is room (or the subscription closed), false when the sample is
  // dropped for this subscriber (counted).
  bool wait_for_room(std::unique_lock<std::mutex>& lock, const Endpoint& publisher,
                     PublisherReport& report) {
    const std::string& subscriber = endpoint_.owner;
    auto stopping = [&] {
      report.count_drop(1, fmt::format("the process is stopping and subscriber '{}' in this "
                                       "process has no room",
                                       subscriber));
      return false;
    };
    if (transport_.stopped_waiting_.load()) return stopping();
    if (!transport_.begin_wait(publisher.owner, subscriber)) {
      // Waiting would never end: the subscriber waits, perhaps through others, for this very
      // publisher (a component subscribed to its own output, or a cycle of full queues).
      // The queue takes the sample beyond its depth instead; nothing is lost.
      if (overfilled_.count()) {
        Logger(publisher.owner)
            .warn(
                "{}: the subscriber '{}' waits for this publisher itself; its queue of {} "
                "takes more instead of the publisher waiting ({} time(s) so far)",
                endpoint_.topic, subscriber, endpoint_.qos.depth, overfilled_.total());
      }
      return true;
    }
    auto start = std::chrono::steady_clock::now();
    auto ready = [&] { return closed_ || !full() || transport_.stopped_waiting_.load(); };
    bool in_time = true;
    {
      WaitingScope waiting;
      if (publisher.qos.max_blocking) {
        in_time = room_.wait_for(lock, *publisher.qos.max_blocking, ready);
      } else {
        room_.wait(lock, ready);
      }
    }
    transport_.end_wait(publisher.owner, subscriber);
    report.count_wait(std::chrono::steady_clock::now() - start,
                      fmt::format("subscriber '{}' in this process", subscriber));
    if (closed_ || !full()) return true;
    if (!in_time) {
      report.count_drop(1, fmt::format("subscriber '{}' in this process had no room for "
                                       "max_blocking {} ms",
                                       subscriber, publisher.qos.max_blocking->count()));
      return false;
    }
    return stopping();
  }

  IntraProcessTransport& transport_;
  Endpoint endpoint_;
  DataNotification on_data_;
  mutable std::mutex mutex_;
  std::condition_variable room_;
  std::deque<ReceivedMessage> messages_;
  bool closed_ = false;
  DropReport drops_;
  Throttle overfilled_;
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
  uint64_t dropped() const override { return queue_->dropped(); }
  std::optional<size_t> waiting() const override { return queue_->waiting(); }

 private:
  IntraProcessTransport& transport_;
  std::shared_ptr<Queue> queue_;
};

class IntraProcessTransport::Publisher final : public TransportPublisher {
 public:
  Publisher(IntraProcessTransport& transport, const Endpoint& endpoint)
      : transport_(transport), endpoint_(endpoint), report_(endpoint) {}

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
    for (const auto& queue : matched) queue->push(sample, endpoint_, report_);
  }

  size_t matched_subscribers() const override {
    std::shared_lock lock(transport_.mutex_);
    return matched_.size();
  }

  PublisherStats stats() const override { return report_.stats(); }

  const Endpoint& endpoint() const { return endpoint_; }

 private:
  friend class IntraProcessTransport;
  IntraProcessTransport& transport_;
  Endpoint endpoint_;
  PublisherReport report_;
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
    // Under the transport's lock, so without waiting: the history is at most the publisher's
    // depth, which the new queue takes whatever its own depth.
    std::lock_guard history_lock(publisher.history_mutex_);
    for (const ReceivedMessage& sample : publisher.history_) {
      subscription->push(sample, offered, publisher.report_, false);
    }
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
  auto queue = std::make_shared<Queue>(*this, endpoint, std::move(on_data));
  for (Publisher* publisher : topic.publishers) connect(*publisher, queue);
  topic.subscriptions.push_back(queue);
  return std::make_unique<Subscription>(*this, std::move(queue));
}

void IntraProcessTransport::stop_waiting() {
  stopped_waiting_.store(true);
  std::shared_lock lock(mutex_);
  for (const auto& [name, topic] : topics_) {
    for (const auto& queue : topic.subscriptions) queue->wake_publishers();
  }
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

bool IntraProcessTransport::begin_wait(const std::string& publisher,
                                       const std::string& subscriber) {
  std::lock_guard lock(waits_mutex_);
  // Everyone `subscriber` waits for, directly or through others; a cycle is broken as it forms,
  // so the walk ends.
  std::vector<std::string> pending{subscriber};
  while (!pending.empty()) {
    std::string waiter = std::move(pending.back());
    pending.pop_back();
    if (waiter == publisher) return false;
    auto [begin, end] = waiting_for_.equal_range(waiter);
    for (auto it = begin; it != end; ++it) pending.push_back(it->second);
  }
  waiting_for_.emplace(publisher, subscriber);
  return true;
}

void IntraProcessTransport::end_wait(const std::string& publisher, const std::string& subscriber) {
  std::lock_guard lock(waits_mutex_);
  auto [begin, end] = waiting_for_.equal_range(publisher);
  for (auto it = begin; it != end; ++it) {
    if (it->second == subscriber) {
      waiting_for_.erase(it);
      return;
    }
  }
}

}  // namespace mocap
