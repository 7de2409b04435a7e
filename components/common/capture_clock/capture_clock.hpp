// Frames taken together by the cameras of a volume: one at every multiple of the period on the
// system clock, stamped with that time, so that cameras in different processes (on hosts with
// synchronized clocks) capture the same instants. A frame whose time passed while the previous
// one was taken is skipped, as a real camera drops it. Runs on a worker of its own, sleeping
// until each capture time, where a timer would fire at any phase.
#pragma once

#include <sys/prctl.h>

#include <chrono>
#include <stop_token>
#include <thread>

#include <mocap/component.hpp>

namespace mocap {

// Calls take(capture_time) at each multiple of `period` until `stop` is requested.
template <class Take>
void capture_on_the_clock(std::chrono::nanoseconds period, const std::stop_token& stop, Take take) {
  constexpr auto kStopCheck = std::chrono::milliseconds(100);
  // Woken at the capture time, not up to Linux's default timer slack (50 us) after it: the
  // frame's latency counts from its stamp.
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  while (!stop.stop_requested()) {
    const auto since_epoch = std::chrono::system_clock::now().time_since_epoch();
    const Clock::time_point next(since_epoch / period * period + period);
    if (next - std::chrono::system_clock::now() > kStopCheck) {
      std::this_thread::sleep_for(kStopCheck);
      continue;
    }
    std::this_thread::sleep_until(next);
    take(next);
  }
}

}  // namespace mocap
