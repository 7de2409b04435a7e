// What a DDS publisher does when its reliable keep_all subscribers have no room, and when it
// closes with samples they have not acknowledged: one policy for every DDS implementation,
// which supplies only its own write and wait-for-acknowledgements calls.
//
// An implementation's write waits at most kWriteWaitSlice for room (its max_blocking_time);
// the policy writes again until there is room, the process stops (Transport::stop_waiting) or
// Qos::max_blocking has passed, so that each of those is seen in time. Every wait is counted
// and logged with the subscribers it waited for; every sample given up is counted as dropped.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <mocap/waiting_scope.hpp>

#include "transport/transport.hpp"

namespace mocap {

// The longest one DDS write waits for room in a full keep-all history (the writers'
// max_blocking_time): short, so that a waiting publisher sees the process stopping and
// Qos::max_blocking in time.
constexpr std::chrono::nanoseconds kWriteWaitSlice = std::chrono::milliseconds(5);

class WriterBackpressure {
 public:
  // `subscribers` names the matched subscribers for messages ("DDS subscriber(s) in 'sink'").
  // `stopped_waiting` is the transport's: set when the process stops.
  WriterBackpressure(const Endpoint& endpoint, const std::atomic<bool>& stopped_waiting,
                     std::function<std::string()> subscribers)
      : endpoint_(endpoint),
        stopped_waiting_(stopped_waiting),
        subscribers_(std::move(subscribers)),
        report_(endpoint) {}

  // Nobody in another process listens, and nobody who joins later may ask for the sample: it
  // need not be written at all.
  bool nobody_needs_it(int remote_readers) const {
    return remote_readers == 0 && endpoint_.qos.durability == Durability::Volatile;
  }

  // Calls `write_once` until it returns a result `no_room` does not call a lack of room, or
  // the policy gives up (then the result is the last one, a lack of room, and the sample is
  // counted as dropped).
  template <typename WriteOnce, typename NoRoom>
  auto write(WriteOnce&& write_once, NoRoom&& no_room) {
    auto start = std::chrono::steady_clock::now();
    auto result = write_once();
    if (!no_room(result)) return result;
    std::optional<std::string> given_up;
    {
      WaitingScope waiting;
      while (no_room(result) && !(given_up = reason_to_give_up(start))) result = write_once();
    }
    report_.count_wait(std::chrono::steady_clock::now() - start, subscribers_());
    if (given_up) report_.count_drop(1, *given_up);
    return result;
  }

  // A write that failed for another reason than room: `reason` ("DDS write failed (code 1)").
  void count_failed_write(std::string_view reason) { report_.count_drop(1, reason); }

  // Deleting a reliable writer drops the samples its subscribers have not acknowledged yet,
  // such as the last ones `mocap_bag play` publishes before it exits. So before it is
  // deleted, it waits for them (`acknowledged_within(kWriteWaitSlice)` until true), unless the
  // process is stopping on a signal; subscribers that have not acknowledged within kCloseWait
  // count as stalled, and a warning says so.
  template <typename AcknowledgedWithin>
  void deliver_what_was_written(int remote_readers, AcknowledgedWithin&& acknowledged_within) {
    if (endpoint_.qos.reliability != Reliability::Reliable || remote_readers == 0) return;
    auto start = std::chrono::steady_clock::now();
    while (!acknowledged_within(kWriteWaitSlice)) {
      if (std::optional<std::string> why = reason_to_stop_delivering(start)) {
        Logger(endpoint_.owner)
            .warn("{}: publisher closed before {} acknowledged all it published ({})",
                  endpoint_.topic, subscribers_(), *why);
        return;
      }
    }
  }

  PublisherStats stats() const { return report_.stats(); }

  static constexpr std::chrono::seconds kCloseWait{5};

 private:
  std::optional<std::string> reason_to_give_up(std::chrono::steady_clock::time_point start) const;
  std::optional<std::string> reason_to_stop_delivering(
      std::chrono::steady_clock::time_point start) const;

  const Endpoint& endpoint_;
  const std::atomic<bool>& stopped_waiting_;
  std::function<std::string()> subscribers_;
  PublisherReport report_;
};

}  // namespace mocap
