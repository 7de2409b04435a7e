// The cameras' messages of one capture time gathered (frame_assembler.hpp): out of order and
// stamped a little apart, a late camera, a camera that stops and comes back.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "volume/frame_assembly/frame_assembler.hpp"

namespace mocap::volume {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
using Frames = FrameAssembler<int>;

constexpr int64_t kPeriodNs = 8'333'333;  // 120 Hz

int count_messages(const AssembledFrame<int>& frame) {
  return static_cast<int>(std::count_if(frame.messages.begin(), frame.messages.end(),
                                        [](const auto& m) { return m.has_value(); }));
}

// Four cameras, their stamps up to a millisecond apart, arriving in any order: each capture
// time one frame, whole, in order, as soon as its last message is in.
TEST(FrameAssembler, GathersOneFramePerCaptureTimeInOrder) {
  Frames frames(4);
  std::mt19937 random(4);
  std::uniform_int_distribution<int64_t> jitter(-500'000, 500'000);
  Clock::time_point now{};
  std::vector<AssembledFrame<int>> out;
  for (int k = 0; k < 50; ++k) {
    std::vector<int> order = {0, 1, 2, 3};
    std::shuffle(order.begin(), order.end(), random);
    for (int camera : order) {
      now += milliseconds(1);
      frames.add(camera, k * kPeriodNs + jitter(random), 100 * k + camera, now);
    }
    for (auto& frame : frames.take_ready(now)) out.push_back(std::move(frame));
  }
  ASSERT_EQ(out.size(), 50u);
  for (int k = 0; k < 50; ++k) {
    EXPECT_TRUE(out[k].complete);
    ASSERT_EQ(count_messages(out[k]), 4);
    for (int camera = 0; camera < 4; ++camera)
      EXPECT_EQ(*out[k].messages[camera], 100 * k + camera);
  }
  EXPECT_EQ(frames.late_drops(), 0);
}

// A camera later than the wait: the frame goes without it, and its message, when it comes, is
// dropped and counted; a newer frame does not overtake an older one still waiting.
TEST(FrameAssembler, ALateCameraIsNotWaitedForBeyondTheWait) {
  Frames frames(3, {.wait = milliseconds(5)});
  Clock::time_point t0{};
  for (int camera = 0; camera < 3; ++camera) frames.add(camera, 0, camera, t0);  // heard once
  ASSERT_EQ(frames.take_ready(t0).size(), 1u);
  frames.add(0, kPeriodNs, 10, t0 + milliseconds(1));
  frames.add(1, kPeriodNs, 11, t0 + milliseconds(1));
  frames.add(0, 2 * kPeriodNs, 20, t0 + milliseconds(2));
  frames.add(1, 2 * kPeriodNs, 21, t0 + milliseconds(2));
  frames.add(2, 2 * kPeriodNs, 22, t0 + milliseconds(2));  // the newer frame is whole
  EXPECT_TRUE(frames.take_ready(t0 + milliseconds(5)).empty());
  const auto ready = frames.take_ready(t0 + milliseconds(7));
  ASSERT_EQ(ready.size(), 2u);
  EXPECT_EQ(ready[0].stamp_ns, kPeriodNs);
  EXPECT_FALSE(ready[0].complete);
  EXPECT_EQ(count_messages(ready[0]), 2);
  EXPECT_TRUE(ready[1].complete);
  frames.add(2, kPeriodNs, 12, t0 + milliseconds(8));
  EXPECT_EQ(frames.late_drops(), 1);
  EXPECT_TRUE(frames.take_ready(t0 + milliseconds(20)).empty());
}

// A camera that stops: once silent, frames no longer wait for it and say it is out; its next
// message takes it back.
TEST(FrameAssembler, ASilentCameraIsLeftOutUntilItComesBack) {
  Frames frames(2, {.wait = milliseconds(5), .silent_after = milliseconds(100)});
  Clock::time_point now{};
  int64_t stamp = 0;
  auto frame_of = [&](bool with_camera_1) {
    now += milliseconds(8);
    stamp += kPeriodNs;
    frames.add(0, stamp, 0, now);
    if (with_camera_1) frames.add(1, stamp, 1, now);
    return frames.take_ready(now);
  };
  ASSERT_EQ(frame_of(true).size(), 1u);
  // Camera 1 stops. Until it counts as silent, each frame waits out the wait for it.
  int waited = 0;
  while (true) {
    auto ready = frame_of(false);
    if (!ready.empty() && ready.back().silent[1]) {
      EXPECT_TRUE(ready.back().complete);
      EXPECT_FALSE(ready.back().messages[1].has_value());
      break;
    }
    ++waited;
    ASSERT_LT(waited, 20) << "camera 1 never counted as silent";
  }
  EXPECT_GE(waited * 8, 100 - 8);
  // From now on each frame comes out as its one live camera's message arrives.
  for (int k = 0; k < 5; ++k) {
    auto ready = frame_of(false);
    ASSERT_EQ(ready.size(), 1u);
    EXPECT_TRUE(ready[0].complete);
  }
  // Back: its first message is in the frame, and it is no longer silent.
  auto back = frame_of(true);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_FALSE(back[0].silent[1]);
  EXPECT_EQ(count_messages(back[0]), 2);
}

// At 240 Hz a frame lasts 4.2 ms: once the capture times show the rate, a frame waits at most
// that long for a late camera, not the 30 ms the options allow at most; a third of it with the
// share 1/3; with the share 0, the whole 30 ms.
TEST(FrameAssembler, TheWaitIsSizedToTheFrameRate) {
  constexpr int64_t kFrameNs = 4'166'667;  // 240 Hz
  for (double share : {FrameAssemblerOptions{}.wait_share_of_frame, 1.0 / 3.0, 0.0}) {
    SCOPED_TRACE(share);
    Frames frames(2, {.wait_share_of_frame = share});
    Clock::time_point now{};
    int64_t stamp = 0;
    for (int k = 0; k < 20; ++k) {  // both cameras, on time; one frame dropped on the way
      stamp += (k == 10 ? 2 : 1) * kFrameNs;
      now += std::chrono::nanoseconds(kFrameNs);
      frames.add(0, stamp, 0, now);
      frames.add(1, stamp, 1, now);
      ASSERT_EQ(frames.take_ready(now).size(), 1u);
    }
    EXPECT_EQ(frames.frame_period().count(), kFrameNs);
    const auto expected_wait = share > 0 ? std::chrono::round<std::chrono::nanoseconds>(
                                               std::chrono::nanoseconds(kFrameNs) * share)
                                         : milliseconds(30);
    EXPECT_EQ(frames.wait(), expected_wait);
    // Camera 1 late: the frame goes without it once the wait has run out, not before.
    stamp += kFrameNs;
    now += std::chrono::nanoseconds(kFrameNs);
    frames.add(0, stamp, 0, now);
    EXPECT_TRUE(frames.take_ready(now + expected_wait - std::chrono::microseconds(10)).empty());
    const auto ready = frames.take_ready(now + expected_wait);
    ASSERT_EQ(ready.size(), 1u);
    EXPECT_FALSE(ready[0].complete);
  }
}

// Not above 0, every camera would be silent and every frame complete at once; negative, no two
// stamps would be one capture time. Refused, naming the field.
// A fusion stalled for a third of a second (84 frames at 240 Hz ready at once) fuses the two
// newest and, of the rest, every frame that keeps the fused ones at most 20 ms apart, counting
// from the frame it fused before the stall; with nothing fused before, the newest two only.
TEST(FramesToFuse, ABacklogIsThinnedToTheGapTheTracksBridge) {
  const int64_t period_ns = 4'166'667, gap_ns = 20'000'000;
  std::vector<int64_t> stamps;
  for (int f = 1; f <= 84; ++f) stamps.push_back(f * period_ns);
  const std::vector<size_t> fused = frames_to_fuse(stamps, 0, 2, gap_ns);
  ASSERT_GE(fused.size(), 2u);
  EXPECT_EQ(fused[fused.size() - 2], 82u);
  EXPECT_EQ(fused.back(), 83u);
  int64_t last = 0;
  for (size_t i : fused) {
    EXPECT_LE(stamps[i] - last, gap_ns) << "frame " << i;
    last = stamps[i];
  }
  // Each fused frame is the last before the gap would run out: 4 frames of 4.17 ms apart.
  EXPECT_EQ(fused.size(), 2u + 84 / 4 - 1);
  EXPECT_EQ(fused[0], 3u);
  EXPECT_EQ(frames_to_fuse(stamps, std::nullopt, 2, gap_ns), (std::vector<size_t>{82, 83}));
  EXPECT_EQ(frames_to_fuse({}, 0, 2, gap_ns), std::vector<size_t>{});
}

TEST(FrameAssemblerOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(FrameAssemblerOptions{}.problem(), std::nullopt);
  EXPECT_EQ(FrameAssemblerOptions{.same_capture = std::chrono::microseconds(-1500)}.problem(),
            "same_capture: -1.5 ms is below 0");
  EXPECT_EQ(FrameAssemblerOptions{.wait = milliseconds(0)}.problem(), std::nullopt);  // no wait
  EXPECT_EQ(FrameAssemblerOptions{.wait = milliseconds(-5)}.problem(), "wait: -5 ms is below 0");
  EXPECT_EQ(FrameAssemblerOptions{.wait_share_of_frame = 1.5}.problem(),
            "wait_share_of_frame: 1.5 is not between 0 and 1");
  EXPECT_EQ(FrameAssemblerOptions{.silent_after = milliseconds(0)}.problem(),
            "silent_after: 0 ms is not above 0");
  try {
    Frames frames(2, {.silent_after = milliseconds(0)});
    ADD_FAILURE() << "silent_after 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "FrameAssemblerOptions::silent_after: 0 ms is not above 0");
  }
}

}  // namespace
}  // namespace mocap::volume
