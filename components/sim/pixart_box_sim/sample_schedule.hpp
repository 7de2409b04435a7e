// When the simulated box samples its cameras: sample k at scene time k / rate_hz (≈270 Hz in
// the seed), every camera at the same instant. Pure arithmetic on elapsed time, so the real-time
// player and the log writer share it and tests need no clock.
#pragma once

#include <cstdint>
#include <optional>

namespace mocap::pixart {

// The highest sample rate a schedule takes.
inline constexpr double kMaxSampleRate_hz = 100000;

class SampleSchedule {
 public:
  // Throws std::invalid_argument unless 0 < rate_hz <= kMaxSampleRate_hz.
  explicit SampleSchedule(double rate_hz);

  double rate_hz() const { return rate_hz_; }
  double period_s() const { return 1 / rate_hz_; }
  // Scene time of sample `index`.
  double time_of(uint64_t index) const { return static_cast<double>(index) / rate_hz_; }
  // The samples taken before `duration_s`: at 0, 1/rate, ... (0 for a duration of 0).
  uint64_t samples_before(double duration_s) const;

  // What a real-time player sends at `elapsed_s`, when sample `next` is the next one it has not
  // handled: nothing while `next` is still in the future; otherwise the latest sample whose
  // time has come, and how many samples between `next` and it are skipped because the player
  // fell behind (sending them now would be a burst of stale samples).
  struct Due {
    uint64_t index = 0;
    uint64_t skipped = 0;
  };
  std::optional<Due> due(double elapsed_s, uint64_t next) const;

 private:
  double rate_hz_;
};

}  // namespace mocap::pixart
