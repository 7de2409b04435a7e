#include "tracking/fiducial_monitor/fiducial_monitor.hpp"

#include <algorithm>
#include <cmath>

namespace mocap::demo {

void StreamStatistics::add(double latency_s, size_t items) {
  latencies_.push_back(latency_s);
  items_ += items;
  ++total_;
}

std::optional<StreamStatistics::Report> StreamStatistics::report() {
  if (latencies_.empty()) return std::nullopt;
  std::vector<double> sorted = std::move(latencies_);
  latencies_.clear();
  std::sort(sorted.begin(), sorted.end());
  auto quantile = [&](double q) {
    size_t index = static_cast<size_t>(std::ceil(q * static_cast<double>(sorted.size()))) - 1;
    return sorted[std::min(index, sorted.size() - 1)];
  };
  Report report{sorted.size(), static_cast<double>(items_) / static_cast<double>(sorted.size()),
                quantile(0.5), quantile(0.99), sorted.back()};
  items_ = 0;
  return report;
}

}  // namespace mocap::demo
