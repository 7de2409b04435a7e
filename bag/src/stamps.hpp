// Stamps as a bag's files give them: arithmetic that cannot overflow, and the clock time
// problem lines show.
#pragma once

#include <cstdint>
#include <string>

namespace mocap::bag {

// Stamps and row ids come from the file and may be anything: sums and differences of them
// saturate rather than overflow.
inline int64_t clamped_sum(int64_t a, int64_t b) {
  int64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) return b > 0 ? INT64_MAX : INT64_MIN;
  return sum;
}
inline int64_t clamped_difference(int64_t a, int64_t b) {
  int64_t difference = 0;
  if (__builtin_sub_overflow(a, b, &difference)) return b < 0 ? INT64_MAX : INT64_MIN;
  return difference;
}

// "12:03:04.512", local time: what a user compares with the clock of the recording.
std::string time_of_day(int64_t stamp_ns);

}  // namespace mocap::bag
