// Plays a bag's messages back at their recorded pace: the time between two messages is the
// time between their recorded stamps divided by `rate`; rate 0 plays them as fast as they can
// be handed over, in order. Middleware-free: the caller publishes (mocap_bag play over DDS,
// the bag_player component in a launch file).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <mocap/bag/bag_reader.hpp>

namespace mocap::bag {

struct PlaybackOptions {
  double rate = 1.0;                // 0: as fast as possible
  bool loop = false;                // start again after the last message, until stopped
  std::vector<std::string> topics;  // only these (empty: all)
};

struct PlaybackStats {
  uint64_t published = 0;
  uint64_t loops = 0;  // times the end was reached
};

// Calls `publish` for each message when it is due (steady clock, relative to when run()
// started) until the bag ends (or, looping, until `stop`). Returns early once `stop` is set;
// a wait is cut short within 20 ms. Throws std::invalid_argument for a negative rate.
PlaybackStats play(BagReader& reader, const PlaybackOptions& options,
                   const std::function<void(const BagMessage&)>& publish,
                   const std::atomic<bool>& stop);

}  // namespace mocap::bag
