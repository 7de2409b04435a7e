// Limits a repeated report to one per interval while counting every occurrence.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>

namespace mocap {

class Throttle {
 public:
  explicit Throttle(std::chrono::steady_clock::duration interval = std::chrono::seconds(2))
      : interval_(interval) {}

  // Counts `n` occurrences. Returns how many happened since the last report when a report
  // is due now (the first occurrence always is), nullopt otherwise.
  std::optional<uint64_t> count(uint64_t n = 1) {
    std::lock_guard lock(mutex_);
    total_ += n;
    unreported_ += n;
    auto now = std::chrono::steady_clock::now();
    if (reported_once_ && now - last_report_ < interval_) return std::nullopt;
    reported_once_ = true;
    last_report_ = now;
    uint64_t since_last = unreported_;
    unreported_ = 0;
    return since_last;
  }

  uint64_t total() const {
    std::lock_guard lock(mutex_);
    return total_;
  }

 private:
  std::chrono::steady_clock::duration interval_;
  mutable std::mutex mutex_;
  std::chrono::steady_clock::time_point last_report_;
  bool reported_once_ = false;
  uint64_t total_ = 0;
  uint64_t unreported_ = 0;
};

}  // namespace mocap
