#include "common/can_io/adaptor_clock.hpp"

#include <algorithm>

namespace mocap::can {
namespace {

constexpr int64_t kMinute_ms = 60'000;
constexpr int64_t kNsPerMs = 1'000'000;

}  // namespace

int64_t AdaptorClock::host_time(uint32_t adaptor_ms, int64_t read_ns) {
  if (offset_ns_ && read_ns - last_read_ns_ <= kMaxSilence_ns) {
    const int64_t step_ms =
        ((static_cast<int64_t>(adaptor_ms) - last_ms_) % kMinute_ms + kMinute_ms) % kMinute_ms;
    adaptor_ns_ += step_ms * kNsPerMs;
    const auto drift_ns =
        static_cast<int64_t>(kMaxDrift * static_cast<double>(read_ns - last_read_ns_));
    offset_ns_ = std::min(*offset_ns_ + drift_ns, read_ns - adaptor_ns_);
  } else {
    adaptor_ns_ = static_cast<int64_t>(adaptor_ms) * kNsPerMs;
    offset_ns_ = read_ns - adaptor_ns_;
  }
  last_ms_ = adaptor_ms;
  last_read_ns_ = read_ns;
  if (read_ns - (adaptor_ns_ + *offset_ns_) > kMaxDelay_ns) offset_ns_ = read_ns - adaptor_ns_;
  return adaptor_ns_ + *offset_ns_;
}

}  // namespace mocap::can
