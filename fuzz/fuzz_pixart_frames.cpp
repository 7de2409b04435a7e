// The PixArt boxes' CAN frames, as a raw CAN socket delivers them (one struct can_frame per 16
// bytes after a 3-byte header: base ID, big-endian, and box count, within the bridge's
// parameter ranges). Whatever the bus carries, the decoder counts each frame once (decoded,
// wrong length or unknown ID), yields only points on the sensor, and what it decodes encodes
// back to the same points; the sample assembler loses no point and never merges more than a
// camera's four slots.
#include <linux/can.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <vector>

#include "common/can_io/socketcan.hpp"
#include "pixart/pixart_bridge/camera_samples.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"

namespace {

using mocap::pixart::CameraSample;
using mocap::pixart::PixartPoint;

uint64_t frame_counts(const mocap::pixart::PixartDecodeStats& s) {
  return s.frames + s.wrong_length + s.unknown_id;
}

uint64_t slot_counts(const mocap::pixart::PixartDecodeStats& s) {
  return s.points + s.empty_slots + s.invalid_points;
}

bool same_points(const std::vector<PixartPoint>& a, const std::vector<PixartPoint>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].camera_id != b[i].camera_id || a[i].point_id != b[i].point_id || a[i].x != b[i].x ||
        a[i].y != b[i].y || a[i].stamp_ns != b[i].stamp_ns) {
      return false;
    }
  }
  return true;
}

// Checks a sample leaving the assembler and returns its point count.
size_t check_sample(const CameraSample& sample) {
  if (sample.points.size() > mocap::pixart::kPointsPerCamera) std::abort();
  for (const PixartPoint& point : sample.points) {
    if (point.camera_id != sample.camera_id) std::abort();
  }
  return sample.points.size();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mocap::pixart;
  constexpr size_t kHeader = 3;
  if (size < kHeader) return 0;
  PixartDecoderOptions options;
  options.base_id = (static_cast<uint32_t>(data[0]) << 8 | data[1]) & 0x7FF;
  options.boxes = 1 + data[2] % 64;
  std::optional<PixartDecoder> decoder;
  try {
    decoder.emplace(options);
  } catch (const std::invalid_argument&) {
    return 0;
  }
  CameraSampleAssembler assembler;
  size_t points_in = 0, points_out = 0;
  std::vector<PixartPoint> points;
  for (size_t offset = kHeader; offset + sizeof(can_frame) <= size; offset += sizeof(can_frame)) {
    can_frame linux_frame;
    std::memcpy(&linux_frame, data + offset, sizeof(linux_frame));
    mocap::can::CanFrame frame = mocap::can::from_linux_frame(linux_frame);
    frame.stamp_ns = static_cast<int64_t>(offset);

    const PixartDecodeStats before = decoder->stats();
    points.clear();
    const std::optional<uint16_t> camera = decoder->decode(frame, points);
    const PixartDecodeStats& after = decoder->stats();
    if (frame_counts(after) != frame_counts(before) + 1) std::abort();
    if (camera.has_value() != (after.frames == before.frames + 1)) std::abort();
    if (!camera) {
      if (!points.empty() || slot_counts(after) != slot_counts(before)) std::abort();
      continue;
    }
    if (slot_counts(after) != slot_counts(before) + 2) std::abort();
    if (points.size() != after.points - before.points) std::abort();
    if (*camera >= kCamerasPerBox * options.boxes) std::abort();
    const int half = static_cast<int>((frame.id - options.base_id) & 1u);
    std::array<PointSlot, 2> slots;
    for (const PixartPoint& point : points) {
      if (point.camera_id != *camera || point.x >= kSensorWidth || point.y >= kSensorHeight ||
          point.x == kNoPoint || point.stamp_ns != frame.stamp_ns || point.point_id / 2 != half) {
        std::abort();
      }
      slots[point.point_id % 2] = std::array<uint16_t, 2>{point.x, point.y};
    }
    PixartDecoder again(options);
    std::vector<PixartPoint> back;
    again.decode(encode_pixart_frame(options.base_id, *camera, half, slots, frame.stamp_ns), back);
    if (!same_points(back, points)) std::abort();

    points_in += points.size();
    if (auto sample = assembler.add(*camera, half, frame.stamp_ns, points)) {
      points_out += check_sample(*sample);
    }
  }
  const std::vector<CameraSample> rest = assembler.flush();
  if (rest.size() > static_cast<size_t>(kCamerasPerBox * options.boxes)) std::abort();
  for (const CameraSample& sample : rest) points_out += check_sample(sample);
  if (points_out != points_in) std::abort();
  return 0;
}
