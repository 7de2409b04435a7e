// The publication rate of a topic, from its samples' source timestamps.
#pragma once

#include <chrono>
#include <cstddef>
#include <deque>
#include <optional>

namespace mocap {

// Uses the publisher's timestamps, not arrival times: delivery jitter and batching in the
// receiving process then do not bias the figure, and a slow receiver does not under-read
// as long as it receives every sample.
class RateEstimator {
 public:
  using TimePoint = std::chrono::system_clock::time_point;

  struct Stats {
    double rate_hz;
    double min_period_s;
    double max_period_s;
    double stddev_period_s;
    size_t samples;
  };

  explicit RateEstimator(size_t window = 10000) : window_(window) {}

  void add(TimePoint source_time);
  // Over the last `window` samples; nullopt below two samples or with no time between them.
  std::optional<Stats> stats() const;

 private:
  size_t window_;
  std::deque<TimePoint> times_;
};

}  // namespace mocap
