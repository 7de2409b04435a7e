// What one Foxglove client has yet to receive: frames in order, within a byte budget. A client
// that reads slower than the graph publishes loses its oldest frames, never slows the graph;
// one that stays over its budget is to be disconnected.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>

namespace mocap::foxglove {

struct ClientQueueOptions {
  size_t limit_bytes = 10'000'000;
  // Over the limit (dropping) for this long without a break: disconnect.
  std::chrono::steady_clock::duration disconnect_after = std::chrono::seconds(5);

  // Why these options cannot be used, naming the field ("limit_bytes: 0 leaves no room for a
  // message"); nullopt when they can. ClientQueue's constructor throws std::invalid_argument
  // with it.
  std::optional<std::string> problem() const;
};

class ClientQueue {
 public:
  using Clock = std::chrono::steady_clock;
  explicit ClientQueue(ClientQueueOptions options = {});

  // Appends a frame; drops the oldest frames while the queue would exceed the limit (a frame
  // larger than the limit on its own is dropped itself).
  void push(std::string frame, Clock::time_point now);
  // The oldest frame, if any.
  std::optional<std::string> pop();

  size_t bytes() const { return bytes_; }
  size_t frames() const { return frames_.size(); }
  uint64_t dropped() const { return dropped_; }
  // True once the client has been behind for disconnect_after: from the first frame dropped
  // until the queue is next emptied (the client caught up).
  bool should_disconnect(Clock::time_point now) const;

 private:
  ClientQueueOptions options_;
  std::deque<std::string> frames_;
  size_t bytes_ = 0;
  uint64_t dropped_ = 0;
  std::optional<Clock::time_point> dropping_since_;
};

}  // namespace mocap::foxglove
