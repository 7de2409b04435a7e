// Every message type through a bag both ways a deployment uses one: typed messages recorded by
// the Recorder (serialized by its writer thread) and read back as the bytes of the original,
// which the player deserializes into equal messages. Also the Recorder's own limits: a full
// bag ends the recording with the writer's error, counted drops, and a readable bag; a disk
// slower than the messages makes record() wait rather than drop.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include <fmt/format.h>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/bag/recorder.hpp>
#include <mocap/generated_message_types.hpp>

#include "messages/idl_schema.hpp"
#include "test/random_cdr.hpp"
#include "test/test_support.hpp"

namespace mocap::bag {
namespace {

constexpr int kPerType = 10;

std::vector<uint8_t> serialize(const MessageType& type, const void* message) {
  std::vector<uint8_t> bytes(type.serialized_size(message), 0);
  bytes.resize(type.serialize(message, bytes));
  return bytes;
}

TEST(BagMessageTypes, EveryTypeRoundTripsThroughTheRecorderAndThePlayersDeserialization) {
  test::TempDir dir;
  std::mt19937 random(11);
  // Per topic, the bytes of each message recorded, in order.
  std::map<std::string, std::vector<std::vector<uint8_t>>> recorded;
  std::map<std::string, const MessageType*> types;
  {
    Recorder recorder((dir / "types").string());
    int64_t stamp = 1'700'000'000'000'000'000;
    for (const MessageType* type : generated_message_types()) {
      IdlSchema schema;
      schema.parse(full_definition(*type));
      std::string topic = "/types/" + type->name();
      std::replace(topic.begin(), topic.end(), '/', '_');
      topic[0] = '/';
      types[topic] = type;
      const uint32_t id = recorder.add_topic({topic, type->name(), "cdr", {Qos::reliable()}, 0});
      for (int i = 0; i < kPerType; ++i) {
        std::vector<uint8_t> bytes = test::random_cdr(schema, type->name(), random);
        std::shared_ptr<void> message = type->create();
        type->deserialize(bytes, message.get());
        recorded[topic].push_back(bytes);
        recorder.record(id, stamp += 1000, std::move(message), type);
      }
    }
    EXPECT_EQ(recorder.close(), std::nullopt);
    EXPECT_EQ(recorder.stats().written, recorded.size() * kPerType);
    EXPECT_EQ(recorder.stats().dropped, 0u);
  }
  ASSERT_GE(recorded.size(), 23u);

  BagReader reader((dir / "types").string());
  EXPECT_TRUE(reader.problems().empty());
  std::map<std::string, size_t> seen;
  BagMessage message;
  while (reader.next(message)) {
    const std::string& topic = message.topic->name;
    ASSERT_TRUE(types.contains(topic)) << topic;
    const MessageType& type = *types[topic];
    EXPECT_EQ(message.topic->type, type.name());
    const size_t index = seen[topic]++;
    ASSERT_LT(index, recorded[topic].size());
    // The bag holds exactly the original bytes (the writer zeroes CDR's padding, as the
    // random originals have it) ...
    EXPECT_EQ(message.data, recorded[topic][index]) << topic << " message " << index;
    // ... and the player's deserialization gives the same message back.
    std::shared_ptr<void> played = type.create();
    ASSERT_NO_THROW(type.deserialize(message.data, played.get())) << topic;
    EXPECT_EQ(serialize(type, played.get()), recorded[topic][index]) << topic;
  }
  for (const auto& [topic, messages] : recorded) EXPECT_EQ(seen[topic], messages.size()) << topic;
}

TEST(BagMessageTypes, AFullBagEndsTheRecordingAndKeepsWhatWasCommitted) {
  test::TempDir dir;
  RecorderOptions options;
  options.writer.max_bytes = 256 * 1024;
  Recorder recorder((dir / "full").string(), options);
  const uint32_t id = recorder.add_topic({"/blob", "std_msgs/msg/Empty", "cdr", {}, 0});
  for (int i = 0; i < 100; ++i) {
    auto blob = std::make_shared<std::vector<uint8_t>>(10 * 1024, static_cast<uint8_t>(i));
    recorder.record(id, 1'000'000'000 + i, std::move(blob), nullptr);
  }
  const auto error = recorder.close();
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->find("full"), std::string::npos) << *error;
  const RecorderStats stats = recorder.stats();
  EXPECT_GT(stats.written, 0u);
  EXPECT_EQ(stats.written + stats.dropped, 100u);

  BagReader reader((dir / "full").string());
  ASSERT_EQ(reader.metadata().message_count, stats.written);
  BagMessage message;
  uint8_t expected = 0;
  while (reader.next(message)) {
    ASSERT_EQ(message.data.size(), 10u * 1024);
    EXPECT_EQ(message.data.front(), expected++);  // the first ones, in order
  }
}

TEST(BagMessageTypes, ARecorderBehindItsDiskWaitsForItInsteadOfDropping) {
  test::TempDir dir;
  RecorderOptions options;
  options.max_queued_bytes = 4 * 1024;  // four messages
  Recorder recorder((dir / "slow").string(), options);
  const uint32_t id = recorder.add_topic({"/blob", "std_msgs/msg/Empty", "cdr", {}, 0});
  size_t most_queued = 0;
  for (int i = 0; i < 2000; ++i) {
    auto blob = std::make_shared<std::vector<uint8_t>>(1024, static_cast<uint8_t>(i));
    recorder.record(id, 1'000'000'000 + i, std::move(blob), nullptr);
    most_queued = std::max(most_queued, recorder.stats().queued_bytes);
  }
  EXPECT_LE(most_queued, options.max_queued_bytes);
  ASSERT_FALSE(recorder.close().has_value());
  EXPECT_EQ(recorder.stats().written, 2000u);
  EXPECT_EQ(recorder.stats().dropped, 0u);
  BagReader reader((dir / "slow").string());
  BagMessage message;
  int n = 0;
  while (reader.next(message)) ASSERT_EQ(message.data.front(), static_cast<uint8_t>(n++));
  EXPECT_EQ(n, 2000);
}

}  // namespace
}  // namespace mocap::bag
