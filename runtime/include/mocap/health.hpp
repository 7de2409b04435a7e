// How a component is doing, in the terms ROS 2's diagnostics use: a level, a sentence and
// figures. A component fills a HealthReport in Component::report_health(), which the runtime
// calls once a second on the component's own strand; the runtime adds what it counts itself
// (messages in and out, drops, callback errors) and hands the whole process's reports to
// whoever asks (Context::process_health(): the diagnostics component, which publishes them on
// /diagnostics).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mocap {

// diagnostic_msgs/DiagnosticStatus's levels, in its order.
enum class HealthLevel : uint8_t { ok = 0, warn = 1, error = 2, stale = 3 };

std::string_view to_string(HealthLevel level);

struct HealthReport {
  HealthLevel level = HealthLevel::ok;
  // What is wrong, for a person: "cam_2 refused: its clock is 5.03 ms ahead". Empty when OK.
  std::string message;
  // Figures with their units in the key: {"fused frames/s", "239.8"}.
  std::vector<std::pair<std::string, std::string>> values;

  void add(std::string key, std::string value) {
    values.emplace_back(std::move(key), std::move(value));
  }
  // Raises the level to `at_least` and adds `problem` to the message (several are joined
  // with "; "). The level never goes down: the worst problem sets it.
  void flag(HealthLevel at_least, std::string_view problem);
};

// The latency of one stage over the last report's period: the component adds a sample per
// message (the time from the frame's capture stamp to the moment it sent its output), and
// report() gives the median and the 99th percentile in milliseconds, then starts over.
// Thread-safe: a capture worker adds while report_health() reports.
class LatencyFigures {
 public:
  void add(std::chrono::nanoseconds latency) {
    std::lock_guard lock(mutex_);
    samples_.push_back(latency.count());
  }
  // Adds "<stage> median (ms)" and "<stage> p99 (ms)" (nothing measured: "-").
  void report(HealthReport& report, std::string_view stage);

 private:
  std::mutex mutex_;
  std::vector<int64_t> samples_;
};

// A stream's rate against the rate it should have (a camera's frames against its rate_hz),
// over the last kWindow reports' periods (about 5 s), as ROS's diagnostic_updater judges a
// frequency by default: one stall of a fifth of a second on a busy host is not a stream too
// slow, a stream that stays slow is. report() adds "<what> (Hz)" and "<what> expected (Hz)",
// and flags WARN with `why_low` when the window ran below 90 % of it. A stream that stopped
// (none in the last period: a camera waiting for its first subscriber) shows 0 Hz, is left to
// who reads it, and starts a new window. The first period, which holds the start, is not
// judged. Thread-safe.
class RateFigures {
 public:
  static constexpr size_t kWindow = 5;

  void add() { count_.fetch_add(1, std::memory_order_relaxed); }
  void report(HealthReport& report, std::string_view what, double expected_hz,
              std::string_view why_low,
              std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());

 private:
  struct Period {
    uint64_t count = 0;
    std::chrono::steady_clock::duration length{};
  };
  std::atomic<uint64_t> count_{0};
  std::optional<std::chrono::steady_clock::time_point> since_;
  std::deque<Period> window_;  // the last kWindow periods, newest last
};

// What the runtime counts for one topic of a component, since the component started.
struct TopicCounts {
  std::string topic;      // after remaps
  uint64_t messages = 0;  // published, or received (callbacks run)
  // Published: given up for some subscriber (Qos::max_blocking, a failed write). Received:
  // given up for this one (its keep-last queue overflowed, lost or rejected in transit).
  uint64_t dropped = 0;
  // Received: samples waiting to be taken now (its queue's depth); nullopt where the DDS
  // implementation does not tell.
  std::optional<size_t> waiting = std::nullopt;
};

// One component of this process, as Context::process_health() gives it.
struct ComponentHealth {
  std::string name;
  std::string plugin;
  std::vector<TopicCounts> published;
  std::vector<TopicCounts> received;
  uint64_t callback_errors = 0;  // callbacks and workers that threw
  // Its last report_health(), and when it was made (none yet: an empty report, at the epoch).
  HealthReport report;
  std::chrono::steady_clock::time_point reported_at{};
};

}  // namespace mocap
