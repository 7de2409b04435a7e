// mocap_calibration_record: the calibration board as the PixArt cameras saw it, from a candump
// log of the box's CAN frames to a calibration data file (board_recording.hpp).
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <mocap/calibration/board_recording.hpp>

#include "camera_samples.hpp"
#include "candump_log.hpp"
#include "pixart_decoder.hpp"

namespace {

using namespace mocap;
using namespace mocap::calibration;

constexpr const char* kUsage = R"(usage:
  mocap_calibration_record --candump LOG --output DATA.json [--base-id 0x100]
                           [--camera-names camera0,camera1,...] [--period S] [--pause S]

  --candump       a candump -L log of the PixArt box's CAN frames (record one with
                  `candump -L can0 > LOG`, or let pixart_box_sim write one); recording live
                  from the bus is not supported yet
  --output        the data file to write: one frame per cycle of the board's LEDs, holding
                  every camera that saw all four LEDs in that cycle
  --base-id       CAN ID of box 0, camera 0 (default 0x100)
  --camera-names  the names the data file gives cameras 0, 1, ... (default camera<id>); they
                  must match the calibration configuration's cameras
  --period        from one LED lighting to the next, seconds (default 0.2)
  --pause         the board's further dark time after LED 3, seconds (default 0.3): it tells
                  which LED is LED 0
exit status: 0 written; 1 unreadable log, no complete board cycle, unwritable output;
2 bad arguments
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

struct Arguments {
  std::string candump, output;
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
    if (option == "--candump") {
      arguments.candump = value;
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
  if (arguments.candump.empty()) usage_error("--candump LOG is required");
  if (arguments.output.empty()) usage_error("--output DATA.json is required");
  try {
    group_shots({}, arguments.shots);
  } catch (const std::invalid_argument& e) {
    usage_error(fmt::format("--period {} --pause {}: {}", arguments.shots.period_s,
                            arguments.shots.pause_s, e.what()));
  }
  return arguments;
}

struct LogPoints {
  std::vector<RawPoint> points;
  uint64_t frames = 0;
};

// Every point of every camera sample in the log, stamped with its sample's time.
LogPoints read_points(const std::string& path, pixart::PixartDecoder& decoder) {
  LogPoints log;
  can::CandumpReader reader(path);
  pixart::CameraSampleAssembler assembler;
  auto add = [&log](const pixart::CameraSample& sample) {
    for (const pixart::PixartPoint& point : sample.points) {
      log.points.push_back({sample.stamp_ns, point.camera_id, Eigen::Vector2d(point.x, point.y)});
    }
  };
  std::vector<pixart::PixartPoint> points;
  while (auto record = reader.next()) {
    ++log.frames;
    points.clear();
    auto camera = decoder.decode(record->frame, points);
    if (!camera) continue;
    const int half = static_cast<int>((record->frame.id - decoder.options().base_id) & 1u);
    if (auto sample = assembler.add(*camera, half, record->frame.stamp_ns, points)) add(*sample);
  }
  for (const pixart::CameraSample& sample : assembler.flush()) add(sample);
  return log;
}

std::string name_of(const std::map<int, std::string>& names, int camera_id) {
  auto found = names.find(camera_id);
  return found != names.end() ? found->second : fmt::format("camera{}", camera_id);
}

}  // namespace

int main(int argc, char** argv) {
  const Arguments arguments = parse_arguments(argc, argv);
  try {
    pixart::PixartDecoder decoder(arguments.decoder);
    const LogPoints log = read_points(arguments.candump, decoder);
    BlinkStats blink_stats;
    const std::vector<Blink> blinks = average_blinks(log.points, {}, &blink_stats);
    ShotStats shot_stats;
    const std::vector<BoardShot> shots = group_shots(blinks, arguments.shots, &shot_stats);
    std::string per_camera;
    for (const auto& [camera, count] : shot_stats.shots_per_camera) {
      per_camera += fmt::format("{}{} {}", per_camera.empty() ? "" : ", ",
                                name_of(arguments.camera_names, camera), count);
    }
    fmt::print(
        "mocap_calibration_record: {}: {} CAN frames ({} not PixArt), {} points; {} blinks ({} "
        "glitches dropped); {} shots{}, {} incomplete cycles dropped, {} runs without the "
        "board's pause\n",
        arguments.candump, log.frames, decoder.stats().unknown_id + decoder.stats().wrong_length,
        log.points.size(), blink_stats.blinks, blink_stats.glitches, shot_stats.shots,
        per_camera.empty() ? "" : " (" + per_camera + ")", shot_stats.dropped_cycles,
        shot_stats.overlong_runs);
    if (shots.empty()) {
      fmt::print(stderr,
                 "mocap_calibration_record: {}: no complete cycle of the board's four LEDs{}; "
                 "nothing written\n",
                 arguments.candump,
                 shot_stats.overlong_runs > 0
                     ? fmt::format(" (does the board pause {} s after LED 3? see --pause)",
                                   arguments.shots.pause_s)
                     : std::string());
      return 1;
    }
    write_data_file(arguments.output, shots, arguments.camera_names, arguments.shots);
    fmt::print("mocap_calibration_record: {} frames -> {}\n",
               group_frames(shots, arguments.shots).size(), arguments.output);
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_calibration_record: {}\n", e.what());
    return 1;
  }
}
