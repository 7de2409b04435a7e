// At most one message per period per key (a board), by the messages' own stamps rather than
// the clock, so that a replayed bag gives the live run's messages.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <string>

namespace mocap::outputs {

class StampRate {
 public:
  // 0 Hz: every message.
  explicit StampRate(double rate_hz)
      : period_ns_(rate_hz > 0 ? static_cast<int64_t>(std::llround(1e9 / rate_hz)) : 0) {}

  // Whether a message of `key` stamped `stamp_ns` goes out; if so, it is the new last one. A 1 %
  // allowance lets a 30 Hz camera's frames, 33.3 ms apart, all through a 30 Hz output.
  bool due(const std::string& key, int64_t stamp_ns) {
    if (period_ns_ == 0) return true;
    auto [last, first] = last_ns_.try_emplace(key, stamp_ns);
    if (!first && stamp_ns - last->second < period_ns_ - period_ns_ / 100) return false;
    last->second = stamp_ns;
    return true;
  }

 private:
  int64_t period_ns_;
  std::map<std::string, int64_t> last_ns_;
};

}  // namespace mocap::outputs
