#include "sim/pixart_box_sim/sample_schedule.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::pixart {
namespace {

// Sample times are index / rate; products like (index / rate) * rate land a hair below the
// index, which must still count as the index.
constexpr double kIndexTolerance = 1e-9;

}  // namespace

SampleSchedule::SampleSchedule(double rate_hz) : rate_hz_(rate_hz) {
  if (!(rate_hz > 0 && rate_hz <= kMaxSampleRate_hz)) {
    throw std::invalid_argument(fmt::format("sample rate {} Hz: must be above 0 and at most {} Hz",
                                            rate_hz, kMaxSampleRate_hz));
  }
}

uint64_t SampleSchedule::samples_before(double duration_s) const {
  if (!(duration_s > 0)) return 0;
  return static_cast<uint64_t>(std::ceil(duration_s * rate_hz_ - kIndexTolerance));
}

std::optional<SampleSchedule::Due> SampleSchedule::due(double elapsed_s, uint64_t next) const {
  const double position = elapsed_s * rate_hz_ + kIndexTolerance;
  if (position < static_cast<double>(next)) return std::nullopt;
  const auto latest = static_cast<uint64_t>(std::floor(position));
  const uint64_t index = latest > next ? latest : next;
  return Due{index, index - next};
}

}  // namespace mocap::pixart
