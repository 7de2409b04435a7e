#include <mocap/health.hpp>

#include <algorithm>

#include <fmt/format.h>

namespace mocap {

std::string_view to_string(HealthLevel level) {
  switch (level) {
    case HealthLevel::ok:
      return "OK";
    case HealthLevel::warn:
      return "WARN";
    case HealthLevel::error:
      return "ERROR";
    case HealthLevel::stale:
      return "STALE";
  }
  return "?";
}

void HealthReport::flag(HealthLevel at_least, std::string_view problem) {
  // STALE is the worst for a reader (nothing is known), so it ranks above ERROR as it does in
  // diagnostic_msgs' numbering.
  level = std::max(level, at_least);
  if (problem.empty()) return;
  if (!message.empty()) message += "; ";
  message += problem;
}

void LatencyFigures::report(HealthReport& report, std::string_view stage) {
  std::vector<int64_t> samples;
  {
    std::lock_guard lock(mutex_);
    samples.swap(samples_);
  }
  if (samples.empty()) {
    report.add(fmt::format("{} median (ms)", stage), "-");
    report.add(fmt::format("{} p99 (ms)", stage), "-");
    return;
  }
  auto at = [&samples](double quantile) {
    auto nth = samples.begin() + static_cast<ptrdiff_t>(quantile * (samples.size() - 1) + 0.5);
    std::nth_element(samples.begin(), nth, samples.end());
    return static_cast<double>(*nth) * 1e-6;
  };
  report.add(fmt::format("{} median (ms)", stage), fmt::format("{:.3f}", at(0.5)));
  report.add(fmt::format("{} p99 (ms)", stage), fmt::format("{:.3f}", at(0.99)));
}

void RateFigures::report(HealthReport& report, std::string_view what, double expected_hz,
                         std::string_view why_low, std::chrono::steady_clock::time_point now) {
  const uint64_t count = count_.exchange(0, std::memory_order_relaxed);
  const std::optional<std::chrono::steady_clock::time_point> since = since_;
  since_ = now;
  report.add(fmt::format("{} expected (Hz)", what), fmt::format("{:.1f}", expected_hz));
  if (!since) {
    report.add(fmt::format("{} (Hz)", what), "-");
    return;
  }
  if (count == 0) {
    window_.clear();
    report.add(fmt::format("{} (Hz)", what), "0.0");
    return;
  }
  window_.push_back({count, now - *since});
  if (window_.size() > kWindow) window_.pop_front();
  uint64_t counted = 0;
  std::chrono::steady_clock::duration length{};
  for (const Period& period : window_) {
    counted += period.count;
    length += period.length;
  }
  const double hz = static_cast<double>(counted) / std::chrono::duration<double>(length).count();
  report.add(fmt::format("{} (Hz)", what), fmt::format("{:.1f}", hz));
  if (hz < 0.9 * expected_hz) {
    report.flag(HealthLevel::warn,
                fmt::format("{} at {:.1f} Hz of {:.1f}: {}", what, hz, expected_hz, why_low));
  }
}

}  // namespace mocap
