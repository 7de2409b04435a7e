#include "core/rate_estimator.hpp"

#include <algorithm>
#include <cmath>

namespace mocap {

void RateEstimator::add(TimePoint source_time) {
  times_.push_back(source_time);
  while (times_.size() > window_) times_.pop_front();
}

std::optional<RateEstimator::Stats> RateEstimator::stats() const {
  if (times_.size() < 2) return std::nullopt;
  double span = std::chrono::duration<double>(times_.back() - times_.front()).count();
  if (span <= 0) return std::nullopt;
  size_t periods = times_.size() - 1;
  double mean = span / static_cast<double>(periods);
  double min = INFINITY, max = -INFINITY, squares = 0;
  for (size_t i = 1; i < times_.size(); ++i) {
    double period = std::chrono::duration<double>(times_[i] - times_[i - 1]).count();
    min = std::min(min, period);
    max = std::max(max, period);
    squares += (period - mean) * (period - mean);
  }
  return Stats{static_cast<double>(periods) / span, min, max,
               std::sqrt(squares / static_cast<double>(periods)), times_.size()};
}

}  // namespace mocap
