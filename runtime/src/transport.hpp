// The interface every transport implements: in-process (intra) and DDS (fastdds).
//
// A process composes them: a publisher publishes through every transport, a subscription
// takes from every transport. Each transport delivers only what the others do not: intra
// within the process, DDS between processes. So a sample crosses each boundary once and
// never reaches a subscriber twice.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include <mocap/component.hpp>
#include <mocap/message_type.hpp>
#include <mocap/qos.hpp>

#include "throttle.hpp"

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
  virtual void publish(const std::shared_ptr<const void>& message, Clock::time_point now) = 0;
  virtual size_t matched_subscribers() const = 0;
};

class TransportSubscription {
 public:
  virtual ~TransportSubscription() = default;
  // Moves the next waiting message into `out`; false when none waits.
  virtual bool take(ReceivedMessage& out) = 0;
};

class Transport {
 public:
  virtual ~Transport() = default;
  virtual std::unique_ptr<TransportPublisher> advertise(const Endpoint& endpoint) = 0;
  // `on_data` may be called from any thread, whenever a message may be ready to take. When
  // calls_on_own_threads(), only from the transport's own threads, never a publisher's.
  virtual std::unique_ptr<TransportSubscription> subscribe(const Endpoint& endpoint,
                                                           std::function<void()> on_data) = 0;
  virtual bool calls_on_own_threads() const { return false; }
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

}  // namespace mocap
