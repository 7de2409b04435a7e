// The interface every transport implements: in-process (intra) and DDS (fastdds), and the
// reports of drops and waits they share.
//
// A process composes them: a publisher publishes through every transport, a subscription
// takes from every transport. Each transport delivers only what the others do not: intra
// within the process, DDS between processes. So a sample crosses each boundary once and
// never reaches a subscriber twice.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <mocap/component.hpp>
#include <mocap/message_type.hpp>
#include <mocap/qos.hpp>

#include "core/throttle.hpp"

namespace mocap {

struct Endpoint {
  std::string topic;  // as components name it: "/a/b"
  const MessageType* type = nullptr;
  Qos qos;
  std::string owner;  // component name, for reports
};

struct ReceivedMessage {
  std::shared_ptr<const void> message;
  Clock::time_point source_time;  // when it was published
};

class TransportPublisher {
 public:
  virtual ~TransportPublisher() = default;
  // Waits while a reliable keep-all subscriber has no room (Qos::max_blocking).
  virtual void publish(const std::shared_ptr<const void>& message, Clock::time_point now) = 0;
  virtual size_t matched_subscribers() const = 0;
  // Waits and drops; `published` stays 0 (the host counts publish() calls).
  virtual PublisherStats stats() const = 0;
};

class TransportSubscription {
 public:
  virtual ~TransportSubscription() = default;
  // Moves the next waiting message into `out`; false when none waits.
  virtual bool take(ReceivedMessage& out) = 0;
  // Samples given up for this subscriber: a keep-last queue that overflowed, lost or rejected
  // in transit, malformed. Thread-safe.
  virtual uint64_t dropped() const = 0;
  // Samples waiting to be taken now; nullopt where the implementation does not tell (Cyclone
  // DDS). Thread-safe.
  virtual std::optional<size_t> waiting() const = 0;
};

// Called, from any thread, when a message may be ready to take. `may_run_callbacks` is true
// only on a transport's own thread (a DDS receive thread) and never inside a publish(): the
// subscriber's callbacks may then run right there (Strand::dispatch).
using DataNotification = std::function<void(bool may_run_callbacks)>;

class Transport {
 public:
  virtual ~Transport() = default;
  virtual std::unique_ptr<TransportPublisher> advertise(const Endpoint& endpoint) = 0;
  virtual std::unique_ptr<TransportSubscription> subscribe(const Endpoint& endpoint,
                                                           DataNotification on_data) = 0;
  // The process is stopping and subscribers will not catch up: publishers waiting for room
  // give up now, and later ones do not wait (what does not fit is dropped and counted).
  virtual void stop_waiting() = 0;
};

// Counts dropped samples of one endpoint and logs them at most every two seconds.
class DropReport {
 public:
  DropReport(const Endpoint& endpoint, std::string what)
      : logger_(endpoint.owner), topic_(endpoint.topic), what_(std::move(what)) {}
  // Drops counted after the last report are reported here, so none go unmentioned.
  ~DropReport() {
    if (throttle_.total() > 0) {
      logger_.warn("{}: {} dropped {} sample(s) in all", topic_, what_, throttle_.total());
    }
  }

  void count(uint64_t n, std::string_view reason) {
    if (auto since_last = throttle_.count(n)) {
      logger_.warn("{}: {} {} sample(s) dropped ({} in all): {}", topic_, what_, *since_last,
                   throttle_.total(), reason);
    }
  }
  uint64_t total() const { return throttle_.total(); }

 private:
  Logger logger_;
  std::string topic_;
  std::string what_;
  Throttle throttle_;
};

// A publisher's waits for subscribers without room and the samples it gave up: counted for
// stats(), logged with whom it waits for (at once, then at most every ten seconds), and
// summed up when the publisher goes.
class PublisherReport {
 public:
  explicit PublisherReport(const Endpoint& endpoint)
      : logger_(endpoint.owner), topic_(endpoint.topic), drops_(endpoint, "publisher") {}
  ~PublisherReport() {
    std::lock_guard lock(mutex_);
    if (stats_.waited > 0) {
      logger_.info(
          "{}: publisher waited {:.3f} s in all for subscribers without room ({} "
          "sample(s) waited, the longest {:.1f} ms)",
          topic_, seconds(stats_.blocked), stats_.waited, seconds(stats_.longest_wait) * 1e3);
    }
  }

  // One sample waited `waited` for `whom` ("subscriber 'sink' in this process").
  void count_wait(std::chrono::nanoseconds waited, std::string_view whom) {
    std::lock_guard lock(mutex_);
    ++stats_.waited;
    stats_.blocked += waited;
    stats_.longest_wait = std::max(stats_.longest_wait, waited);
    if (waits_.count()) {
      logger_.info(
          "{}: publisher waits for {} ({} sample(s) waited, {:.3f} s in all): a "
          "reliable keep_all subscriber sets the pace",
          topic_, whom, stats_.waited, seconds(stats_.blocked));
    }
  }
  void count_drop(uint64_t n, std::string_view reason) { drops_.count(n, reason); }

  PublisherStats stats() const {
    std::lock_guard lock(mutex_);
    PublisherStats stats = stats_;
    stats.dropped = drops_.total();
    return stats;
  }

 private:
  static double seconds(std::chrono::nanoseconds duration) {
    return std::chrono::duration<double>(duration).count();
  }

  Logger logger_;
  std::string topic_;
  DropReport drops_;
  mutable std::mutex mutex_;
  PublisherStats stats_;
  Throttle waits_{std::chrono::seconds(10)};
};

}  // namespace mocap
