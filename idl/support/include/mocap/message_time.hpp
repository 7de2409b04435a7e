// Conversions between clock time points and builtin_interfaces/msg/Time.
#pragma once

#include <chrono>
#include <cstdint>

#include <builtin_interfaces/msg/time.hpp>

namespace mocap {

template <class Clock, class Duration>
builtin_interfaces::msg::Time to_time_msg(std::chrono::time_point<Clock, Duration> time) {
  auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count();
  builtin_interfaces::msg::Time msg;
  auto sec = ns / 1000000000;
  auto nanosec = ns % 1000000000;
  if (nanosec < 0) {  // before the epoch: nanosec stays in [0, 1e9)
    nanosec += 1000000000;
    sec -= 1;
  }
  msg.sec(static_cast<int32_t>(sec));
  msg.nanosec(static_cast<uint32_t>(nanosec));
  return msg;
}

template <class Clock = std::chrono::system_clock>
typename Clock::time_point from_time_msg(const builtin_interfaces::msg::Time& msg) {
  auto since_epoch = std::chrono::seconds(msg.sec()) + std::chrono::nanoseconds(msg.nanosec());
  return
      typename Clock::time_point(std::chrono::duration_cast<typename Clock::duration>(since_epoch));
}

// A stamp as one integer, to pair messages of the same frame (an image and its results).
inline int64_t to_nanoseconds(const builtin_interfaces::msg::Time& msg) {
  return static_cast<int64_t>(msg.sec()) * 1000000000 + msg.nanosec();
}

}  // namespace mocap
