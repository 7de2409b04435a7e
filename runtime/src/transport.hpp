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
