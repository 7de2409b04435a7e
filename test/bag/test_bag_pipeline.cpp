// The seed's test method (seed 000 §5.1, §5.4.3): record a live run of the tracking pipeline
// on the synthetic camera (images, ground truth and poses) with the bag_recorder component,
// replay the images into the pipeline with the bag_player component as fast as it goes, and
// get the very poses of the live run back. Both runs use the launch files in launch_yaml/.
#include <gtest/gtest.h>

#include <map>

#include <fmt/format.h>
#include <mocap/bag/bag_reader.hpp>

#include "test_support.hpp"

namespace mocap::bag {
namespace {

constexpr int kFrames = 30;

std::string launcher() { return (test::bin_dir() / "mocap_launch").string(); }

// Payloads of `topic`, by receive order.
std::vector<std::vector<uint8_t>> messages_of(const std::filesystem::path& bag,
                                              const std::string& topic) {
  BagReader reader(bag.string());
  EXPECT_TRUE(reader.problems().empty()) << bag;
  reader.set_topic_filter({topic});
  std::vector<std::vector<uint8_t>> payloads;
  BagMessage message;
  while (reader.next(message)) payloads.push_back(message.data);
  return payloads;
}

TEST(BagPipeline, ReplayingARecordedRunGivesItsPosesBack) {
  test::TempDir dir;
  const std::filesystem::path live = dir / "live", replayed = dir / "replayed";
  const std::string launch_dir = (test::source_dir() / "launch_yaml").string();
  const std::map<std::string, std::string> domain = {
      {"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(41))}};

  // The live run: kFrames frames at 30 Hz (1 s), stopped well after the last.
  auto [live_code, live_output] = test::run_command(
      {launcher(), launch_dir + "/record_tracking.yaml", "--duration", "6", "--set",
       "recorder.output=" + live.string(), "--set", fmt::format("camera.max_frames={}", kFrames),
       "--set", "camera.rate_hz=30"},
      domain, std::chrono::seconds(120));
  ASSERT_EQ(live_code, 0) << live_output;
  const auto live_images = messages_of(live, "/camera/ir/image_raw");
  const auto live_poses = messages_of(live, "/mocap/poses");
  ASSERT_EQ(live_images.size(), static_cast<size_t>(kFrames)) << live_output;
  ASSERT_EQ(live_poses.size(), static_cast<size_t>(kFrames)) << live_output;
  EXPECT_EQ(messages_of(live, "/camera/ir/ground_truth").size(), static_cast<size_t>(kFrames));

  // The replay: the player feeds the recorded images at rate 0 and ends the run after them.
  auto [replay_code, replay_output] = test::run_command(
      {launcher(), launch_dir + "/replay_tracking.yaml", "--set", "player.bag=" + live.string(),
       "--set", "recorder.output=" + replayed.string()},
      domain, std::chrono::seconds(120));
  ASSERT_EQ(replay_code, 0) << replay_output;
  EXPECT_NE(replay_output.find(fmt::format("played {} message(s)", 2 * kFrames)), std::string::npos)
      << replay_output;
  const auto replayed_poses = messages_of(replayed, "/mocap/poses");
  ASSERT_EQ(replayed_poses.size(), live_poses.size()) << replay_output;
  // The same poses, byte for byte: stamps (the recorded images'), identities and values.
  for (size_t i = 0; i < live_poses.size(); ++i) {
    EXPECT_EQ(replayed_poses[i], live_poses[i]) << "pose message " << i;
  }
}

}  // namespace
}  // namespace mocap::bag
