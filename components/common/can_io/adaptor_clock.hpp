// The time at which an SLCAN adaptor took a frame off the bus, on the host's clock.
//
// Read times suffer the host's scheduling: frames that wait in the USB link while the reader
// is descheduled all come out of one read, with one stamp, and a PixArt sample 3.7 ms after
// the last looks 40 ms after it. An adaptor switched to "Z1" mode stamps every frame itself,
// with the millisecond within a minute at which it received it. AdaptorClock turns those
// stamps into host times: host = adaptor + offset, the offset the least (read time - adaptor
// time) seen so far, that is, the stamp of the frame read with the shortest delay. The least
// offset may rise by kMaxDrift per second, so that an adaptor clock slower than the host's
// keeps being followed.
#pragma once

#include <cstdint>
#include <optional>

namespace mocap::can {

class AdaptorClock {
 public:
  // Adaptor and host clocks may run apart by this much (a crystal's 100 ppm, ten times over).
  static constexpr double kMaxDrift = 1e-3;
  // Frames further apart than this start the mapping afresh: the adaptor's stamp wraps every
  // minute, so after a longer silence the minutes cannot be counted.
  static constexpr int64_t kMaxSilence_ns = 30'000'000'000;
  // A stamp this far before its read time is not believed (a frozen or reset adaptor clock):
  // the mapping starts afresh from this frame.
  static constexpr int64_t kMaxDelay_ns = 500'000'000;

  // The host time of a frame the adaptor stamped `adaptor_ms` (0 .. 59,999) and the host read at
  // `read_ns`. Never later than `read_ns`. Frames must come in the order the adaptor sent them.
  int64_t host_time(uint32_t adaptor_ms, int64_t read_ns);

 private:
  std::optional<int64_t> offset_ns_;  // host - adaptor, the least seen (rising by the drift)
  int64_t adaptor_ns_ = 0;            // the adaptor's time, minutes counted
  uint32_t last_ms_ = 0;
  int64_t last_read_ns_ = 0;
};

}  // namespace mocap::can
