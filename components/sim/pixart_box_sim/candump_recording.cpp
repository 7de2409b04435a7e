#include "sim/pixart_box_sim/candump_recording.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "common/can_io/candump_log.hpp"

namespace mocap::pixart {
namespace {

// A standard frame with 8 data bytes is 111 bits plus up to 24 stuff bits: about 130 µs at
// 1 Mbit/s, the box's bus.
constexpr int64_t kFrameOnBus_ns = 130000;

void write_truth(const PixartBoxSimulator& simulator, double time_s, int64_t stamp_ns,
                 std::ostream& out) {
  for (const RobotTruth& truth : simulator.ground_truth(time_s)) {
    out << fmt::format("{},{},{:.6f},{:.6f},{:.6f}\n", stamp_ns, truth.name, truth.pose.x,
                       truth.pose.y, truth.pose.theta);
  }
  if (!out) throw std::runtime_error("cannot write the ground truth");
}

// Why `rate_hz` cannot be a rate of a SampleSchedule.
std::optional<std::string> rate_problem(const char* name, double rate_hz) {
  if (!(rate_hz > 0)) return fmt::format("{}: {} is not above 0", name, rate_hz);
  if (rate_hz > kMaxSampleRate_hz) {
    return fmt::format("{}: {} is above {}", name, rate_hz, kMaxSampleRate_hz);
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> CandumpRecordingOptions::problem() const {
  if (!(duration_s >= 0)) return fmt::format("duration_s: {} is below 0", duration_s);
  if (!std::isfinite(duration_s)) return fmt::format("duration_s: {} is not finite", duration_s);
  if (auto problem = rate_problem("rate_hz", rate_hz)) return problem;
  if (start_ns < 0) {
    return fmt::format("start_ns: {} is below 0 (candump stamps from 1970)", start_ns);
  }
  if (interface.empty() || interface.find_first_of(" \t\r\n") != std::string::npos) {
    return fmt::format("interface: '{}' is empty or holds blanks", interface);
  }
  // Without a stream the rate is not used.
  if (auto problem = rate_problem("truth_rate_hz", truth_rate_hz); truth != nullptr && problem) {
    return *problem + " (a truth stream is given)";
  }
  return std::nullopt;
}

uint64_t write_candump_recording(PixartBoxSimulator& simulator, std::ostream& out,
                                 const CandumpRecordingOptions& options, std::stop_token stop) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("CandumpRecordingOptions::" + *problem);
  }
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
  const bool with_truth = options.truth != nullptr;
  if (with_truth) *options.truth << kTruthCsvHeader << '\n';
  const SampleSchedule truth_schedule(with_truth ? options.truth_rate_hz : 1);
  uint64_t next_truth = 0;
  uint64_t written = 0;
  std::string line;
  for (uint64_t k = 0; k < samples && !stop.stop_requested(); ++k) {
    const double time_s = schedule.time_of(k);
    const int64_t sample_ns = options.start_ns + std::llround(time_s * 1e9);
    for (; with_truth && truth_schedule.time_of(next_truth) <= time_s; ++next_truth) {
      const double truth_s = truth_schedule.time_of(next_truth);
      write_truth(simulator, truth_s, options.start_ns + std::llround(truth_s * 1e9),
                  *options.truth);
    }
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
  if (with_truth && !options.truth->flush()) {
    throw std::runtime_error("cannot write the ground truth");
  }
  return written;
}

}  // namespace mocap::pixart
