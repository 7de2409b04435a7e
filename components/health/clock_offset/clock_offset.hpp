// Another host's clock measured over the network as NTP does (RFC 5905): a probe leaves at t1
// on our clock, arrives at t2 on theirs, is answered at t3 on theirs and the answer arrives at
// t4 on ours. If the way there and the way back take equally long, their clock is ahead of ours
// by ((t2 - t1) + (t3 - t4)) / 2, and the round trip took (t4 - t1) - (t3 - t2). A sample is off
// by at most half its round trip, and queues make round trips long one way more than the other:
// of the last few seconds' samples, the one with the shortest round trip is the one to trust
// (NTP's clock filter, over more samples than NTP keeps: below).
//
//   ClockOffsetFilter filter;
//   filter.add({t1, t2, t3, t4});
//   if (auto clock = filter.offset()) use(clock->offset_ns);
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::health {

// One exchange's four times, in nanoseconds since the epoch on the clock each was read from.
struct ClockExchange {
  int64_t probe_sent_ns = 0;      // t1, ours
  int64_t probe_received_ns = 0;  // t2, theirs
  int64_t reply_sent_ns = 0;      // t3, theirs
  int64_t reply_received_ns = 0;  // t4, ours

  int64_t offset_ns() const;  // theirs minus ours
  int64_t round_trip_ns() const;
};

struct ClockOffset {
  int64_t offset_ns = 0;      // the other clock minus ours
  int64_t round_trip_ns = 0;  // of the exchange it comes from: the offset is good to half of it
  int samples = 0;            // exchanges the filter holds
  int64_t span_ns = 0;        // from the first of them to the last, on our clock

  // What the exchange proves: the other clock is off by at least this much (0 when the round
  // trip leaves room for none). A check on this does not flap with the network's queues.
  int64_t least_offset_ns() const;
};

class ClockOffsetFilter {
 public:
  // NTP keeps 8 samples, polling every 64 s and more. Probes many times a second on a busy host
  // meet queues more often, and a quick exchange among them is rarer: the filter keeps the
  // exchanges of the last two seconds, in which a clock drifts a few microseconds at most.
  static constexpr std::chrono::seconds kWindow{2};
  // Bounds what a peer costs however often it is probed.
  static constexpr size_t kMaxSamples = 1024;

  // An exchange whose round trip is negative (a clock stepped during it) is not kept.
  void add(const ClockExchange& exchange);
  // Of the exchanges within kWindow of the last one, the one with the shortest round trip;
  // none yet: nullopt.
  std::optional<ClockOffset> offset() const;

 private:
  std::deque<ClockExchange> samples_;
};

// The clocks of the processes that answer a requester's probes, each known by the topics it
// publishes: whose clock stamped the messages of a topic.
class PeerClocks {
 public:
  using SteadyTime = std::chrono::steady_clock::time_point;

  struct Peer {
    std::string host;
    std::string process;
    std::vector<std::string> topics;
    ClockOffsetFilter filter;
    SteadyTime last_reply{};
  };

  // An answer from the process `instance` (a number each process draws at its start, so that a
  // restarted process starts a filter afresh) of `process` on `host`, publishing `topics`.
  void add(uint64_t instance, std::string_view host, std::string_view process,
           const std::vector<std::string>& topics, const ClockExchange& exchange, SteadyTime now);
  // The process that publishes `topic` and answered last; none: nullptr.
  const Peer* publisher_of(std::string_view topic) const;
  // Forgets processes that have not answered for `silence` (a process that ended).
  void forget_silent(SteadyTime now, std::chrono::nanoseconds silence);
  size_t size() const { return peers_.size(); }

 private:
  std::map<uint64_t, Peer> peers_;  // by instance
};

}  // namespace mocap::health
