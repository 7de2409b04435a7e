#include "candump_recording.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "candump_log.hpp"

namespace mocap::pixart {
namespace {

// A standard frame with 8 data bytes is 111 bits plus up to 24 stuff bits: about 130 µs at
// 1 Mbit/s, the box's bus.
constexpr int64_t kFrameOnBus_ns = 130000;

}  // namespace

uint64_t write_candump_recording(PixartBoxSimulator& simulator, std::ostream& out,
                                 const CandumpRecordingOptions& options, std::stop_token stop) {
  const SampleSchedule schedule(options.rate_hz);
  const uint64_t samples = schedule.samples_before(options.duration_s);
  const size_t frames_per_sample = 2 * simulator.rig().cameras.size();
  const auto period_ns = static_cast<int64_t>(std::llround(schedule.period_s() * 1e9));
  const int64_t spacing_ns =
      frames_per_sample == 0
          ? 0
          : std::min(kFrameOnBus_ns, period_ns / static_cast<int64_t>(frames_per_sample));
  can::CandumpRecord record;
  record.interface = options.interface;
  uint64_t written = 0;
  std::string line;
  for (uint64_t k = 0; k < samples && !stop.stop_requested(); ++k) {
    const double time_s = schedule.time_of(k);
    const int64_t sample_ns = options.start_ns + std::llround(time_s * 1e9);
    int64_t frame_ns = sample_ns;
    for (can::CanFrame& frame : simulator.frames_at(time_s)) {
      frame.stamp_ns = frame_ns;
      record.stamp_ns = frame_ns;
      record.frame = frame;
      line = can::format_candump_line(record);
      line += '\n';
      out.write(line.data(), static_cast<std::streamsize>(line.size()));
      frame_ns += spacing_ns;
      ++written;
    }
    if (!out) throw std::runtime_error("cannot write the candump log");
  }
  out.flush();
  if (!out) throw std::runtime_error("cannot write the candump log");
  return written;
}

}  // namespace mocap::pixart
