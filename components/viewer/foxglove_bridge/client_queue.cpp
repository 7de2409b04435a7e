#include "viewer/foxglove_bridge/client_queue.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace mocap::foxglove {

std::optional<std::string> ClientQueueOptions::problem() const {
  if (limit_bytes == 0) return "limit_bytes: 0 leaves no room for a message";
  if (disconnect_after < std::chrono::steady_clock::duration::zero()) {
    return fmt::format("disconnect_after: {} s is below 0",
                       std::chrono::duration<double>(disconnect_after).count());
  }
  return std::nullopt;
}

ClientQueue::ClientQueue(ClientQueueOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("ClientQueueOptions::" + *problem);
  }
}

void ClientQueue::push(std::string frame, Clock::time_point now) {
  if (frame.size() > options_.limit_bytes) {
    ++dropped_;
    if (!dropping_since_) dropping_since_ = now;
    return;
  }
  while (!frames_.empty() && bytes_ + frame.size() > options_.limit_bytes) {
    bytes_ -= frames_.front().size();
    frames_.pop_front();
    ++dropped_;
    if (!dropping_since_) dropping_since_ = now;
  }
  bytes_ += frame.size();
  frames_.push_back(std::move(frame));
}

std::optional<std::string> ClientQueue::pop() {
  if (frames_.empty()) return std::nullopt;
  std::string frame = std::move(frames_.front());
  frames_.pop_front();
  bytes_ -= frame.size();
  if (frames_.empty()) dropping_since_.reset();  // caught up
  return frame;
}

bool ClientQueue::should_disconnect(Clock::time_point now) const {
  return dropping_since_ && now - *dropping_since_ >= options_.disconnect_after;
}

}  // namespace mocap::foxglove
