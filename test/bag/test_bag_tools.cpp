// Bags as a user makes and uses them: mocap_bag recording topics of another process over
// DDS, describing and playing the bag back; the bag_recorder and bag_player components in
// launch files, with the tracking pipeline run live and then offline from its recording.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <csignal>
#include <functional>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <thread>
#include <tuple>

#include <fmt/format.h>
#include <geometry_msgs/msg/twist.hpp>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/bag/bag_writer.hpp>
#include <mocap/bag/playback.hpp>
#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <nlohmann/json.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "test/test_support.hpp"

namespace mocap::bag {
namespace {

using mocap_msgs::msg::FiducialArray;

constexpr int kMessages = 100;

std::string bag_tool() { return (test::bin_dir() / "mocap_bag").string(); }

// Each test its own DDS domain: ctest runs them side by side.
std::map<std::string, std::string> domain_environment(int slot) {
  return {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(slot))}};
}

void join_domain(int slot) {
  for (const auto& [key, value] : domain_environment(slot)) setenv(key.c_str(), value.c_str(), 1);
}

// Publishes kMessages numbered FiducialArrays on /numbers (reliable) and as many Twists on
// /velocity (sensor_data), 10 ms apart, once something subscribes to both.
class NumberedSource final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.publishes<FiducialArray>("/numbers", Qos::reliable(), "numbered arrays");
    spec.publishes<geometry_msgs::msg::Twist>("/velocity", Qos::sensor_data(), "numbered twists");
  }
  explicit NumberedSource(Context& context) : Component(context) {
    numbers_ = create_publisher<FiducialArray>("/numbers");
    velocity_ = create_publisher<geometry_msgs::msg::Twist>("/velocity");
    create_timer(std::chrono::milliseconds(10), [this] {
      if (sent_ == kMessages || numbers_.matched_subscribers() == 0 ||
          velocity_.matched_subscribers() == 0) {
        return;
      }
      FiducialArray array;
      array.header().stamp().sec(sent_);
      array.header().frame_id(fmt::format("message {}", sent_));
      array.fiducials().resize(static_cast<size_t>(sent_ % 7));
      numbers_.publish(std::move(array));
      geometry_msgs::msg::Twist twist;
      twist.linear().x(sent_);
      velocity_.publish(std::move(twist));
      if (++sent_ == kMessages) log().info("published all");
    });
  }

 private:
  Publisher<FiducialArray> numbers_;
  Publisher<geometry_msgs::msg::Twist> velocity_;
  int sent_ = 0;
};

// What a subscriber on /numbers received, in order.
struct Received {
  std::mutex mutex;
  std::vector<int> sequence;
};
Received received;

class NumbersSink final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<FiducialArray>("/numbers", Qos::reliable(), "numbered arrays");
  }
  explicit NumbersSink(Context& context) : Component(context) {
    create_subscription<FiducialArray>("/numbers", [](const FiducialArray& array) {
      std::lock_guard lock(received.mutex);
      received.sequence.push_back(array.header().stamp().sec());
    });
  }
};

HostOptions dds_host(const std::string& name) {
  return {.name = name, .threads = 2, .dds = {.enabled = true}};
}

// The count of `topic`'s messages committed to the bag so far (0 while it cannot be read).
uint64_t committed(const std::filesystem::path& bag, const std::string& topic) {
  try {
    BagReader reader(bag.string());
    for (const BagTopic& t : reader.metadata().topics) {
      if (t.name == topic) return t.message_count;
    }
  } catch (const BagError&) {
  }
  return 0;
}

bool wait_for(const std::function<bool()>& done, std::chrono::seconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return true;
}

TEST(MocapBag, RecordsDescribesAndPlaysTopicsOfAnotherProcess) {
  join_domain(40);
  test::TempDir dir;
  const std::filesystem::path bag = dir / "numbers";

  // Record both topics, published by this process, until every reliable one is in the bag
  // (a reader may look while the recorder writes); then Ctrl-C.
  {
    test::ChildProcess recorder({bag_tool(), "record", "-o", bag.string(), "/numbers", "/velocity"},
                                domain_environment(40), dir / "record.log");
    ComponentHost host(dds_host("bag_source"));
    host.add(make_component_factory<NumberedSource>("numbered_source"), {.name = "source"});
    host.start();
    ASSERT_TRUE(recorder.wait_for_output("subscribed to /velocity", std::chrono::seconds(30)))
        << recorder.output();
    ASSERT_TRUE(
        wait_for([&] { return committed(bag, "/numbers") == kMessages; }, std::chrono::seconds(60)))
        << recorder.output();
    recorder.signal(SIGINT);
    ASSERT_EQ(recorder.wait(std::chrono::seconds(30)), 0) << recorder.output();
    EXPECT_NE(recorder.output().find("recorded "), std::string::npos) << recorder.output();
    host.stop();
  }

  // The bag holds them in order, with their types and QoS, byte for byte what was published.
  BagReader reader(bag.string());
  EXPECT_TRUE(reader.problems().empty());
  const BagMetadata& metadata = reader.metadata();
  ASSERT_EQ(metadata.topics.size(), 2u);
  std::map<std::string, const BagTopic*> topics;
  for (const BagTopic& topic : metadata.topics) topics[topic.name] = &topic;
  ASSERT_EQ(topics.count("/numbers"), 1u);
  EXPECT_EQ(topics["/numbers"]->type, "mocap_msgs/msg/FiducialArray");
  EXPECT_EQ(topics["/velocity"]->type, "geometry_msgs/msg/Twist");
  ASSERT_EQ(topics["/numbers"]->offered_qos.size(), 1u);
  EXPECT_EQ(topics["/numbers"]->offered_qos[0].reliability, Reliability::Reliable);
  ASSERT_EQ(topics["/velocity"]->offered_qos.size(), 1u);
  EXPECT_EQ(topics["/velocity"]->offered_qos[0].reliability, Reliability::BestEffort);
  EXPECT_GT(topics["/velocity"]->message_count, 0u);  // best effort: most, maybe not all

  const MessageType& type = message_type<FiducialArray>();
  std::vector<int> numbers;
  int64_t previous_stamp = 0;
  BagMessage message;
  reader.set_topic_filter({"/numbers"});
  while (reader.next(message)) {
    FiducialArray array;
    type.deserialize(message.data, &array);
    numbers.push_back(array.header().stamp().sec());
    EXPECT_EQ(array.header().frame_id(), fmt::format("message {}", numbers.back()));
    EXPECT_EQ(array.fiducials().size(), static_cast<size_t>(numbers.back() % 7));
    EXPECT_GE(message.timestamp_ns, previous_stamp);
    previous_stamp = message.timestamp_ns;
  }
  std::vector<int> expected(kMessages);
  std::iota(expected.begin(), expected.end(), 0);
  EXPECT_EQ(numbers, expected);

  // info: what ros2 bag info shows.
  auto [info_code, info] = test::run_command({bag_tool(), "info", bag.string()});
  EXPECT_EQ(info_code, 0) << info;
  EXPECT_NE(info.find(fmt::format("Topic: /numbers | Type: mocap_msgs/msg/FiducialArray | Count: "
                                  "{} | Serialization Format: cdr",
                                  kMessages)),
            std::string::npos)
      << info;
  EXPECT_NE(info.find("Storage id:        mcap"), std::string::npos) << info;

  // play, at the recorded pace and as fast as possible: a subscriber gets every message, in
  // order, with its content.
  for (const char* rate : {"1", "0"}) {
    {
      std::lock_guard lock(received.mutex);
      received.sequence.clear();
    }
    ComponentHost host(dds_host("bag_sink"));
    host.add(make_component_factory<NumbersSink>("numbers_sink"), {.name = "sink"});
    host.start();
    auto [code, output] = test::run_command(
        {bag_tool(), "play", bag.string(), "--rate", rate, "--topics", "/numbers"},
        domain_environment(40));
    EXPECT_EQ(code, 0) << output;
    EXPECT_NE(output.find(fmt::format("played {} message(s)", kMessages)), std::string::npos)
        << output;
    EXPECT_TRUE(wait_for(
        [&] {
          std::lock_guard lock(received.mutex);
          return received.sequence.size() >= static_cast<size_t>(kMessages);
        },
        std::chrono::seconds(30)))
        << "rate " << rate;
    host.stop();
    std::lock_guard lock(received.mutex);
    EXPECT_EQ(received.sequence, expected) << "rate " << rate;
  }
}

// `mocap_bag record --all` into DIR/NAME while NumberedSource publishes from this process, on
// the DDS domain of `slot`.
struct RecordingUnderWay {
  RecordingUnderWay(int slot, const test::TempDir& dir, const std::string& name,
                    const std::string& storage = "mcap")
      : bag(dir / name),
        recorder({bag_tool(), "record", "-o", bag.string(), "--all", "--storage", storage},
                 domain_environment(slot), dir / "record.log"),
        host(dds_host("bag_source")) {
    host.add(make_component_factory<NumberedSource>("numbered_source"), {.name = "source"});
    host.start();
  }
  // Half of /numbers committed to the bag.
  bool half_committed() const {
    return wait_for([&] { return committed(bag, "/numbers") >= kMessages / 2; },
                    std::chrono::seconds(60));
  }

  std::filesystem::path bag;
  test::ChildProcess recorder;
  ComponentHost host;
};

// kill -9 in the middle of a recording of everything published: the bag opens and holds the
// messages up to the last commit, in order and without holes. The chunk being written when the
// kill came may be in the file in part: said as the file's cut-short end, and nothing else.
TEST(MocapBag, AKilledRecordingLeavesABagThatOpens) {
  join_domain(42);
  test::TempDir dir;
  RecordingUnderWay recording(42, dir, "killed");
  test::ChildProcess& recorder = recording.recorder;
  const std::filesystem::path& bag = recording.bag;
  ASSERT_TRUE(recording.half_committed()) << recorder.output();
  recorder.signal(SIGKILL);
  EXPECT_EQ(recorder.wait(std::chrono::seconds(30)), 128 + SIGKILL);
  recording.host.stop();

  auto [code, info] = test::run_command({bag_tool(), "info", bag.string()});
  EXPECT_EQ(code, 0) << info;
  BagReader reader(bag.string());
  EXPECT_LE(reader.problems().size(), 1u) << info;
  for (const std::string& problem : reader.problems()) {
    EXPECT_NE(problem.find("cut short"), std::string::npos) << problem;
  }
  reader.set_topic_filter({"/numbers"});
  BagMessage message;
  int expected = 0;
  while (reader.next(message)) {
    FiducialArray array;
    message_type<FiducialArray>().deserialize(message.data, &array);
    EXPECT_EQ(array.header().stamp().sec(), expected++);
  }
  EXPECT_GE(expected, kMessages / 2);
}

// Stop requests as supervisors send them: one SIGTERM; two in the same instant (`timeout`,
// process-group kills, `docker stop`); Ctrl-C twice, 200 ms apart. Each is one request: the
// recording ends with its closing line, metadata.yaml counts exactly what the database holds,
// and no -wal file is left beside it. Both storages.
enum class StopPattern { OneSigterm, TwoSigtermsAtOnce, CtrlCTwice };

class MocapBagStops : public ::testing::TestWithParam<std::tuple<StopPattern, std::string>> {};

TEST_P(MocapBagStops, LeaveABagWhoseMetadataAgreesWithItsDatabase) {
  const auto [pattern, storage] = GetParam();
  // Domains of their own: ctest runs tests side by side, and the recorder records --all.
  const int slot = (storage == "mcap" ? 44 : 51) + static_cast<int>(pattern);
  join_domain(slot);
  test::TempDir dir;
  RecordingUnderWay recording(slot, dir, "stopped", storage);
  test::ChildProcess& recorder = recording.recorder;
  const std::filesystem::path& bag = recording.bag;
  ASSERT_TRUE(recording.half_committed()) << recorder.output();
  switch (pattern) {
    case StopPattern::OneSigterm:
      recorder.signal(SIGTERM);
      break;
    case StopPattern::TwoSigtermsAtOnce:
      recorder.signal(SIGTERM);
      recorder.signal(SIGTERM);
      break;
    case StopPattern::CtrlCTwice:
      recorder.signal(SIGINT);
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      recorder.signal(SIGINT);
      break;
  }
  ASSERT_EQ(recorder.wait(std::chrono::seconds(30)), 0) << recorder.output();
  recording.host.stop();
  EXPECT_NE(recorder.output().find("recorded "), std::string::npos) << recorder.output();

  for (const auto& entry : std::filesystem::directory_iterator(bag)) {
    EXPECT_FALSE(entry.path().string().ends_with("-wal")) << entry.path();
  }
  EXPECT_TRUE(std::filesystem::exists(
      bag / ("stopped_0." + std::string(storage == "mcap" ? "mcap" : "db3"))));
  const BagMetadata metadata =
      parse_metadata_yaml(test::read_file(bag / "metadata.yaml"), "metadata.yaml");
  std::map<std::string, uint64_t> in_database;
  BagReader reader(bag.string());
  BagMessage message;
  while (reader.next(message)) ++in_database[message.topic->name];
  uint64_t total = 0;
  for (const BagTopic& topic : metadata.topics) {
    EXPECT_EQ(topic.message_count, in_database[topic.name]) << topic.name;
    total += topic.message_count;
  }
  EXPECT_EQ(metadata.message_count, total);
  EXPECT_GE(in_database["/numbers"], static_cast<uint64_t>(kMessages / 2));
}

std::string stop_test_name(const ::testing::TestParamInfo<MocapBagStops::ParamType>& info) {
  constexpr std::array<const char*, 3> kNames = {"OneSigterm", "TwoSigtermsAtOnce", "CtrlCTwice"};
  return kNames[static_cast<size_t>(std::get<0>(info.param))] + ("_" + std::get<1>(info.param));
}

INSTANTIATE_TEST_SUITE_P(Patterns, MocapBagStops,
                         ::testing::Combine(::testing::Values(StopPattern::OneSigterm,
                                                              StopPattern::TwoSigtermsAtOnce,
                                                              StopPattern::CtrlCTwice),
                                            ::testing::Values("mcap", "sqlite3")),
                         stop_test_name);

// A bag cut short (a full disk, a copy interrupted): info says what is lost and play plays the
// rest, both with exit status 0. Both storages: an MCAP file loses its summary and the chunks
// past the cut, a database its pages past the cut.
class MocapBagCutShort : public ::testing::TestWithParam<std::string> {};

TEST_P(MocapBagCutShort, InfoAndPlayUseWhatIsReadableAndSayWhatIsNot) {
  const std::string storage = GetParam();
  test::TempDir dir;
  const std::filesystem::path bag = dir / "cut";
  constexpr int kWritten = 600;
  {
    BagWriterOptions options;
    options.storage = storage;
    options.commit_messages = 50;  // an MCAP chunk per commit: 12 of them
    BagWriter writer(bag.string(), options);
    const uint32_t id = writer.add_topic({"/blob", "std_msgs/msg/Empty", "cdr", {}, 0});
    std::mt19937 random(1);
    for (int i = 0; i < kWritten; ++i) {
      std::vector<uint8_t> data(1000);
      for (uint8_t& byte : data) byte = static_cast<uint8_t>(random());  // not compressible
      writer.write(id, 1'000'000'000 + i * 1'000'000LL, data);
    }
    writer.close();
  }
  const std::string file_name = storage == "mcap" ? "cut_0.mcap" : "cut_0.db3";
  const std::filesystem::path file = bag / file_name;
  std::filesystem::resize_file(file, std::filesystem::file_size(file) * 6 / 10);

  auto [info_code, info] = test::run_command({bag_tool(), "info", bag.string()});
  EXPECT_EQ(info_code, 0) << info;
  EXPECT_NE(info.find("Damage:"), std::string::npos) << info;
  EXPECT_NE(info.find(file_name), std::string::npos) << info;

  auto [play_code, played] =
      test::run_command({bag_tool(), "play", bag.string(), "--rate", "0", "--delay", "0"},
                        domain_environment(storage == "mcap" ? 55 : 43));
  EXPECT_EQ(play_code, 0) << played;
  EXPECT_NE(played.find(file_name), std::string::npos) << played;  // the damage, said
  BagReader reader(bag.string());
  const uint64_t readable = reader.metadata().message_count;
  EXPECT_NE(played.find(fmt::format("played {} message(s)", readable)), std::string::npos)
      << played;
  EXPECT_NE(info.find(fmt::format("Messages:          {}", readable)), std::string::npos) << info;
  // About the 60 % that is left, whole messages only.
  EXPECT_GT(readable, static_cast<uint64_t>(kWritten) * 4 / 10);
  EXPECT_LT(readable, static_cast<uint64_t>(kWritten));
}

INSTANTIATE_TEST_SUITE_P(Storages, MocapBagCutShort, ::testing::Values("mcap", "sqlite3"),
                         [](const auto& info) { return info.param; });

// The follower demo recorded by mocap_bag to MCAP (its default storage) and read by readers
// that are not ours (test/bag/mcap_check.mjs): @mcap/core's indexed reader (summary, chunk and
// message indexes) and stream reader, zstd chunks, every message decoded from the schema the
// file stores, on every topic, as many as BagReader counts. (A file-format check: once, on
// Fast DDS; the MocapBag tests record MCAP on both implementations.)
TEST(McapReaders, ReadAndDecodeARecordingOfTheFollowerDemo) {
  const int slot = 50;
  test::TempDir dir;
  const std::filesystem::path bag = dir / "demo";
  test::ChildProcess recorder({bag_tool(), "record", "-o", bag.string(), "--all"},
                              domain_environment(slot), dir / "recorder.log");
  ASSERT_TRUE(recorder.wait_for_output("recording to", std::chrono::seconds(30)))
      << recorder.output();
  auto [code, output] = test::run_command(
      {(test::bin_dir() / "mocap_launch").string(),
       (test::source_dir() / "launch_yaml" / "follower_demo.yaml").string(), "--duration", "4",
       "--set", "servos.device_link=" + (dir / "servos").string(), "--set",
       "turret.port=" + (dir / "servos").string(), "--set", "viewer.port=0"},
      domain_environment(slot), std::chrono::seconds(120));
  ASSERT_EQ(code, 0) << output;
  recorder.signal(SIGINT);
  ASSERT_EQ(recorder.wait(std::chrono::seconds(30)), 0) << recorder.output();

  BagReader reader(bag.string());
  EXPECT_EQ(reader.metadata().storage_identifier, "mcap");
  EXPECT_TRUE(reader.problems().empty()) << reader.problems().front();
  ASSERT_GT(reader.metadata().message_count, 100u) << recorder.output();
  auto [node_code, report] =
      test::run_command({"node", (test::source_dir() / "test" / "bag" / "mcap_check.mjs").string(),
                         (bag / "demo_0.mcap").string()});
  ASSERT_EQ(node_code, 0) << report;
  const nlohmann::json checked = nlohmann::json::parse(report);
  EXPECT_EQ(checked["profile"], "ros2");
  EXPECT_EQ(checked["indexed"]["messages"], reader.metadata().message_count) << report;
  EXPECT_EQ(checked["indexed"]["statistics"], reader.metadata().message_count) << report;
  EXPECT_EQ(checked["stream"]["complete"], true) << report;
  EXPECT_NE(checked["indexed"]["compression"].dump().find("zstd"), std::string::npos) << report;
  for (const BagTopic& topic : reader.metadata().topics) {
    const nlohmann::json& theirs = checked["topics"][topic.name];
    EXPECT_EQ(theirs["count"], topic.message_count) << topic.name;
    EXPECT_EQ(theirs["decoded"], topic.message_count) << topic.name << ": " << theirs.dump();
    EXPECT_EQ(theirs["type"], topic.type) << topic.name;
  }
  // Decoded, not only counted: the poses' header names its frame.
  EXPECT_TRUE(checked["topics"]["/mocap/poses"]["first"]["header"]["frame_id"].is_string())
      << report;
}

// The other way: a file written by @mcap/core's own writer as ROS 2 Jazzy's rosbag2 writes it
// (test/bag/mcap_write.mjs: a "ros2msg" schema, zstd chunks), alone in a directory without
// metadata.yaml, is read by BagReader and described by mocap_bag info, every message intact; a
// channel without a schema has no type, and mocap_bag play says it leaves it out.
TEST(McapReaders, AFileOfMcapsOwnWriterIsReadAsABag) {
  constexpr int kMessages = 40;
  test::TempDir dir;
  const std::filesystem::path bag = dir / "jazzy";
  std::filesystem::create_directories(bag);
  auto [node_code, written] =
      test::run_command({"node", (test::source_dir() / "test" / "bag" / "mcap_write.mjs").string(),
                         (bag / "jazzy_0.mcap").string(), std::to_string(kMessages)});
  ASSERT_EQ(node_code, 0) << written;

  BagReader reader(bag.string());
  EXPECT_TRUE(reader.problems().empty()) << reader.problems().front();
  EXPECT_EQ(reader.metadata().storage_identifier, "mcap");
  ASSERT_EQ(reader.metadata().topics.size(), 2u);
  EXPECT_EQ(reader.metadata().topics[1].name, "/unnamed");
  EXPECT_EQ(reader.metadata().topics[1].type, "");
  EXPECT_EQ(reader.metadata().topics[1].message_count, 3u);
  reader.set_topic_filter({"/chatter"});
  const BagTopic& topic = reader.metadata().topics.front();
  EXPECT_EQ(topic.name, "/chatter");
  EXPECT_EQ(topic.type, "std_msgs/msg/String");
  EXPECT_EQ(topic.serialization_format, "cdr");
  ASSERT_EQ(topic.offered_qos.size(), 1u);
  EXPECT_EQ(topic.offered_qos.front().reliability, Reliability::Reliable);
  BagMessage message;
  int read = 0;
  while (reader.next(message)) {
    const std::string text = fmt::format("message {}", read);
    ASSERT_EQ(message.data.size(), 8 + text.size() + 1);
    EXPECT_EQ(std::string(message.data.begin() + 8, message.data.end() - 1), text);
    EXPECT_EQ(message.timestamp_ns, 1'700'000'000'000'000'000 + read * 1'000'000LL);
    ++read;
  }
  EXPECT_EQ(read, kMessages);

  auto [info_code, info] = test::run_command({bag_tool(), "info", bag.string()});
  EXPECT_EQ(info_code, 0) << info;
  EXPECT_NE(info.find("Storage id:        mcap"), std::string::npos) << info;
  EXPECT_NE(info.find(fmt::format("Count: {}", kMessages)), std::string::npos) << info;

  auto [play_code, played] = test::run_command(
      {bag_tool(), "play", bag.string(), "--rate", "0", "--delay", "0"}, domain_environment(54));
  EXPECT_EQ(play_code, 0) << played;
  EXPECT_NE(played.find("not playing /unnamed: its type is unknown"), std::string::npos) << played;
}

// The player never publishes a message before its time: each is handed over no earlier than
// its recorded offset from the first, divided by the rate. (How late it is, the benchmark
// measures: tests do not depend on timing.)
TEST(Playback, NoMessageLeavesBeforeItsTime) {
  test::TempDir dir;
  {
    BagWriter writer((dir / "paced").string());
    const uint32_t id = writer.add_topic({"/tick", "std_msgs/msg/Empty", "cdr", {}, 0});
    const std::vector<uint8_t> empty = {0, 1, 0, 0};
    for (int i = 0; i < 20; ++i) writer.write(id, 1'000'000'000 + i * 7'000'000LL, empty);
    writer.close();
  }
  BagReader reader((dir / "paced").string());
  for (double rate : {1.0, 2.0}) {
    std::vector<std::chrono::steady_clock::time_point> handed;
    std::vector<int64_t> stamps;
    std::atomic<bool> stop{false};
    const PlaybackStats stats = play(
        reader, PlaybackOptions{.rate = rate, .loop = false, .topics = {}},
        [&](const BagMessage& message) {
          handed.push_back(std::chrono::steady_clock::now());
          stamps.push_back(message.timestamp_ns);
        },
        stop);
    ASSERT_EQ(stats.published, 20u);
    for (size_t i = 1; i < handed.size(); ++i) {
      const double due_s = static_cast<double>(stamps[i] - stamps[0]) * 1e-9 / rate;
      EXPECT_GE(std::chrono::duration<double>(handed[i] - handed[0]).count(), due_s - 1e-6)
          << "message " << i << " at rate " << rate;
    }
  }
  std::atomic<bool> stop{true};
  EXPECT_EQ(play(
                reader, {}, [](const BagMessage&) {}, stop)
                .published,
            0u);
  EXPECT_THROW(play(
                   reader, PlaybackOptions{.rate = -1, .loop = false, .topics = {}},
                   [](const BagMessage&) {}, stop),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::bag
