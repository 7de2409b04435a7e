// A `candump -L` log of the simulated box (candump_log.hpp), written as fast as the simulator
// runs: what a real box on the bus would have produced over `duration_s` of scene time, for
// the bridge to replay (source: candump) or for can-utils' canplayer. Optionally with the
// robots' ground truth beside it, as CSV on the log's own time scale, so that what a replay
// localizes can be compared with the truth by stamp:
//
//   stamp_ns,robot,x_m,y_m,theta_rad
//   1700000000000000000,robot_a,0.300000,0.000000,1.570796
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <stop_token>
#include <string>

#include "sim/pixart_box_sim/pixart_box_simulator.hpp"
#include "sim/pixart_box_sim/sample_schedule.hpp"

namespace mocap::pixart {

struct CandumpRecordingOptions {
  double duration_s = 10;  // scene time covered: the samples before it
  double rate_hz = 270;    // samples per second (each: two frames per camera)
  int64_t start_ns = 0;    // receive time of sample 0, nanoseconds since the Unix epoch
  std::string interface = "can0";
  // Ground truth: one row per robot every 1 / truth_rate_hz of scene time, from time 0, into
  // `truth` (none when null).
  std::ostream* truth = nullptr;
  double truth_rate_hz = 50;

  // Why these options cannot be used, naming the field ("rate_hz: 0 is not above 0"); nullopt
  // when they can. write_candump_recording throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// The header line of the ground-truth CSV.
inline constexpr const char* kTruthCsvHeader = "stamp_ns,robot,x_m,y_m,theta_rad";

// Writes the frames of every sample before options.duration_s, one line each. A sample's
// frames follow each other on the bus: frame i of sample k is stamped start + k/rate plus
// i · 130 µs (a classic 8-byte frame with stuffing at 1 Mbit/s), squeezed when the sample
// period is too short for that. Stops early, between samples, when `stop` is requested.
// Returns the number of frames written. Throws std::invalid_argument for options that cannot
// be used, std::runtime_error when a stream fails.
uint64_t write_candump_recording(PixartBoxSimulator& simulator, std::ostream& out,
                                 const CandumpRecordingOptions& options, std::stop_token stop = {});

}  // namespace mocap::pixart
