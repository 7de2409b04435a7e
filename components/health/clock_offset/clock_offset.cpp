#include "health/clock_offset/clock_offset.hpp"

#include <algorithm>
#include <cstdlib>

namespace mocap::health {

int64_t ClockExchange::offset_ns() const {
  // Each difference is small; their sum cannot overflow where the times themselves might.
  return ((probe_received_ns - probe_sent_ns) + (reply_sent_ns - reply_received_ns)) / 2;
}

int64_t ClockExchange::round_trip_ns() const {
  return (reply_received_ns - probe_sent_ns) - (reply_sent_ns - probe_received_ns);
}

int64_t ClockOffset::least_offset_ns() const {
  return std::max<int64_t>(0, std::abs(offset_ns) - round_trip_ns / 2);
}

void ClockOffsetFilter::add(const ClockExchange& exchange) {
  if (exchange.round_trip_ns() < 0) return;
  samples_.push_back(exchange);
  const int64_t oldest_kept_ns =
      exchange.reply_received_ns - std::chrono::nanoseconds(kWindow).count();
  while (samples_.size() > kMaxSamples || samples_.front().reply_received_ns < oldest_kept_ns) {
    samples_.pop_front();
  }
}

std::optional<ClockOffset> ClockOffsetFilter::offset() const {
  if (samples_.empty()) return std::nullopt;
  const auto best = std::min_element(samples_.begin(), samples_.end(),
                                     [](const ClockExchange& a, const ClockExchange& b) {
                                       return a.round_trip_ns() < b.round_trip_ns();
                                     });
  return ClockOffset{best->offset_ns(), best->round_trip_ns(), static_cast<int>(samples_.size()),
                     samples_.back().reply_received_ns - samples_.front().reply_received_ns};
}

void PeerClocks::add(uint64_t instance, std::string_view host, std::string_view process,
                     const std::vector<std::string>& topics, const ClockExchange& exchange,
                     SteadyTime now) {
  Peer& peer = peers_[instance];
  peer.host = host;
  peer.process = process;
  peer.topics = topics;
  peer.filter.add(exchange);
  peer.last_reply = now;
}

const PeerClocks::Peer* PeerClocks::publisher_of(std::string_view topic) const {
  const Peer* newest = nullptr;
  for (const auto& [instance, peer] : peers_) {
    if (std::find(peer.topics.begin(), peer.topics.end(), topic) == peer.topics.end()) continue;
    if (newest == nullptr || peer.last_reply > newest->last_reply) newest = &peer;
  }
  return newest;
}

void PeerClocks::forget_silent(SteadyTime now, std::chrono::nanoseconds silence) {
  std::erase_if(peers_, [&](const auto& entry) { return now - entry.second.last_reply > silence; });
}

}  // namespace mocap::health
