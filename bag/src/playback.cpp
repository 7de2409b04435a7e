#include <mocap/bag/playback.hpp>

#include <chrono>
#include <stdexcept>
#include <thread>

namespace mocap::bag {
namespace {

using SteadyClock = std::chrono::steady_clock;

// Sleeps until `when` in slices, so that `stop` ends the wait within one slice.
bool wait_until(SteadyClock::time_point when, const std::atomic<bool>& stop) {
  constexpr auto kSlice = std::chrono::milliseconds(20);
  while (!stop.load()) {
    const auto now = SteadyClock::now();
    if (now >= when) return true;
    std::this_thread::sleep_until(std::min(when, now + kSlice));
  }
  return false;
}

}  // namespace

PlaybackStats play(BagReader& reader, const PlaybackOptions& options,
                   const std::function<void(const BagMessage&)>& publish,
                   const std::atomic<bool>& stop) {
  if (!(options.rate >= 0)) {
    throw std::invalid_argument("playback rate must be 0 (as fast as possible) or positive");
  }
  reader.set_topic_filter(options.topics);
  PlaybackStats stats;
  BagMessage message;
  for (;;) {
    reader.rewind();
    bool first = true;
    int64_t first_stamp = 0;
    SteadyClock::time_point start;
    while (!stop.load() && reader.next(message)) {
      if (first) {
        first = false;
        first_stamp = message.timestamp_ns;
        start = SteadyClock::now();
      } else if (options.rate > 0) {
        const auto offset = std::chrono::nanoseconds(static_cast<int64_t>(
            static_cast<double>(message.timestamp_ns - first_stamp) / options.rate));
        if (!wait_until(start + offset, stop)) return stats;
      }
      publish(message);
      ++stats.published;
    }
    if (stop.load()) return stats;
    ++stats.loops;
    // A bag with nothing to play would loop without pause.
    if (!options.loop || first) return stats;
  }
}

}  // namespace mocap::bag
