// PixArt frame decoding (docs/pixart_can.md) and the grouping of frames into camera samples.
#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <string>

#include "pixart/pixart_bridge/camera_samples.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"

namespace mocap::pixart {
namespace {

can::CanFrame frame_of(uint32_t id, std::vector<uint8_t> bytes) {
  can::CanFrame frame;
  frame.id = id;
  frame.length = static_cast<uint8_t>(bytes.size());
  for (size_t i = 0; i < bytes.size() && i < 8; ++i) frame.data[i] = bytes[i];
  return frame;
}

TEST(PixartDecoder, ReadsTwoBigEndianPointsPerFrame) {
  PixartDecoder decoder;
  std::vector<PixartPoint> points;
  // Box 0, camera 1, slots 2-3: ID 0x100 + 2 * 1 + 1. Slot 2 holds (0x123, 0x2FF = 767),
  // slot 3 (5, 1023): empty.
  auto camera =
      decoder.decode(frame_of(0x103, {0x01, 0x23, 0x02, 0xFF, 0x00, 0x05, 0x03, 0xFF}), points);
  ASSERT_EQ(camera, 1);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].camera_id, 1);
  EXPECT_EQ(points[0].point_id, 2);
  EXPECT_EQ(points[0].x, 0x123);
  EXPECT_EQ(points[0].y, 0x2FF);
}

TEST(PixartDecoder, BoxesCamerasAndHalves) {
  PixartDecoder decoder;
  std::vector<PixartPoint> points;
  // Box 2, camera 3: camera_id 11, IDs 0x116 (slots 0-1) and 0x117 (slots 2-3).
  for (uint32_t id : {0x116u, 0x117u}) {
    ASSERT_EQ(decoder.decode(frame_of(id, {0, 10, 0, 20, 0, 30, 0, 40}), points), 11);
  }
  ASSERT_EQ(points.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(points[i].camera_id, 11);
    EXPECT_EQ(points[i].point_id, i);
    EXPECT_EQ(points[i].x, i % 2 == 0 ? 10 : 30);
  }
  // A configurable base: 0x200.
  PixartDecoder other({0x200, 1});
  points.clear();
  EXPECT_EQ(other.decode(frame_of(0x205, {0, 1, 0, 2, 3, 255, 3, 255}), points), 2);
  EXPECT_EQ(points.size(), 1u);
  EXPECT_FALSE(other.decode(frame_of(0x208, {0, 1, 0, 2, 0, 1, 0, 2}), points));  // box 1
  EXPECT_EQ(other.stats().unknown_id, 1u);
}

TEST(PixartDecoder, DropsEmptyAndInvalidPointsAndCountsBadFrames) {
  PixartDecoder decoder;
  std::vector<PixartPoint> points;
  // 1023 in x, 1023 in y: empty slots.
  decoder.decode(frame_of(0x100, {0x03, 0xFF, 0x00, 0x10, 0x00, 0x10, 0x03, 0xFF}), points);
  // y = 768 and x = 1024: not a point the sensor can report.
  decoder.decode(frame_of(0x100, {0x00, 0x10, 0x03, 0x00, 0x04, 0x00, 0x00, 0x10}), points);
  EXPECT_TRUE(points.empty());
  EXPECT_EQ(decoder.stats().empty_slots, 2u);
  EXPECT_EQ(decoder.stats().invalid_points, 2u);
  // Wrong lengths, foreign IDs, extended and remote frames: counted, not decoded.
  EXPECT_FALSE(decoder.decode(frame_of(0x101, {1, 2, 3, 4}), points));
  EXPECT_FALSE(decoder.decode(frame_of(0x0FF, {0, 1, 0, 1, 0, 1, 0, 1}), points));
  EXPECT_FALSE(decoder.decode(frame_of(0x140, {0, 1, 0, 1, 0, 1, 0, 1}), points));
  can::CanFrame extended = frame_of(0x100, {0, 1, 0, 1, 0, 1, 0, 1});
  extended.extended = true;
  EXPECT_FALSE(decoder.decode(extended, points));
  can::CanFrame remote = frame_of(0x100, {});
  remote.remote = true;
  EXPECT_FALSE(decoder.decode(remote, points));
  EXPECT_EQ(decoder.stats().wrong_length, 1u);
  EXPECT_EQ(decoder.stats().unknown_id, 4u);
  EXPECT_EQ(decoder.stats().frames, 2u);
  EXPECT_TRUE(points.empty());
  EXPECT_THROW(PixartDecoder({0x7F0, 8}), std::invalid_argument);
  // 8 · 2^29 boxes wraps to 0 in 32 bits: refused, not taken as "no IDs".
  EXPECT_THROW(PixartDecoder({1, 1 << 29}), std::invalid_argument);
  EXPECT_NO_THROW(PixartDecoder({0, 256}));
  EXPECT_THROW(PixartDecoder({0, 257}), std::invalid_argument);
}

TEST(PixartDecoder, EncodeDecodeRoundTrip) {
  PixartDecoder decoder;
  for (uint16_t camera = 0; camera < 32; ++camera) {
    for (int half = 0; half < 2; ++half) {
      std::array<PointSlot, 2> slots = {std::array<uint16_t, 2>{uint16_t(camera * 31), 767},
                                        std::nullopt};
      std::vector<PixartPoint> points;
      ASSERT_EQ(decoder.decode(encode_pixart_frame(0x100, camera, half, slots, 42), points),
                camera);
      ASSERT_EQ(points.size(), 1u);
      EXPECT_EQ(points[0].x, camera * 31);
      EXPECT_EQ(points[0].y, 767);
      EXPECT_EQ(points[0].point_id, 2 * half);
      EXPECT_EQ(points[0].stamp_ns, 42);
    }
  }
  EXPECT_EQ(decoder.stats().empty_slots, 64u);
}

TEST(CameraSampleAssembler, PairsHalvesAndSurvivesLostFrames) {
  CameraSampleAssembler assembler;
  PixartPoint a{3, 0, 10, 20, 1}, b{3, 2, 30, 40, 2};
  EXPECT_FALSE(assembler.add(3, 0, 1, {a}));
  auto sample = assembler.add(3, 1, 2, {b});
  ASSERT_TRUE(sample);
  EXPECT_TRUE(sample->complete);
  EXPECT_EQ(sample->stamp_ns, 1);
  EXPECT_EQ(sample->points.size(), 2u);
  // Second half lost: the sample comes out incomplete when the next one begins.
  EXPECT_FALSE(assembler.add(3, 0, 3, {a}));
  sample = assembler.add(3, 0, 5, {});
  ASSERT_TRUE(sample);
  EXPECT_FALSE(sample->complete);
  EXPECT_EQ(sample->stamp_ns, 3);
  // First half lost: the second stands alone. Other cameras do not interfere.
  EXPECT_FALSE(assembler.add(4, 0, 6, {}));
  sample = assembler.add(3, 1, 6, {b});  // completes camera 3's sample begun at 5
  ASSERT_TRUE(sample);
  EXPECT_TRUE(sample->complete);
  sample = assembler.add(3, 1, 7, {b});
  ASSERT_TRUE(sample);
  EXPECT_FALSE(sample->complete);
  EXPECT_EQ(assembler.flush().size(), 1u);  // camera 4's
  EXPECT_EQ(assembler.incomplete_samples(), 3u);
}

// The bridge's parameter ranges keep a launch file's options usable; options built in code get
// the same checks from the decoder, which names the field.
TEST(PixartDecoderOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(PixartDecoderOptions{}.problem(), std::nullopt);
  EXPECT_EQ((PixartDecoderOptions{.base_id = 0x100, .boxes = 0}.problem()), "boxes: 0 is below 1");
  EXPECT_EQ((PixartDecoderOptions{.base_id = 0x100, .boxes = 300}.problem()),
            "boxes: 300; at most 256 boxes of 8 IDs fit the 11-bit CAN IDs");
  EXPECT_EQ((PixartDecoderOptions{.base_id = 0x7F0, .boxes = 8}.problem()),
            "base_id: 0x7f0 with 8 boxes needs CAN IDs up to 0x82f, above 0x7ff");
  // A base far beyond 11 bits does not wrap around into the range.
  EXPECT_EQ((PixartDecoderOptions{.base_id = 0xFFFFFFFF, .boxes = 1}.problem()),
            "base_id: 0xffffffff with 1 boxes needs CAN IDs up to 0x100000006, above 0x7ff");
  try {
    PixartDecoder decoder({.base_id = 0x100, .boxes = 0});
    ADD_FAILURE() << "no boxes accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "PixartDecoderOptions::boxes: 0 is below 1");
  }
}

}  // namespace
}  // namespace mocap::pixart
