#include "stamps.hpp"

#include <ctime>

#include <fmt/format.h>

namespace mocap::bag {

std::string time_of_day(int64_t stamp_ns) {
  const std::time_t seconds = static_cast<std::time_t>(stamp_ns / 1'000'000'000);
  const auto millis = static_cast<int>((stamp_ns % 1'000'000'000) / 1'000'000);
  std::tm tm{};
  if (localtime_r(&seconds, &tm) == nullptr) return fmt::format("{} ns", stamp_ns);
  return fmt::format("{:02}:{:02}:{:02}.{:03}", tm.tm_hour, tm.tm_min, tm.tm_sec,
                     millis < 0 ? 0 : millis);
}

}  // namespace mocap::bag
