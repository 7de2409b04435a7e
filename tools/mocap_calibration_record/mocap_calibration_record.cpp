// mocap_calibration_record: the calibration board as the PixArt cameras saw it, from the box's
// CAN frames (a candump log, or the live bus through an SLCAN adaptor or SocketCAN) to a
// calibration data file (board_recording.hpp).
#include <signal.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <mocap/calibration/board_recording.hpp>

#include "common/can_io/can_source.hpp"
#include "common/can_io/slcan.hpp"
#include "pixart/pixart_bridge/camera_samples.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"

namespace {

using namespace mocap;
using namespace mocap::calibration;

constexpr const char* kUsage = R"(usage:
  mocap_calibration_record --candump LOG --output DATA.json [OPTIONS]
  mocap_calibration_record --slcan DEVICE [--bitrate 1000000] --duration S --output DATA.json
                           [OPTIONS]
  mocap_calibration_record --socketcan IFACE --duration S --output DATA.json [OPTIONS]
OPTIONS: [--base-id 0x100] [--camera-names camera0,camera1,...] [--period S] [--pause S]

  --candump       a candump -L log of the PixArt box's CAN frames (record one with
                  `candump -L can0 > LOG`, or let pixart_box_sim write one), read to its end
  --slcan         the serial device of a USB-CAN adaptor on the box's bus that speaks SLCAN
                  (e.g. /dev/ttyACM0); the tool opens the CAN channel itself, no slcand needed
  --bitrate       --slcan: the bus's bitrate, bit/s (default 1000000)
  --socketcan     a SocketCAN interface on the box's bus, already up (e.g. can0)
  --duration      --slcan, --socketcan: how long to record the bus, seconds; Ctrl-C stops
                  earlier and keeps what was recorded
  --output        the data file to write: one frame per cycle of the board's LEDs, holding
                  every camera that saw all four LEDs in that cycle
  --base-id       CAN ID of box 0, camera 0 (default 0x100)
  --camera-names  the names the data file gives cameras 0, 1, ... (default camera<id>); they
                  must match the calibration configuration's cameras
  --period        from one LED lighting to the next, seconds (default 0.2)
  --pause         the board's further dark time after LED 3, seconds (default 0.3): it tells
                  which LED is LED 0
exit status: 0 written; 1 unreadable log, a device that cannot be opened or fails while
recording (what was recorded until then is still written), no complete board cycle, unwritable
output; 2 bad arguments
)";

[[noreturn]] void usage_error(std::string_view message) {
  fmt::print(stderr, "mocap_calibration_record: {}\n\n{}", message, kUsage);
  std::exit(2);
}

double parse_seconds(std::string_view option, const std::string& text) {
  double value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !(value > 0)) {
    usage_error(fmt::format("{} {}: expected a positive number of seconds", option, text));
  }
  return value;
}

uint32_t parse_base_id(const std::string& text) {
  std::string_view digits = text;
  int base = 10;
  if (digits.starts_with("0x") || digits.starts_with("0X")) {
    digits.remove_prefix(2);
    base = 16;
  }
  uint32_t value = 0;
  auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value, base);
  if (digits.empty() || error != std::errc() || end != digits.data() + digits.size() ||
      value > can::kMaxStandardId) {
    usage_error(fmt::format("--base-id {}: expected a CAN ID, 0 to 0x7FF", text));
  }
  return value;
}

std::map<int, std::string> parse_camera_names(const std::string& text) {
  std::map<int, std::string> names;
  size_t start = 0;
  for (int id = 0;; ++id) {
    const size_t comma = text.find(',', start);
    const std::string name = text.substr(start, comma == std::string::npos ? comma : comma - start);
    if (name.empty()) usage_error(fmt::format("--camera-names {}: a name is empty", text));
    for (const auto& [other_id, other] : names) {
      if (other == name) {
        usage_error(fmt::format("--camera-names {}: '{}' is given twice", text, name));
      }
    }
    names[id] = name;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return names;
}

int parse_bitrate(const std::string& text) {
  int value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) {
    usage_error(fmt::format("--bitrate {}: expected a number of bit/s", text));
  }
  try {
    can::slcan_open_commands(value);
  } catch (const std::invalid_argument& e) {
    usage_error(fmt::format("--bitrate {}: {}", text, e.what()));
  }
  return value;
}

// Where the frames come from: exactly one of these options.
constexpr std::string_view kSources[] = {"--candump", "--slcan", "--socketcan"};

struct Arguments {
  std::string source_option;  // one of kSources
  std::string source;         // its value: the log, the device, the interface
  std::optional<int> bitrate;
  std::optional<double> duration_s;
  std::string output;
  pixart::PixartDecoderOptions decoder;
  std::map<int, std::string> camera_names;
  ShotOptions shots;
};

Arguments parse_arguments(int argc, char** argv) {
  Arguments arguments;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--help" || option == "-h") {
      fmt::print("{}", kUsage);
      std::exit(0);
    }
    if (i + 1 >= argc) usage_error(fmt::format("{} needs a value", option));
    const std::string value = argv[++i];
    if (std::find(std::begin(kSources), std::end(kSources), option) != std::end(kSources)) {
      if (!arguments.source_option.empty()) {
        usage_error(fmt::format("{} and {}: give exactly one of --candump, --slcan, --socketcan",
                                arguments.source_option, option));
      }
      arguments.source_option = option;
      arguments.source = value;
    } else if (option == "--bitrate") {
      arguments.bitrate = parse_bitrate(value);
    } else if (option == "--duration") {
      arguments.duration_s = parse_seconds(option, value);
    } else if (option == "--output") {
      arguments.output = value;
    } else if (option == "--base-id") {
      arguments.decoder.base_id = parse_base_id(value);
    } else if (option == "--camera-names") {
      arguments.camera_names = parse_camera_names(value);
    } else if (option == "--period") {
      arguments.shots.period_s = parse_seconds(option, value);
    } else if (option == "--pause") {
      arguments.shots.pause_s = parse_seconds(option, value);
    } else {
      usage_error(fmt::format("unknown option {}", option));
    }
  }
  if (arguments.source_option.empty()) {
    usage_error("a source is required: --candump LOG, --slcan DEVICE or --socketcan IFACE");
  }
  const bool live = arguments.source_option != "--candump";
  if (live && !arguments.duration_s) {
    usage_error(fmt::format("{} needs --duration SECONDS", arguments.source_option));
  }
  if (!live && arguments.duration_s) {
    usage_error("--duration is for --slcan and --socketcan; a log is read to its end");
  }
  if (arguments.bitrate && arguments.source_option != "--slcan") {
    usage_error("--bitrate is for --slcan only");
  }
  if (arguments.output.empty()) usage_error("--output DATA.json is required");
  try {
    group_shots({}, arguments.shots);
  } catch (const std::invalid_argument& e) {
    usage_error(fmt::format("--period {} --pause {}: {}", arguments.shots.period_s,
                            arguments.shots.pause_s, e.what()));
  }
  return arguments;
}

std::unique_ptr<can::CanSource> open_source(const Arguments& arguments) {
  if (arguments.source_option == "--slcan") {
    return can::open_slcan(
        {.device = arguments.source,
         .bitrate = arguments.bitrate.value_or(can::SlcanSourceOptions{}.bitrate)});
  }
  if (arguments.source_option == "--socketcan") return can::open_socketcan(arguments.source);
  return can::open_candump({.file = arguments.source, .recorded_timing = false});
}

// Set by Ctrl-C: the recording stops and what it holds is kept.
volatile std::sig_atomic_t interrupt_requested = 0;

void on_interrupt(int) { interrupt_requested = 1; }

// The first Ctrl-C stops the recording; a second one, the handler reset, ends the process.
void stop_on_interrupt() {
  struct sigaction action = {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
}

struct Recording {
  std::vector<RawPoint> points;
  uint64_t frames = 0;
  double seconds = 0;  // from the first read to the last
  bool interrupted = false;
  std::string failure;  // why the source failed while recording; empty if it did not
};

using Clock = std::chrono::steady_clock;

// Every point of every camera sample `source` delivers, stamped with its sample's time, until
// the source finishes (the end of a log), `deadline` passes, Ctrl-C or the source fails.
Recording read_points(can::CanSource& source, pixart::PixartDecoder& decoder,
                      std::optional<Clock::time_point> deadline) {
  Recording recording;
  pixart::CameraSampleAssembler assembler;
  auto add = [&recording](const pixart::CameraSample& sample) {
    for (const pixart::PixartPoint& point : sample.points) {
      recording.points.push_back(
          {sample.stamp_ns, point.camera_id, Eigen::Vector2d(point.x, point.y)});
    }
  };
  std::vector<pixart::PixartPoint> points;
  const Clock::time_point start = Clock::now();
  while (!source.finished()) {
    if (interrupt_requested) {
      recording.interrupted = true;
      break;
    }
    // Short reads, so that Ctrl-C stops within a tenth of a second.
    std::chrono::milliseconds timeout(100);
    if (deadline) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(*deadline - Clock::now());
      if (left.count() <= 0) break;
      timeout = std::min(timeout, left);
    }
    std::vector<can::CanFrame> frames;
    try {
      frames = source.read(timeout);
    } catch (const can::CanSourceError& e) {
      recording.failure = e.what();
      break;
    }
    for (const can::CanFrame& frame : frames) {
      ++recording.frames;
      points.clear();
      auto camera = decoder.decode(frame, points);
      if (!camera) continue;
      const int half = static_cast<int>((frame.id - decoder.options().base_id) & 1u);
      if (auto sample = assembler.add(*camera, half, frame.stamp_ns, points)) add(*sample);
    }
  }
  recording.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  for (const pixart::CameraSample& sample : assembler.flush()) add(sample);
  return recording;
}

std::string name_of(const std::map<int, std::string>& names, int camera_id) {
  auto found = names.find(camera_id);
  return found != names.end() ? found->second : fmt::format("camera{}", camera_id);
}

}  // namespace

int main(int argc, char** argv) {
  const Arguments arguments = parse_arguments(argc, argv);
  const std::string& name = arguments.source;
  try {
    pixart::PixartDecoder decoder(arguments.decoder);
    const std::unique_ptr<can::CanSource> source = open_source(arguments);
    std::optional<Clock::time_point> deadline;
    if (arguments.duration_s) {
      fmt::print("mocap_calibration_record: recording {} for {} s (Ctrl-C stops earlier)\n",
                 source->description(), *arguments.duration_s);
      std::fflush(stdout);
      deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(*arguments.duration_s));
    }
    stop_on_interrupt();
    const Recording recording = read_points(*source, decoder, deadline);
    if (recording.interrupted) {
      fmt::print("mocap_calibration_record: stopped after {:.1f} s; keeping what was recorded\n",
                 recording.seconds);
    }
    if (!recording.failure.empty()) {
      fmt::print(stderr,
                 "mocap_calibration_record: {}; recording stopped after {:.1f} s, keeping what "
                 "was recorded\n",
                 recording.failure, recording.seconds);
    }
    BlinkStats blink_stats;
    const std::vector<Blink> blinks = average_blinks(recording.points, {}, &blink_stats);
    ShotStats shot_stats;
    const std::vector<BoardShot> shots = group_shots(blinks, arguments.shots, &shot_stats);
    std::string per_camera;
    for (const auto& [camera, count] : shot_stats.shots_per_camera) {
      per_camera += fmt::format("{}{} {}", per_camera.empty() ? "" : ", ",
                                name_of(arguments.camera_names, camera), count);
    }
    const uint64_t unreadable = source->read_errors();
    fmt::print(
        "mocap_calibration_record: {}: {} CAN frames ({} not PixArt{}), {} points; {} blinks ({} "
        "glitches dropped); {} shots{}, {} incomplete cycles dropped, {} runs without the "
        "board's pause\n",
        name, recording.frames, decoder.stats().unknown_id + decoder.stats().wrong_length,
        unreadable > 0 ? fmt::format(", {} unreadable", unreadable) : std::string(),
        recording.points.size(), blink_stats.blinks, blink_stats.glitches, shot_stats.shots,
        per_camera.empty() ? "" : " (" + per_camera + ")", shot_stats.dropped_cycles,
        shot_stats.overlong_runs);
    if (shots.empty()) {
      fmt::print(stderr,
                 "mocap_calibration_record: {}: no complete cycle of the board's four LEDs{}; "
                 "nothing written\n",
                 name,
                 shot_stats.overlong_runs > 0
                     ? fmt::format(" (does the board pause {} s after LED 3? see --pause)",
                                   arguments.shots.pause_s)
                     : std::string());
      return 1;
    }
    write_data_file(arguments.output, shots, arguments.camera_names, arguments.shots);
    fmt::print("mocap_calibration_record: {} frames -> {}\n",
               group_frames(shots, arguments.shots).size(), arguments.output);
    return recording.failure.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_calibration_record: {}\n", e.what());
    return 1;
  }
}
