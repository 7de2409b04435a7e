// Decode throughput of the PixArt bridge, one core: SLCAN text -> CAN frames -> PixArt points,
// and candump lines -> frames -> points, against a plain sscanf-based SLCAN reader measured in
// the same run (what a first implementation would write).
//   build/bin/pixart_decode_bench [--quick]
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "common/can_io/candump_log.hpp"
#include "common/can_io/slcan.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"

namespace {

using namespace mocap;
using Clock = std::chrono::steady_clock;

// A second of a busy bus: 16 cameras at 270 Hz, two frames a sample, 0-4 points each.
std::vector<can::CanFrame> bus_traffic(int frames) {
  std::mt19937 random(3);
  std::uniform_int_distribution<int> x(0, 1023), y(0, 767), present(0, 3);
  std::vector<can::CanFrame> out;
  for (int i = 0; out.size() < static_cast<size_t>(frames); ++i) {
    auto camera = static_cast<uint16_t>(i % 16);
    for (int half = 0; half < 2; ++half) {
      std::array<pixart::PointSlot, 2> slots;
      for (auto& slot : slots) {
        if (present(random) > 0) {
          slot = std::array<uint16_t, 2>{uint16_t(x(random)), uint16_t(y(random))};
        }
      }
      out.push_back(pixart::encode_pixart_frame(0x100, camera, half, slots));
    }
  }
  return out;
}

// The reference: one sscanf per message, then the same decoding.
size_t sscanf_reader(const std::string& text, pixart::PixartDecoder& decoder,
                     std::vector<pixart::PixartPoint>& points) {
  size_t frames = 0;
  const char* p = text.c_str();
  while (*p) {
    const char* end = std::strchr(p, '\r');
    if (end == nullptr) break;
    unsigned id = 0, length = 0;
    unsigned bytes[8] = {};
    if (*p == 't' &&
        std::sscanf(p + 1, "%3x%1u%2x%2x%2x%2x%2x%2x%2x%2x", &id, &length, &bytes[0], &bytes[1],
                    &bytes[2], &bytes[3], &bytes[4], &bytes[5], &bytes[6], &bytes[7]) >= 2) {
      can::CanFrame frame;
      frame.id = id;
      frame.length = static_cast<uint8_t>(length);
      for (int i = 0; i < 8; ++i) frame.data[i] = static_cast<uint8_t>(bytes[i]);
      decoder.decode(frame, points);
      ++frames;
    }
    p = end + 1;
  }
  return frames;
}

template <class Step>
double frames_per_second(size_t frames_per_step, double seconds, Step&& step) {
  size_t frames = 0;
  auto start = Clock::now();
  double elapsed = 0;
  while (elapsed < seconds) {
    step();
    frames += frames_per_step;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  }
  return frames / elapsed;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const double seconds = quick ? 0.5 : 3.0;
  const std::vector<can::CanFrame> frames = bus_traffic(8640);  // one second of 16 cameras
  std::string slcan;
  std::vector<std::string> candump;
  for (size_t i = 0; i < frames.size(); ++i) {
    slcan += can::encode_slcan(frames[i]);
    candump.push_back(can::format_candump_line(
        {1'700'000'000'000'000'000 + static_cast<int64_t>(i) * 115'740, "can0", frames[i]}));
  }
  std::vector<pixart::PixartPoint> points;
  points.reserve(4 * frames.size());

  double decode_only = frames_per_second(frames.size(), seconds, [&] {
    pixart::PixartDecoder decoder;
    points.clear();
    for (const auto& frame : frames) decoder.decode(frame, points);
  });
  double slcan_rate = frames_per_second(frames.size(), seconds, [&] {
    pixart::PixartDecoder decoder;
    can::SlcanParser parser;
    points.clear();
    // As the bytes arrive from a USB adaptor: in chunks of a few hundred bytes.
    for (size_t at = 0; at < slcan.size(); at += 512) {
      parser.feed(std::string_view(slcan).substr(at, 512));
      for (const auto& frame : parser.take_frames()) decoder.decode(frame, points);
    }
  });
  double sscanf_rate = frames_per_second(frames.size(), seconds, [&] {
    pixart::PixartDecoder decoder;
    points.clear();
    sscanf_reader(slcan, decoder, points);
  });
  double candump_rate = frames_per_second(frames.size(), seconds, [&] {
    pixart::PixartDecoder decoder;
    points.clear();
    for (const auto& line : candump) decoder.decode(can::parse_candump_line(line).frame, points);
  });

  fmt::print("PixArt decoding, one thread, {} frames of 16 cameras per pass\n\n", frames.size());
  fmt::print("| path | frames/s | µs per frame | vs sscanf reference |\n|---|---:|---:|---:|\n");
  auto row = [&](const char* name, double rate) {
    fmt::print("| {} | {:.3g} | {:.3f} | {:.1f}x |\n", name, rate, 1e6 / rate, rate / sscanf_rate);
  };
  row("frames -> points (decoder alone)", decode_only);
  row("SLCAN text -> points (SlcanParser + decoder)", slcan_rate);
  row("candump lines -> points", candump_rate);
  row("SLCAN text -> points (sscanf reference)", sscanf_rate);
  fmt::print("\nA full bus: 4 boxes x 4 cameras x 270 Hz x 2 frames = 8640 frames/s.\n");
  return 0;
}
