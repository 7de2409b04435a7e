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

}  // namespace mocap
