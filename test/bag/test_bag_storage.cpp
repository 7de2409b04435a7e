// The bag storage library against rosbag2's sqlite3 layout: round trips, the exact Humble
// schema, bags as ROS 2 Humble and Jazzy write them, a writer killed with SIGKILL, a full disk
// (max_bytes and a real tmpfs), damaged files, and the writer's errors.
//
// Malformed metadata.yaml: the reader does not throw; it reports the parse error (file, line and
// key) in problems() and reads the directory's .db3 files instead (ReadDamage.
// MalformedMetadataYamlFallsBackToTheDatabases).
#include <fcntl.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <mocap/bag/bag_metadata.hpp>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/bag/bag_writer.hpp>

#include "test/test_support.hpp"

namespace {

namespace fs = std::filesystem;
using namespace mocap;
using namespace mocap::bag;
using mocap::test::read_file;
using mocap::test::TempDir;
using mocap::test::write_file;
using ::testing::HasSubstr;

constexpr int64_t kEpoch = 1'700'000'000'000'000'000;

// ---- payloads that check themselves ------------------------------------------------------

// CDR encapsulation header, the sequence number, then bytes that follow from it: a payload
// that comes back altered in any byte is detected.
std::vector<uint8_t> sequence_payload(uint64_t seq, size_t size) {
  size = std::max<size_t>(size, 12);
  std::vector<uint8_t> out(size);
  out[1] = 1;  // CDR_LE
  std::memcpy(&out[4], &seq, sizeof seq);
  uint64_t x = seq * 0x9E3779B97F4A7C15ull + 1;
  for (size_t i = 12; i < size; ++i) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    out[i] = static_cast<uint8_t>(x);
  }
  return out;
}

std::optional<uint64_t> intact_sequence(const std::vector<uint8_t>& data) {
  if (data.size() < 12) return std::nullopt;
  uint64_t seq;
  std::memcpy(&seq, &data[4], sizeof seq);
  if (sequence_payload(seq, data.size()) != data) return std::nullopt;
  return seq;
}

struct ReadBack {
  std::vector<uint64_t> sequences;  // of the intact payloads, in reading order
  size_t damaged = 0;               // payloads returned but altered
  std::vector<int64_t> stamps;
};

ReadBack read_sequences(BagReader& reader) {
  ReadBack out;
  BagMessage message;
  while (reader.next(message)) {
    if (auto seq = intact_sequence(message.data)) {
      out.sequences.push_back(*seq);
    } else {
      ++out.damaged;
    }
    out.stamps.push_back(message.timestamp_ns);
  }
  return out;
}

bool strictly_increasing(const std::vector<uint64_t>& values) {
  return std::adjacent_find(values.begin(), values.end(),
                            [](uint64_t a, uint64_t b) { return a >= b; }) == values.end();
}

bool consecutive_from_one(const std::vector<uint64_t>& values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i] != i + 1) return false;
  }
  return true;
}

// A closed bag of `count` messages on one topic, payload i = sequence_payload(i, size(i)),
// stamps 1 ms apart.
template <typename SizeOf>
void write_sequence_bag(const fs::path& directory, uint64_t count, SizeOf size_of) {
  BagWriter writer(directory.string());
  uint32_t topic = writer.add_topic({"/seq", "std_msgs/msg/ByteMultiArray", "cdr", {}});
  for (uint64_t seq = 1; seq <= count; ++seq) {
    writer.write(topic, kEpoch + static_cast<int64_t>(seq) * 1'000'000,
                 sequence_payload(seq, size_of(seq)));
  }
  writer.close();
}

fs::path db_of(const fs::path& bag) { return bag / (bag.filename().string() + "_0.db3"); }

// ---- raw SQLite, to look inside and to write bags the way ROS 2 does --------------------

class RawDb {
 public:
  explicit RawDb(const fs::path& path, int flags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE) {
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
      ADD_FAILURE() << path << ": " << sqlite3_errmsg(db_);
    }
  }
  ~RawDb() { sqlite3_close(db_); }
  RawDb(const RawDb&) = delete;
  RawDb& operator=(const RawDb&) = delete;

  void exec(const std::string& sql) {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
      ADD_FAILURE() << sql << ": " << (error ? error : "?");
      sqlite3_free(error);
    }
  }

  std::vector<std::vector<std::string>> rows(const std::string& sql) {
    std::vector<std::vector<std::string>> out;
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK) {
      ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db_);
      return out;
    }
    while (sqlite3_step(statement) == SQLITE_ROW) {
      std::vector<std::string> row;
      for (int i = 0; i < sqlite3_column_count(statement); ++i) {
        const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(statement, i));
        row.push_back(text ? text : "NULL");
      }
      out.push_back(std::move(row));
    }
    sqlite3_finalize(statement);
    return out;
  }

  void insert_message(int64_t topic_id, int64_t stamp, const std::vector<uint8_t>& data) {
    sqlite3_stmt* statement = nullptr;
    sqlite3_prepare_v2(db_, "INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)", -1,
                       &statement, nullptr);
    sqlite3_bind_int64(statement, 1, stamp);
    sqlite3_bind_int64(statement, 2, topic_id);
    sqlite3_bind_blob(statement, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE) << sqlite3_errmsg(db_);
    sqlite3_finalize(statement);
  }

 private:
  sqlite3* db_ = nullptr;
};

void expect_same_metadata(const BagMetadata& a, const BagMetadata& b) {
  EXPECT_EQ(a.start_ns, b.start_ns);
  EXPECT_EQ(a.duration_ns, b.duration_ns);
  EXPECT_EQ(a.message_count, b.message_count);
  ASSERT_EQ(a.topics.size(), b.topics.size());
  for (size_t i = 0; i < a.topics.size(); ++i) {
    SCOPED_TRACE(a.topics[i].name);
    EXPECT_EQ(a.topics[i].name, b.topics[i].name);
    EXPECT_EQ(a.topics[i].type, b.topics[i].type);
    EXPECT_EQ(a.topics[i].serialization_format, b.topics[i].serialization_format);
    EXPECT_EQ(a.topics[i].offered_qos, b.topics[i].offered_qos);
    EXPECT_EQ(a.topics[i].message_count, b.topics[i].message_count);
  }
  ASSERT_EQ(a.files.size(), b.files.size());
  for (size_t i = 0; i < a.files.size(); ++i) {
    EXPECT_EQ(a.files[i].path, b.files[i].path);
    EXPECT_EQ(a.files[i].start_ns, b.files[i].start_ns);
    EXPECT_EQ(a.files[i].duration_ns, b.files[i].duration_ns);
    EXPECT_EQ(a.files[i].message_count, b.files[i].message_count);
  }
}

// ---- 1. round trip -----------------------------------------------------------------------

TEST(BagRoundTrip, TopicsPayloadsStampsAndQosComeBackInTimestampOrder) {
  TempDir dir;
  const fs::path bag = dir / "walk";
  const Qos keep_all_best_effort{Reliability::BestEffort, Durability::Volatile, History::KeepAll,
                                 Qos{}.depth};
  const std::vector<BagTopic> topics = {
      {"/camera/ir/image_raw", "sensor_msgs/msg/Image", "cdr", {Qos::sensor_data()}, 0},
      {"/config", "std_msgs/msg/String", "cdr", {Qos::latched()}, 0},
      {"/events", "std_msgs/msg/String", "cdr", {Qos::reliable(), keep_all_best_effort}, 0},
      {"/silent", "std_msgs/msg/Empty", "cdr", {}, 0},
  };
  struct Sent {
    size_t topic;
    int64_t stamp;
    std::vector<uint8_t> data;
  };
  std::vector<Sent> sent;
  std::mt19937 random(42);
  // Each topic's stamps rise, but the topics are written in turn with jitter, so the stream
  // is out of order across topics; a few stamps repeat (written order must decide).
  std::vector<int64_t> clock = {kEpoch, kEpoch + 5'000'000, kEpoch - 3'000'000};
  for (int i = 0; i < 90; ++i) {
    const size_t topic = static_cast<size_t>(i % 3);
    clock[topic] += std::uniform_int_distribution<int64_t>(0, 20'000'000)(random);
    size_t size = std::uniform_int_distribution<size_t>(0, 4096)(random);
    if (i % 17 == 0) size = std::uniform_int_distribution<size_t>(1'000'000, 2'000'000)(random);
    if (i % 29 == 0) size = 0;
    std::vector<uint8_t> data(size);
    for (uint8_t& byte : data) byte = static_cast<uint8_t>(random());
    sent.push_back({topic, clock[topic], std::move(data)});
    if (i % 10 == 0) sent.push_back({(topic + 1) % 3, clock[topic], {1, 2, 3}});  // same stamp
  }

  BagMetadata written;
  uint64_t payload_bytes = 0;
  {
    BagWriter writer(bag.string());
    std::vector<uint32_t> ids;
    for (const BagTopic& topic : topics) ids.push_back(writer.add_topic(topic));
    EXPECT_EQ(ids, (std::vector<uint32_t>{1, 2, 3, 4}));
    for (const Sent& message : sent) {
      writer.write(ids[message.topic], message.stamp, message.data);
      payload_bytes += message.data.size();
    }
    EXPECT_EQ(writer.bytes_written(), payload_bytes);
    EXPECT_EQ(writer.directory(), bag.string());
    writer.close();
    writer.close();  // idempotent
    written = writer.metadata();
  }
  EXPECT_EQ(written.message_count, sent.size());

  std::vector<Sent> expected = sent;
  std::stable_sort(expected.begin(), expected.end(),
                   [](const Sent& a, const Sent& b) { return a.stamp < b.stamp; });
  int64_t first = expected.front().stamp, last = expected.back().stamp;
  EXPECT_EQ(written.start_ns, first);
  EXPECT_EQ(written.duration_ns, last - first);

  BagReader reader(bag.string());
  EXPECT_TRUE(reader.problems().empty()) << ::testing::PrintToString(reader.problems());
  const BagMetadata& m = reader.metadata();
  expect_same_metadata(m, written);
  ASSERT_EQ(m.topics.size(), 4u);
  for (size_t i = 0; i < topics.size(); ++i) {
    EXPECT_EQ(m.topics[i].offered_qos, topics[i].offered_qos) << topics[i].name;
    auto n = std::count_if(sent.begin(), sent.end(), [&](const Sent& s) { return s.topic == i; });
    EXPECT_EQ(m.topics[i].message_count, static_cast<uint64_t>(n)) << topics[i].name;
  }
  ASSERT_EQ(m.files.size(), 1u);
  EXPECT_EQ(m.files[0].path, "walk_0.db3");
  EXPECT_EQ(m.files[0].message_count, sent.size());

  BagMessage message;
  for (size_t i = 0; i < expected.size(); ++i) {
    ASSERT_TRUE(reader.next(message)) << i;
    ASSERT_NE(message.topic, nullptr);
    EXPECT_EQ(message.topic->name, topics[expected[i].topic].name) << i;
    EXPECT_EQ(message.timestamp_ns, expected[i].stamp) << i;
    EXPECT_TRUE(message.data == expected[i].data) << i << ": " << message.data.size() << " bytes";
  }
  EXPECT_FALSE(reader.next(message));
  EXPECT_FALSE(reader.next(message));

  // metadata.yaml says the same as the writer.
  expect_same_metadata(parse_metadata_yaml(read_file(bag / "metadata.yaml"), "metadata.yaml"),
                       written);

  // Rewind and filter: the same messages again, then one topic only.
  reader.rewind();
  ASSERT_TRUE(reader.next(message));
  EXPECT_EQ(message.timestamp_ns, expected[0].stamp);
  EXPECT_TRUE(message.data == expected[0].data);
  reader.set_topic_filter({"/config", "/no/such/topic"});
  reader.rewind();
  std::vector<int64_t> stamps;
  while (reader.next(message)) {
    EXPECT_EQ(message.topic->name, "/config");
    stamps.push_back(message.timestamp_ns);
  }
  std::vector<int64_t> config_stamps;
  for (const Sent& s : expected) {
    if (s.topic == 1) config_stamps.push_back(s.stamp);
  }
  EXPECT_EQ(stamps, config_stamps);
  reader.set_topic_filter({});
  reader.rewind();
  size_t all = 0;
  while (reader.next(message)) ++all;
  EXPECT_EQ(all, expected.size());
}

TEST(BagRoundTrip, FilterChangedMidwayContinuesFromThePosition) {
  TempDir dir;
  const fs::path bag = dir / "mid";
  {
    BagWriter writer(bag.string());
    uint32_t a = writer.add_topic({"/a", "std_msgs/msg/Empty", "cdr", {}});
    uint32_t b = writer.add_topic({"/b", "std_msgs/msg/Empty", "cdr", {}});
    for (int i = 0; i < 20; ++i) writer.write(i % 2 ? b : a, kEpoch + i, sequence_payload(i, 20));
  }
  BagReader reader(bag.string());
  BagMessage message;
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(reader.next(message));
  EXPECT_EQ(message.timestamp_ns, kEpoch + 5);
  reader.set_topic_filter({"/a"});
  std::vector<int64_t> stamps;
  while (reader.next(message)) stamps.push_back(message.timestamp_ns - kEpoch);
  EXPECT_EQ(stamps, (std::vector<int64_t>{6, 8, 10, 12, 14, 16, 18}));
}

TEST(BagQos, OfferedProfilesRoundTripAndPlaybackQos) {
  const Qos keep_last_7{Reliability::Reliable, Durability::TransientLocal, History::KeepLast, 7};
  const std::vector<Qos> offered = {Qos::sensor_data(), Qos::latched(), Qos::reliable(),
                                    keep_last_7};
  const std::string text = format_offered_qos_profiles(offered);
  EXPECT_EQ(parse_offered_qos_profiles(text), offered);
  // Keep-all depth is a flow-control bound of this runtime that rmw has no place for: it comes
  // back as Qos's default.
  const Qos keep_all_50{Reliability::Reliable, Durability::Volatile, History::KeepAll, 50};
  EXPECT_EQ(parse_offered_qos_profiles(format_offered_qos_profiles({keep_all_50})),
            (std::vector<Qos>{
                {Reliability::Reliable, Durability::Volatile, History::KeepAll, Qos{}.depth}}));
  EXPECT_THAT(
      format_offered_qos_profiles({Qos::sensor_data()}),
      ::testing::StartsWith("- history: 1\n  depth: 5\n  reliability: 2\n  durability: 2\n"));
  EXPECT_THAT(format_offered_qos_profiles({Qos::reliable()}),
              ::testing::StartsWith("- history: 2\n  depth: 0\n  reliability: 1\n"));
  EXPECT_TRUE(parse_offered_qos_profiles("").empty());
  EXPECT_TRUE(parse_offered_qos_profiles("[unclosed").empty());

  // Reliable and transient local only when every publisher was.
  Qos both = playback_qos({Qos::latched(), keep_last_7});
  EXPECT_EQ(both.reliability, Reliability::Reliable);
  EXPECT_EQ(both.durability, Durability::TransientLocal);
  EXPECT_EQ(both.history, History::KeepLast);
  EXPECT_EQ(both.depth, 7);
  Qos mixed = playback_qos({Qos::latched(), Qos::sensor_data()});
  EXPECT_EQ(mixed.reliability, Reliability::BestEffort);
  EXPECT_EQ(mixed.durability, Durability::Volatile);
  EXPECT_EQ(playback_qos({}), Qos{});
}

// ---- 2. the schema, exactly as Humble writes it -----------------------------------------

TEST(BagSchema, TablesAndRowsAreHumbleVersion3) {
  TempDir dir;
  const fs::path bag = dir / "exact";
  {
    BagWriter writer(bag.string());
    uint32_t topic =
        writer.add_topic({"/chatter", "std_msgs/msg/String", "cdr", {Qos::reliable()}});
    writer.write(topic, kEpoch, sequence_payload(1, 40));
  }
  EXPECT_TRUE(fs::exists(db_of(bag)));
  EXPECT_FALSE(fs::exists(db_of(bag).string() + "-wal")) << "closed: the log is merged";
  RawDb db(db_of(bag), SQLITE_OPEN_READONLY);
  using Rows = std::vector<std::vector<std::string>>;
  EXPECT_EQ(
      db.rows("SELECT type, name, sql FROM sqlite_master ORDER BY rowid"),
      (Rows{{"table", "schema",
             "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT "
             "NULL)"},
            {"table", "metadata",
             "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT "
             "NULL,metadata TEXT NOT NULL)"},
            {"table", "topics",
             "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT "
             "NULL,serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL)"},
            {"table", "messages",
             "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT "
             "NULL,timestamp INTEGER NOT NULL, data BLOB NOT NULL)"},
            {"index", "timestamp_idx", "CREATE INDEX timestamp_idx ON messages (timestamp ASC)"}}));
  EXPECT_EQ(db.rows("SELECT schema_version, ros_distro FROM schema"), (Rows{{"3", "humble"}}));
  const Rows metadata = db.rows("SELECT metadata_version, metadata FROM metadata");
  ASSERT_EQ(metadata.size(), 1u);
  EXPECT_EQ(metadata[0][0], "5");
  EXPECT_EQ(metadata[0][1], read_file(bag / "metadata.yaml"));
  EXPECT_EQ(db.rows("SELECT id, name, type, serialization_format, offered_qos_profiles FROM "
                    "topics"),
            (Rows{{"1", "/chatter", "std_msgs/msg/String", "cdr",
                   format_offered_qos_profiles({Qos::reliable()})}}));
  EXPECT_EQ(db.rows("SELECT id, topic_id, timestamp, length(data) FROM messages"),
            (Rows{{"1", "1", std::to_string(kEpoch), "40"}}));
}

TEST(BagSchema, MetadataYamlIsRosbag2sLayout) {
  BagMetadata metadata;
  metadata.start_ns = 1'700'000'000'000'000'000;
  metadata.duration_ns = 1234;
  metadata.message_count = 10;
  metadata.topics = {{"/chatter",
                      "std_msgs/msg/String",
                      "cdr",
                      {{Reliability::Reliable, Durability::Volatile, History::KeepLast, 10}},
                      10}};
  metadata.files = {{"run_0.db3", 1'700'000'000'000'000'000, 1234, 10}};
  EXPECT_EQ(format_metadata_yaml(metadata), R"(rosbag2_bagfile_information:
  version: 5
  storage_identifier: sqlite3
  duration:
    nanoseconds: 1234
  starting_time:
    nanoseconds_since_epoch: 1700000000000000000
  message_count: 10
  topics_with_message_count:
    - topic_metadata:
        name: /chatter
        type: std_msgs/msg/String
        serialization_format: cdr
        offered_qos_profiles: "- history: 1\n  depth: 10\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 9223372036\n    nsec: 854775807\n  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n  avoid_ros_namespace_conventions: false"
      message_count: 10
  compression_format: ""
  compression_mode: ""
  relative_file_paths:
    - run_0.db3
  files:
    - path: run_0.db3
      starting_time:
        nanoseconds_since_epoch: 1700000000000000000
      duration:
        nanoseconds: 1234
      message_count: 10
)");
  // Names that YAML would misread are quoted, and come back unchanged.
  metadata.topics[0].name = "/odd: name # \"quoted\"";
  metadata.topics[0].type = "null";
  BagMetadata back = parse_metadata_yaml(format_metadata_yaml(metadata), "test");
  EXPECT_EQ(back.topics[0].name, metadata.topics[0].name);
  EXPECT_EQ(back.topics[0].type, "null");
}

TEST(BagSchema, MetadataYamlIsWrittenAtOnceAndKeptCurrent) {
  TempDir dir;
  const fs::path bag = dir / "live";
  BagWriter writer(bag.string());
  const fs::path yaml = bag / "metadata.yaml";
  ASSERT_TRUE(fs::exists(yaml));
  EXPECT_TRUE(parse_metadata_yaml(read_file(yaml), yaml).topics.empty());
  uint32_t topic = writer.add_topic({"/x", "std_msgs/msg/Empty", "cdr", {Qos::sensor_data()}});
  BagMetadata listed = parse_metadata_yaml(read_file(yaml), yaml);
  ASSERT_EQ(listed.topics.size(), 1u);
  EXPECT_EQ(listed.topics[0].offered_qos, std::vector<Qos>{Qos::sensor_data()});
  EXPECT_EQ(listed.files.at(0).path, "live_0.db3");
  for (int i = 0; i < 5; ++i) writer.write(topic, kEpoch + i, sequence_payload(i, 16));
  EXPECT_FALSE(fs::exists(bag / "metadata.yaml.tmp"));

  // Commit policy: committed messages are visible to a reader while the writer runs.
  writer.commit();
  {
    BagReader reader(bag.string());
    EXPECT_EQ(reader.metadata().message_count, 5u);
  }
  // A transaction older than commit_interval is committed by the next write.
  for (int i = 5; i < 8; ++i) writer.write(topic, kEpoch + i, sequence_payload(i, 16));
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  writer.write(topic, kEpoch + 8, sequence_payload(8, 16));
  {
    BagReader reader(bag.string());
    EXPECT_EQ(reader.metadata().message_count, 9u);
  }
  writer.close();
  EXPECT_EQ(parse_metadata_yaml(read_file(yaml), yaml).message_count, 9u);
}

// ---- 3. bags written by ROS 2 -------------------------------------------------------------

constexpr const char* kHumbleSchema =
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);"
    "INSERT INTO schema (schema_version, ros_distro) VALUES (3, 'humble');"
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,metadata "
    "TEXT NOT NULL);"
    "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT "
    "NULL,serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);"
    "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp INTEGER "
    "NOT NULL, data BLOB NOT NULL);"
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);";

// Two publishers on /chatter as a Humble recorder discovers them: history unknown, one
// reliable, one best effort; /tf_static transient local.
constexpr const char* kHumbleChatterQos =
    "- history: 3\\n  depth: 0\\n  reliability: 1\\n  durability: 2\\n  deadline:\\n    sec: "
    "9223372036\\n    nsec: 854775807\\n  lifespan:\\n    sec: 9223372036\\n    nsec: "
    "854775807\\n  liveliness: 1\\n  liveliness_lease_duration:\\n    sec: 9223372036\\n    "
    "nsec: 854775807\\n  avoid_ros_namespace_conventions: false\\n- history: 3\\n  depth: 0\\n  "
    "reliability: 2\\n  durability: 2\\n  deadline:\\n    sec: 9223372036\\n    nsec: "
    "854775807\\n  lifespan:\\n    sec: 9223372036\\n    nsec: 854775807\\n  liveliness: 1\\n  "
    "liveliness_lease_duration:\\n    sec: 9223372036\\n    nsec: 854775807\\n  "
    "avoid_ros_namespace_conventions: false";
constexpr const char* kHumbleTfQos =
    "- history: 3\\n  depth: 0\\n  reliability: 1\\n  durability: 1\\n  deadline:\\n    sec: "
    "9223372036\\n    nsec: 854775807\\n  lifespan:\\n    sec: 9223372036\\n    nsec: "
    "854775807\\n  liveliness: 1\\n  liveliness_lease_duration:\\n    sec: 9223372036\\n    "
    "nsec: 854775807\\n  avoid_ros_namespace_conventions: false";

// The YAML escape "\n" made a real newline, as it is in the database's topics table.
std::string unescape(std::string text) {
  for (size_t at; (at = text.find("\\n")) != std::string::npos;) text.replace(at, 2, "\n");
  return text;
}

TEST(RosBags, HumbleBagWithMetadataYaml) {
  TempDir dir;
  const fs::path bag = dir / "ros_humble";
  fs::create_directories(bag);
  {
    RawDb db(bag / "ros_humble_0.db3");
    db.exec("PRAGMA journal_mode=WAL");
    db.exec(kHumbleSchema);
    db.exec(fmt::format(
        "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) VALUES "
        "('/chatter', 'std_msgs/msg/String', 'cdr', '{}'), ('/tf_static', "
        "'tf2_msgs/msg/TFMessage', 'cdr', '{}')",
        unescape(kHumbleChatterQos), unescape(kHumbleTfQos)));
    // rosbag2 writes in arrival order, which is not always stamp order.
    db.insert_message(1, kEpoch + 3'000'000, sequence_payload(3, 30));
    db.insert_message(2, kEpoch, sequence_payload(1, 300));
    db.insert_message(1, kEpoch + 1'000'000, sequence_payload(2, 30));
    db.insert_message(1, kEpoch + 4'000'000, sequence_payload(5, 30));
    db.insert_message(1, kEpoch + 3'000'000, sequence_payload(4, 30));
  }
  write_file(bag / "metadata.yaml", fmt::format(R"(rosbag2_bagfile_information:
  version: 5
  storage_identifier: sqlite3
  duration:
    nanoseconds: 4000000
  starting_time:
    nanoseconds_since_epoch: {0}
  message_count: 5
  topics_with_message_count:
    - topic_metadata:
        name: /chatter
        type: std_msgs/msg/String
        serialization_format: cdr
        offered_qos_profiles: "{1}"
      message_count: 4
    - topic_metadata:
        name: /tf_static
        type: tf2_msgs/msg/TFMessage
        serialization_format: cdr
        offered_qos_profiles: "{2}"
      message_count: 1
  compression_format: ""
  compression_mode: ""
  relative_file_paths:
    - ros_humble_0.db3
  files:
    - path: ros_humble_0.db3
      starting_time:
        nanoseconds_since_epoch: {0}
      duration:
        nanoseconds: 4000000
      message_count: 5)",
                                                kEpoch, kHumbleChatterQos, kHumbleTfQos));

  BagMetadata yaml = parse_metadata_yaml(read_file(bag / "metadata.yaml"), "metadata.yaml");
  ASSERT_EQ(yaml.topics.size(), 2u);
  ASSERT_EQ(yaml.topics[0].offered_qos.size(), 2u);
  EXPECT_EQ(yaml.topics[0].offered_qos[1].reliability, Reliability::BestEffort);
  EXPECT_EQ(yaml.message_count, 5u);

  BagReader reader(bag.string());
  EXPECT_TRUE(reader.problems().empty()) << ::testing::PrintToString(reader.problems());
  const BagMetadata& m = reader.metadata();
  ASSERT_EQ(m.topics.size(), 2u);
  EXPECT_EQ(m.topics[0].name, "/chatter");
  EXPECT_EQ(m.topics[0].type, "std_msgs/msg/String");
  EXPECT_EQ(m.topics[0].message_count, 4u);
  EXPECT_EQ(m.topics[1].message_count, 1u);
  ASSERT_EQ(m.topics[0].offered_qos.size(), 2u);
  // History unknown: Qos's defaults. The rest as announced.
  EXPECT_EQ(m.topics[0].offered_qos[0],
            (Qos{Reliability::Reliable, Durability::Volatile, Qos{}.history, Qos{}.depth}));
  EXPECT_EQ(m.topics[0].offered_qos[1].reliability, Reliability::BestEffort);
  ASSERT_EQ(m.topics[1].offered_qos.size(), 1u);
  EXPECT_EQ(m.topics[1].offered_qos[0].durability, Durability::TransientLocal);
  EXPECT_EQ(playback_qos(m.topics[0].offered_qos).reliability, Reliability::BestEffort);
  EXPECT_EQ(playback_qos(m.topics[1].offered_qos).durability, Durability::TransientLocal);
  EXPECT_EQ(m.start_ns, kEpoch);
  EXPECT_EQ(m.duration_ns, 4'000'000);
  EXPECT_EQ(m.message_count, 5u);

  ReadBack back = read_sequences(reader);
  EXPECT_EQ(back.damaged, 0u);
  EXPECT_EQ(back.sequences, (std::vector<uint64_t>{1, 2, 3, 4, 5}));  // stamp, then id order
}

// rosbag2 writes QoS policies by name from metadata version 9 on (Jazzy's rosbag2 qos.cpp);
// Humble's numbers are read as before. A latched topic must play back latched.
TEST(RosBags, QosPoliciesByNameAsJazzyWritesThem) {
  const std::string jazzy =
      "- history: keep_last\n  depth: 1\n  reliability: reliable\n  durability: "
      "transient_local\n  deadline:\n    sec: 9223372036\n    nsec: 854775807\n  liveliness: "
      "automatic\n  avoid_ros_namespace_conventions: false\n- history: keep_all\n  depth: 0\n  "
      "reliability: best_effort\n  durability: volatile\n";
  EXPECT_EQ(parse_offered_qos_profiles(jazzy),
            (std::vector<Qos>{
                {Reliability::Reliable, Durability::TransientLocal, History::KeepLast, 1},
                {Reliability::BestEffort, Durability::Volatile, History::KeepAll, Qos{}.depth}}));
  EXPECT_EQ(parse_offered_qos_profiles("- history: 1\n  depth: 1\n  reliability: 1\n  "
                                       "durability: 1\n"),
            (std::vector<Qos>{
                {Reliability::Reliable, Durability::TransientLocal, History::KeepLast, 1}}));
}

TEST(RosBags, JazzySchema4WithVersion9MetadataYaml) {
  TempDir dir;
  const fs::path bag = dir / "jazzy_bag";
  fs::create_directories(bag);
  const std::string qos =
      "- history: 1\\n  depth: 10\\n  reliability: 1\\n  durability: 2\\n  deadline:\\n    "
      "sec: 2147483647\\n    nsec: 4294967295\\n  lifespan:\\n    sec: 2147483647\\n    nsec: "
      "4294967295\\n  liveliness: 1\\n  liveliness_lease_duration:\\n    sec: 2147483647\\n    "
      "nsec: 4294967295\\n  avoid_ros_namespace_conventions: false";
  {
    RawDb db(bag / "jazzy_bag_0.db3");
    db.exec(
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);"
        "INSERT INTO schema VALUES (4, 'jazzy');"
        "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT "
        "NULL,metadata TEXT NOT NULL);"
        "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT "
        "NULL,serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT "
        "NULL,type_description_hash TEXT NOT NULL);"
        "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY,topic_type TEXT NOT "
        "NULL,encoding TEXT NOT NULL,encoded_message_definition TEXT NOT "
        "NULL,type_description_hash TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp "
        "INTEGER NOT NULL, data BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);");
    db.exec(fmt::format(
        "INSERT INTO topics VALUES (1, '/odom', 'nav_msgs/msg/Odometry', 'cdr', '{}', "
        "'RIHS01_3c1cbc2b'); INSERT INTO message_definitions VALUES (1, "
        "'nav_msgs/msg/Odometry', 'ros2msg', 'std_msgs/Header header', 'RIHS01_3c1cbc2b');",
        unescape(qos)));
    for (uint64_t seq = 1; seq <= 3; ++seq) {
      db.insert_message(1, kEpoch + static_cast<int64_t>(seq) * 1000, sequence_payload(seq, 64));
    }
    db.exec("INSERT INTO metadata (metadata_version, metadata) VALUES (9, 'not parsed')");
  }
  write_file(bag / "metadata.yaml", fmt::format(R"(rosbag2_bagfile_information:
  version: 9
  storage_identifier: sqlite3
  duration:
    nanoseconds: 2000
  starting_time:
    nanoseconds_since_epoch: {0}
  message_count: 3
  topics_with_message_count:
    - topic_metadata:
        name: /odom
        type: nav_msgs/msg/Odometry
        serialization_format: cdr
        offered_qos_profiles: "{1}"
        type_description_hash: RIHS01_3c1cbc2b
      message_count: 3
  compression_format: ""
  compression_mode: ""
  relative_file_paths:
    - jazzy_bag_0.db3
  files:
    - path: jazzy_bag_0.db3
      starting_time:
        nanoseconds_since_epoch: {0}
      duration:
        nanoseconds: 2000
      message_count: 3
  custom_data: ~
  ros_distro: jazzy
)",
                                                kEpoch + 1000, qos));
  BagMetadata yaml = parse_metadata_yaml(read_file(bag / "metadata.yaml"), "metadata.yaml");
  ASSERT_EQ(yaml.topics.size(), 1u);
  EXPECT_EQ(
      yaml.topics[0].offered_qos,
      (std::vector<Qos>{{Reliability::Reliable, Durability::Volatile, History::KeepLast, 10}}));

  BagReader reader(bag.string());
  EXPECT_TRUE(reader.problems().empty()) << ::testing::PrintToString(reader.problems());
  const BagMetadata& m = reader.metadata();
  ASSERT_EQ(m.topics.size(), 1u);
  EXPECT_EQ(m.topics[0].name, "/odom");
  EXPECT_EQ(m.topics[0].type, "nav_msgs/msg/Odometry");
  EXPECT_EQ(m.topics[0].offered_qos, yaml.topics[0].offered_qos);
  EXPECT_EQ(m.start_ns, kEpoch + 1000);
  EXPECT_EQ(m.duration_ns, 2000);
  ReadBack back = read_sequences(reader);
  EXPECT_EQ(back.sequences, (std::vector<uint64_t>{1, 2, 3}));

  // Versions outside 4..9 are refused, naming the key.
  std::string future = read_file(bag / "metadata.yaml");
  future.replace(future.find("version: 9"), 10, "version: 10");
  try {
    parse_metadata_yaml(future, "future/metadata.yaml");
    FAIL() << "version 10 accepted";
  } catch (const BagError& e) {
    EXPECT_THAT(e.what(), HasSubstr("future/metadata.yaml"));
    EXPECT_THAT(e.what(), HasSubstr("rosbag2_bagfile_information.version"));
  }
}

TEST(RosBags, OldSchemaDatabaseWithoutMetadataYamlOrIndex) {
  // Schema version 1 (Dashing/Eloquent): no schema table, no QoS column; and no timestamp
  // index, so the rows are ordered in memory.
  TempDir dir;
  const fs::path bag = dir / "old";
  fs::create_directories(bag);
  {
    RawDb db(bag / "old_0.db3");
    db.exec(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT "
        "NULL,serialization_format TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp "
        "INTEGER NOT NULL, data BLOB NOT NULL);"
        "INSERT INTO topics VALUES (7, '/scan', 'sensor_msgs/msg/LaserScan', 'cdr');");
    const std::vector<std::pair<int64_t, uint64_t>> rows = {{50, 4}, {10, 1}, {30, 3}, {20, 2}};
    for (auto [stamp, seq] : rows) db.insert_message(7, kEpoch + stamp, sequence_payload(seq, 100));
  }
  for (const fs::path& path : {bag, bag / "old_0.db3"}) {
    SCOPED_TRACE(path.string());
    BagReader reader(path.string());
    EXPECT_TRUE(reader.problems().empty()) << ::testing::PrintToString(reader.problems());
    const BagMetadata& m = reader.metadata();
    ASSERT_EQ(m.topics.size(), 1u);
    EXPECT_EQ(m.topics[0].name, "/scan");
    EXPECT_TRUE(m.topics[0].offered_qos.empty());
    EXPECT_EQ(m.topics[0].message_count, 4u);
    EXPECT_EQ(m.start_ns, kEpoch + 10);
    EXPECT_EQ(m.duration_ns, 40);
    ASSERT_EQ(m.files.size(), 1u);
    EXPECT_EQ(m.files[0].path, "old_0.db3");
    ReadBack back = read_sequences(reader);
    EXPECT_EQ(back.sequences, (std::vector<uint64_t>{1, 2, 3, 4}));
    reader.rewind();
    EXPECT_EQ(read_sequences(reader).sequences.size(), 4u);
  }
}

// Another writer's schema may let a row's timestamp be NULL: such a row cannot be placed in time.
// It is skipped and said, the same with the timestamp index (streamed) and without (ordered in
// memory), and the counts are of the messages that play.
TEST(RosBags, RowsWithoutATimestampAreSkippedAndSaid) {
  for (const bool with_index : {true, false}) {
    SCOPED_TRACE(with_index ? "streamed" : "ordered in memory");
    TempDir dir;
    const fs::path file = dir / "untimed_0.db3";
    {
      RawDb db(file);
      db.exec(
          "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT "
          "NULL,serialization_format TEXT NOT NULL);"
          "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp "
          "INTEGER, data BLOB NOT NULL);"
          "INSERT INTO topics VALUES (7, '/scan', 'sensor_msgs/msg/LaserScan', 'cdr');");
      if (with_index) db.exec("CREATE INDEX timestamp_idx ON messages (timestamp ASC);");
      for (uint64_t seq : {1, 2, 3})
        db.insert_message(7, kEpoch + 10 * seq, sequence_payload(seq, 100));
      db.exec("UPDATE messages SET timestamp = NULL WHERE id = 2;");
    }
    BagReader reader(file.string());
    ASSERT_EQ(reader.problems().size(), 1u) << ::testing::PrintToString(reader.problems());
    EXPECT_EQ(reader.problems()[0], file.string() + ": 1 messages without a timestamp, skipped");
    ASSERT_EQ(reader.metadata().topics.size(), 1u);
    EXPECT_EQ(reader.metadata().topics[0].message_count, 2u);
    EXPECT_EQ(read_sequences(reader).sequences, (std::vector<uint64_t>{1, 3}));
  }
}

TEST(RosBags, SplitBagIsReadFileByFile) {
  // rosbag2 splits a recording into <name>_0.db3, _1.db3, ...: names sort by number.
  TempDir dir;
  const fs::path bag = dir / "split";
  fs::create_directories(bag);
  uint64_t seq = 0;
  for (int file : {0, 1, 2, 10}) {
    RawDb db(bag / fmt::format("split_{}.db3", file));
    db.exec(kHumbleSchema);
    db.exec("INSERT INTO topics VALUES (1, '/a', 'std_msgs/msg/Empty', 'cdr', '')");
    for (int i = 0; i < 3; ++i) {
      ++seq;
      db.insert_message(1, kEpoch + static_cast<int64_t>(seq), sequence_payload(seq, 20));
    }
  }
  BagReader reader(bag.string());
  ASSERT_EQ(reader.metadata().files.size(), 4u);
  EXPECT_EQ(reader.metadata().files[3].path, "split_10.db3");
  EXPECT_EQ(reader.metadata().message_count, 12u);
  EXPECT_EQ(reader.metadata().topics.size(), 1u);
  ReadBack back = read_sequences(reader);
  EXPECT_TRUE(consecutive_from_one(back.sequences));
  EXPECT_EQ(back.sequences.size(), 12u);
}

// ---- 4. a writer killed with SIGKILL ------------------------------------------------------

// Writes sequence numbers 1, 2, ... until killed; publishes the last one write() returned
// for in `written`.
[[noreturn]] void write_until_killed(const fs::path& bag, std::atomic<uint64_t>* written) {
  try {
    BagWriterOptions options;
    options.commit_interval = std::chrono::milliseconds(100);
    BagWriter writer(bag.string(), options);
    uint32_t topic = writer.add_topic({"/seq", "std_msgs/msg/ByteMultiArray", "cdr", {}});
    for (uint64_t seq = 1;; ++seq) {
      writer.write(topic, kEpoch + static_cast<int64_t>(seq) * 1000,
                   sequence_payload(seq, 100 + seq % 400));
      written->store(seq);
    }
  } catch (...) {
    _exit(3);
  }
}

struct KilledBag {
  uint64_t written = 0;  // what write() had returned for when the kill came
};

// Killed after 0.6 s and 30,000 messages at least (about 9 MB: SQLite has checkpointed some of
// its log into the database file by then, however slowly a sanitizer or a busy machine writes).
KilledBag kill_a_writer(const fs::path& bag) {
  void* shared = mmap(nullptr, sizeof(std::atomic<uint64_t>), PROT_READ | PROT_WRITE,
                      MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  EXPECT_NE(shared, MAP_FAILED);
  auto* written = new (shared) std::atomic<uint64_t>(0);
  const pid_t pid = fork();
  if (pid == 0) write_until_killed(bag, written);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (written->load() < 30000 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "the writer ended before the kill, status " << status;
  KilledBag result{written->load()};
  munmap(shared, sizeof(std::atomic<uint64_t>));
  return result;
}

TEST(BagCrash, SigkillLosesAtMostTheOpenTransaction) {
  TempDir dir;
  const fs::path bag = dir / "killed";
  const KilledBag killed = kill_a_writer(bag);
  EXPECT_TRUE(fs::exists(db_of(bag).string() + "-wal")) << "the kill should leave the log";

  BagReader reader(bag.string());
  EXPECT_TRUE(reader.problems().empty()) << ::testing::PrintToString(reader.problems());
  ReadBack back = read_sequences(reader);
  const uint64_t n = back.sequences.size();
  EXPECT_EQ(back.damaged, 0u);
  EXPECT_TRUE(consecutive_from_one(back.sequences)) << "holes in the committed messages";
  EXPECT_EQ(reader.metadata().message_count, n);
  // What is lost is the open transaction: at most commit_messages (1000) or commit_interval
  // (100 ms) of messages, whichever is fewer, plus the write in flight. At this rate (around
  // 100 000 small messages a second here) that is the 1000 of one transaction at most.
  EXPECT_GT(n, 1000u) << "too few messages for a meaningful test (written " << killed.written
                      << ")";
  EXPECT_LE(n, killed.written + 1);
  EXPECT_LE(killed.written - std::min(n, killed.written), 1000u)
      << "lost more than one transaction: read " << n << " of " << killed.written;

  // metadata.yaml is the one add_topic() wrote: it parses, its counts are stale.
  BagMetadata yaml = parse_metadata_yaml(read_file(bag / "metadata.yaml"), "metadata.yaml");
  ASSERT_EQ(yaml.topics.size(), 1u);
  EXPECT_EQ(yaml.topics[0].name, "/seq");
  EXPECT_EQ(yaml.message_count, 0u);

  // The same without the -shm index (copied bag): the log is replayed.
  const fs::path copy = dir / "copy";
  fs::create_directories(copy);
  fs::copy_file(db_of(bag), copy / db_of(bag).filename());
  fs::copy_file(db_of(bag).string() + "-wal", copy / (db_of(bag).filename().string() + "-wal"));
  BagReader copied(copy.string());
  EXPECT_EQ(read_sequences(copied).sequences.size(), n);
  EXPECT_TRUE(copied.problems().empty()) << ::testing::PrintToString(copied.problems());
}

// What a forced exit writes first: metadata.yaml with the committed messages, from another
// thread while the writer holds an open transaction; the database, read after the writer
// is gone without close(), holds exactly those.
TEST(BagCrash, CommittedMetadataIsWhatTheDatabaseHolds) {
  TempDir dir;
  const fs::path bag = dir / "forced";
  BagWriterOptions options;
  options.commit_interval = std::chrono::hours(1);
  options.commit_messages = 1'000'000;
  auto writer = std::make_unique<BagWriter>(bag.string(), options);
  uint32_t topic = writer->add_topic({"/seq", "std_msgs/msg/ByteMultiArray", "cdr", {}});
  for (uint32_t i = 1; i <= 10; ++i) writer->write(topic, kEpoch + i, sequence_payload(i, 10));
  writer->commit();
  for (uint32_t i = 11; i <= 15; ++i) writer->write(topic, kEpoch + i, sequence_payload(i, 10));
  std::thread([&] { writer->write_committed_metadata(); }).join();
  BagMetadata yaml = parse_metadata_yaml(read_file(bag / "metadata.yaml"), "metadata.yaml");
  EXPECT_EQ(yaml.message_count, 10u);
  ASSERT_EQ(yaml.topics.size(), 1u);
  EXPECT_EQ(yaml.topics[0].message_count, 10u);
  EXPECT_EQ(writer->metadata().message_count, 15u) << "accepted, 5 of them not committed";
  // As a forced exit leaves it: the open transaction never committed.
  const fs::path copy = dir / "copy";
  fs::create_directories(copy);
  for (const auto& entry : fs::directory_iterator(bag)) {
    fs::copy_file(entry.path(), copy / entry.path().filename());
  }
  BagReader reader(copy.string());
  EXPECT_EQ(read_sequences(reader).sequences.size(), 10u);
}

TEST(BagCrash, ReaderWithoutWriteAccessFallsBackToTheDatabaseFile) {
  // A killed writer's log needs its -shm index, which SQLite creates next to the database;
  // a reader that may not write there cannot use the log, whether opened read-only or
  // read-write. It reads what was checkpointed into the database file and says what is
  // missing.
  if (geteuid() != 0) GTEST_SKIP() << "needs root to read as another user";
  TempDir dir;
  const fs::path bag = dir / "killed";
  kill_a_writer(bag);
  fs::remove(db_of(bag).string() + "-shm");
  fs::permissions(dir.path(), fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                  fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(bag, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                           fs::perms::others_read | fs::perms::others_exec);
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    std::string result = "setuid failed";
    if (setgid(65534) == 0 && setuid(65534) == 0) {
      try {
        BagReader reader(bag.string());
        ReadBack back = read_sequences(reader);
        bool wal_named = std::any_of(reader.problems().begin(), reader.problems().end(),
                                     [](const std::string& p) { return p.find("-wal") != p.npos; });
        result = fmt::format("{} {} {} {}", back.sequences.size(), back.damaged,
                             strictly_increasing(back.sequences) ? 1 : 0, wal_named ? 1 : 0);
      } catch (const std::exception& e) {
        result = std::string("threw ") + e.what();
      }
    }
    (void)!write(pipe_fds[1], result.data(), result.size());
    _exit(0);
  }
  close(pipe_fds[1]);
  std::string result;
  char buffer[512];
  for (ssize_t n; (n = read(pipe_fds[0], buffer, sizeof buffer)) > 0;) result.append(buffer, n);
  close(pipe_fds[0]);
  waitpid(pid, nullptr, 0);
  unsigned long long count = 0, damaged = 1;
  int increasing = 0, wal_named = 0;
  ASSERT_EQ(sscanf(result.c_str(), "%llu %llu %d %d", &count, &damaged, &increasing, &wal_named), 4)
      << result;
  // The writer checkpoints the schema and topics into the database file, and SQLite
  // checkpoints every ~4 MB of log: most of the messages are there.
  EXPECT_GT(count, 0u);
  EXPECT_EQ(damaged, 0u);
  EXPECT_EQ(increasing, 1);
  EXPECT_EQ(wal_named, 1) << "no problem line names the log";
  // Root reads everything: the log is intact, only the other user could not use it.
  BagReader reader(bag.string());
  EXPECT_GE(read_sequences(reader).sequences.size(), count);
}

// ---- 5. a full disk -----------------------------------------------------------------------

struct FillResult {
  uint64_t accepted = 0;  // write() calls that returned
  std::string error;      // what the one that threw said
};

FillResult fill_until_full(BagWriter& writer, uint32_t topic) {
  FillResult result;
  for (uint64_t seq = 1; seq < 100'000; ++seq) {
    try {
      writer.write(topic, kEpoch + static_cast<int64_t>(seq), sequence_payload(seq, 10 * 1024));
      result.accepted = seq;
    } catch (const BagError& e) {
      result.error = e.what();
      break;
    }
  }
  return result;
}

TEST(BagDiskFull, MaxBytesEndsTheRecordingCleanly) {
  TempDir dir;
  const fs::path bag = dir / "limited";
  BagWriterOptions options;
  options.max_bytes = 256 * 1024;
  BagWriter writer(bag.string(), options);
  uint32_t topic = writer.add_topic({"/big", "std_msgs/msg/ByteMultiArray", "cdr", {}});
  FillResult fill = fill_until_full(writer, topic);
  ASSERT_FALSE(fill.error.empty()) << "max_bytes never reached";
  EXPECT_THAT(fill.error, HasSubstr("full"));
  EXPECT_THAT(fill.error, HasSubstr("limited_0.db3"));
  EXPECT_GT(fill.accepted, 5u);
  EXPECT_THROW(writer.write(topic, kEpoch, sequence_payload(1, 10)), BagError);
  EXPECT_NO_THROW(writer.close());
  // Within the limit, the metadata row included.
  EXPECT_LE(fs::file_size(db_of(bag)), options.max_bytes);

  BagReader reader(bag.string());
  ReadBack back = read_sequences(reader);
  EXPECT_TRUE(reader.problems().empty()) << ::testing::PrintToString(reader.problems());
  EXPECT_GT(back.sequences.size(), 0u);
  EXPECT_TRUE(consecutive_from_one(back.sequences));
  // The open transaction's messages did fit: committed after the error, none lost.
  EXPECT_EQ(back.sequences.size(), fill.accepted);
  EXPECT_THAT(fill.error, HasSubstr(fmt::format("keeps the {} committed", fill.accepted)));
  EXPECT_EQ(writer.metadata().message_count, fill.accepted);
  EXPECT_EQ(parse_metadata_yaml(read_file(bag / "metadata.yaml"), "m").message_count,
            fill.accepted);
  RawDb db(db_of(bag), SQLITE_OPEN_READONLY);
  EXPECT_EQ(db.rows("SELECT count(*) FROM metadata"),
            (std::vector<std::vector<std::string>>{{"1"}}));
}

// An MCAP file that closes a chunk per message: its summary's chunk indexes (about a hundred
// bytes a chunk) outgrow any fixed reserve, and close() must still end within max_bytes.
TEST(BagDiskFull, MaxBytesHoldsForAnMcapFileOfManySmallChunks) {
  TempDir dir;
  const fs::path bag = dir / "chunky";
  BagWriterOptions options;
  options.storage = "mcap";
  options.commit_messages = 1;
  options.max_bytes = 2 * 1024 * 1024;
  BagWriter writer(bag.string(), options);
  uint32_t topic = writer.add_topic({"/small", "std_msgs/msg/ByteMultiArray", "cdr", {}});
  FillResult fill;
  for (uint64_t seq = 1; seq < 100'000; ++seq) {
    try {
      writer.write(topic, kEpoch + static_cast<int64_t>(seq), sequence_payload(seq, 1000));
      fill.accepted = seq;
    } catch (const BagError& e) {
      fill.error = e.what();
      break;
    }
  }
  ASSERT_FALSE(fill.error.empty()) << "max_bytes never reached";
  EXPECT_THAT(fill.error, HasSubstr("max_bytes reached"));
  EXPECT_GT(fill.accepted, 1000u);  // a chunk each: more index than the fixed reserve
  EXPECT_NO_THROW(writer.close());
  const fs::path file = bag / "chunky_0.mcap";
  EXPECT_LE(fs::file_size(file), options.max_bytes);

  BagReader reader(bag.string());
  ReadBack back = read_sequences(reader);
  EXPECT_TRUE(reader.problems().empty()) << ::testing::PrintToString(reader.problems());
  EXPECT_EQ(back.sequences.size(), fill.accepted);
  EXPECT_TRUE(consecutive_from_one(back.sequences));
}

TEST(BagDiskFull, RealFullFileSystem) {
  if (geteuid() != 0) GTEST_SKIP() << "mounting a small tmpfs needs root";
  TempDir dir;
  const fs::path mount_point = dir / "fs";
  fs::create_directories(mount_point);
  auto [code, output] = mocap::test::run_command(
      {"mount", "-t", "tmpfs", "-o", "size=512k", "tmpfs", mount_point.string()});
  if (code != 0) GTEST_SKIP() << "cannot mount a tmpfs here: " << output;
  struct Unmount {
    fs::path path;
    ~Unmount() { mocap::test::run_command({"umount", path.string()}); }
  } unmount{mount_point};

  const fs::path bag = mount_point / "bag";
  FillResult fill;
  {
    BagWriter writer(bag.string());
    uint32_t topic = writer.add_topic({"/big", "std_msgs/msg/ByteMultiArray", "cdr", {}});
    fill = fill_until_full(writer, topic);
    ASSERT_FALSE(fill.error.empty()) << "a 512 KiB file system never filled";
    EXPECT_THAT(fill.error, HasSubstr("full"));
    EXPECT_NO_THROW(writer.close());
  }
  BagReader reader(bag.string());
  ReadBack back = read_sequences(reader);
  // All in one would-be transaction (100 ms): the writer commits ahead of a message the disk
  // may not hold, so only that one is lost.
  EXPECT_GT(back.sequences.size(), 5u);
  EXPECT_EQ(back.sequences.size(), fill.accepted) << fill.error;
  EXPECT_TRUE(consecutive_from_one(back.sequences));
  EXPECT_EQ(back.damaged, 0u);
  EXPECT_EQ(reader.metadata().message_count, back.sequences.size());
}

// ---- 6. damaged bags ----------------------------------------------------------------------

TEST(ReadDamage, TruncatedDatabaseGivesWhatItsIntactPagesHold) {
  TempDir dir;
  const fs::path bag = dir / "cut";
  constexpr uint64_t kTotal = 600;
  // 100 B to 16 KB: small rows on the leaves, large ones with overflow pages.
  write_sequence_bag(bag, kTotal, [](uint64_t seq) { return 100 + (seq * 7919) % 16000; });
  const fs::path db = db_of(bag);
  fs::resize_file(db, fs::file_size(db) * 6 / 10);

  BagReader reader(bag.string());
  ReadBack back = read_sequences(reader);
  EXPECT_EQ(back.damaged, 0u) << "a payload came back altered";
  EXPECT_GT(back.sequences.size(), kTotal / 3);
  EXPECT_LT(back.sequences.size(), kTotal);
  EXPECT_TRUE(strictly_increasing(back.sequences));
  EXPECT_EQ(back.sequences.front(), 1u);
  ASSERT_FALSE(reader.problems().empty());
  for (const std::string& problem : reader.problems()) EXPECT_THAT(problem, HasSubstr("cut_0.db3"));
  EXPECT_THAT(reader.problems().front(), HasSubstr("malformed"));
  // The counts are what can be read.
  EXPECT_LT(reader.metadata().message_count, kTotal);
  EXPECT_GE(reader.metadata().message_count, back.sequences.size());

  // Again from the start: the same messages, no new problem lines.
  const size_t problems = reader.problems().size();
  reader.rewind();
  EXPECT_EQ(read_sequences(reader).sequences, back.sequences);
  EXPECT_EQ(reader.problems().size(), problems);
}

TEST(ReadDamage, GarbageInTheMiddleIsSkipped) {
  TempDir dir;
  const fs::path bag = dir / "garbled";
  constexpr uint64_t kTotal = 3000;
  // Payloads that fit in a b-tree page: SQLite has no checksums, so garbage over a payload's
  // bytes would come back as data; garbage over a page's header is what it detects.
  write_sequence_bag(bag, kTotal, [](uint64_t seq) { return 100 + (seq * 131) % 900; });
  const fs::path db = db_of(bag);
  std::string bytes = read_file(db);
  const size_t page = (static_cast<uint8_t>(bytes[16]) << 8) | static_cast<uint8_t>(bytes[17]);
  ASSERT_EQ(bytes.size() % page, 0u);
  // The first table leaf (flag 13) past the middle, and the two pages after it.
  size_t target = bytes.size() / 2 / page * page;
  while (target < bytes.size() && bytes[target] != 13) target += page;
  ASSERT_LT(target + 3 * page, bytes.size());
  std::mt19937 random(7);
  for (size_t i = target; i < target + 3 * page; ++i) bytes[i] = static_cast<char>(random());
  {
    std::ofstream out(db, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }

  const auto start = std::chrono::steady_clock::now();
  BagReader reader(bag.string());
  ReadBack back = read_sequences(reader);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
  EXPECT_EQ(back.damaged, 0u) << "a payload came back altered";
  EXPECT_GT(back.sequences.size(), kTotal / 2);
  EXPECT_LT(back.sequences.size(), kTotal);
  EXPECT_TRUE(strictly_increasing(back.sequences));
  ASSERT_FALSE(reader.problems().empty());
  EXPECT_THAT(reader.problems().front(), HasSubstr("garbled_0.db3"));
  // The gap is in the middle: both ends were read.
  EXPECT_EQ(back.sequences.front(), 1u);
  EXPECT_EQ(back.sequences.back(), kTotal);
}

// SQLite's variable-length integer: big-endian 7-bit groups, the ninth byte whole.
uint64_t sqlite_varint(const std::string& bytes, size_t& at) {
  uint64_t value = 0;
  for (int i = 0; i < 9; ++i) {
    const auto byte = static_cast<uint8_t>(bytes.at(at++));
    if (i == 8) return (value << 8) | byte;
    value = (value << 7) | (byte & 0x7f);
    if ((byte & 0x80) == 0) break;
  }
  return value;
}

TEST(ReadDamage, ALongDamagedStretchLosesExactlyTheRowsOfItsPages) {
  // Thousands of consecutive ids on garbled leaf pages, more than salvage seeks one by one:
  // it must step past them and find where they end to the id.
  TempDir dir;
  const fs::path bag = dir / "long";
  constexpr uint64_t kTotal = 20000;
  write_sequence_bag(bag, kTotal, [](uint64_t) { return 16; });
  const fs::path db = db_of(bag);
  std::string bytes = read_file(db);
  const size_t page = (static_cast<uint8_t>(bytes[16]) << 8) | static_cast<uint8_t>(bytes[17]);
  auto u16 = [&](size_t at) {
    return static_cast<size_t>((static_cast<uint8_t>(bytes[at]) << 8) |
                               static_cast<uint8_t>(bytes[at + 1]));
  };
  // The message table's leaf pages (flag 13, past the topics table's) by their first row id.
  std::map<uint64_t, size_t> leaf_at;
  for (size_t at = page; at + page <= bytes.size(); at += page) {
    if (bytes[at] != 13 || u16(at + 3) == 0) continue;
    size_t cell = at + u16(at + 8);
    sqlite_varint(bytes, cell);  // payload size
    leaf_at[sqlite_varint(bytes, cell)] = at;
  }
  ASSERT_GT(leaf_at.size(), 50u);
  // Consecutive leaves from the middle of the ids, 3000 rows or more.
  auto first = leaf_at.lower_bound(kTotal / 3);
  auto end = first;
  while (end != leaf_at.end() && end->first - first->first < 3000) ++end;
  ASSERT_NE(end, leaf_at.end());
  const uint64_t lost_from = first->first, lost_to = end->first - 1;
  std::mt19937 random(11);
  for (auto leaf = first; leaf != end; ++leaf) {
    for (size_t i = leaf->second; i < leaf->second + page; ++i)
      bytes[i] = static_cast<char>(random());
  }
  write_file(db, bytes);

  BagReader reader(bag.string());
  ReadBack back = read_sequences(reader);
  EXPECT_EQ(back.damaged, 0u) << "a payload came back altered";
  std::vector<uint64_t> expected;
  for (uint64_t seq = 1; seq <= kTotal; ++seq) {
    if (seq < lost_from || seq > lost_to) expected.push_back(seq);
  }
  EXPECT_EQ(back.sequences, expected);
  ASSERT_EQ(reader.problems().size(), 1u);
  EXPECT_THAT(reader.problems()[0],
              HasSubstr(fmt::format("({}, ids {}-{}) unreadable", lost_to - lost_from + 1,
                                    lost_from, lost_to)));
}

TEST(ReadDamage, RandomBytesAreNotABag) {
  TempDir dir;
  std::string noise(64 * 1024, '\0');
  std::mt19937 random(3);
  for (char& c : noise) c = static_cast<char>(random());
  const fs::path bag = dir / "noise";
  fs::create_directories(bag);
  write_file(bag / "x.db3", noise);
  for (const fs::path& path : {bag / "x.db3", bag}) {
    try {
      BagReader reader(path.string());
      FAIL() << path << " read as a bag";
    } catch (const BagError& e) {
      EXPECT_THAT(e.what(), HasSubstr("x.db3"));
      EXPECT_THAT(e.what(), HasSubstr("not a database"));
    }
  }
  try {
    BagReader reader((dir / "nowhere").string());
    FAIL() << "a missing path read as a bag";
  } catch (const BagError& e) {
    EXPECT_THAT(e.what(), HasSubstr("nowhere"));
  }
  fs::create_directories(dir / "empty");
  EXPECT_THROW(BagReader((dir / "empty").string()), BagError);
}

TEST(ReadDamage, MalformedMetadataYamlFallsBackToTheDatabases) {
  TempDir dir;
  const fs::path bag = dir / "yaml";
  write_sequence_bag(bag, 50, [](uint64_t) { return 64; });
  std::string yaml = read_file(bag / "metadata.yaml");
  yaml.replace(yaml.find("version: 5"), 10, "version: five");
  write_file(bag / "metadata.yaml", yaml);

  try {
    parse_metadata_yaml(yaml, (bag / "metadata.yaml").string());
    FAIL() << "malformed metadata.yaml parsed";
  } catch (const BagError& e) {
    EXPECT_THAT(e.what(), HasSubstr("metadata.yaml"));
    EXPECT_THAT(e.what(), HasSubstr("rosbag2_bagfile_information.version"));
  }
  BagReader reader(bag.string());
  ASSERT_EQ(reader.problems().size(), 1u);
  EXPECT_THAT(reader.problems()[0], HasSubstr("metadata.yaml"));
  EXPECT_THAT(reader.problems()[0], HasSubstr("version"));
  ReadBack back = read_sequences(reader);
  EXPECT_EQ(back.sequences.size(), 50u);
  EXPECT_TRUE(consecutive_from_one(back.sequences));

  // Other keys are named as precisely, with their line.
  try {
    parse_metadata_yaml(
        "rosbag2_bagfile_information:\n  version: 5\n  topics_with_message_count:\n    - "
        "topic_metadata:\n        type: x\n",
        "m.yaml");
    FAIL();
  } catch (const BagError& e) {
    EXPECT_THAT(e.what(), HasSubstr("m.yaml:5: rosbag2_bagfile_information."
                                    "topics_with_message_count[0].topic_metadata.name: missing"));
  }
  EXPECT_THROW(parse_metadata_yaml("key: [unclosed", "m.yaml"), BagError);

  // A listed file that is missing: reported, and the directory's files are read instead.
  write_sequence_bag(dir / "listed", 5, [](uint64_t) { return 20; });
  fs::rename(db_of(dir / "listed"), dir / "listed" / "renamed.db3");
  BagReader listed((dir / "listed").string());
  EXPECT_EQ(read_sequences(listed).sequences.size(), 5u);
  ASSERT_FALSE(listed.problems().empty());
  EXPECT_THAT(listed.problems()[0], HasSubstr("listed_0.db3: listed in metadata.yaml but missing"));
}

// ---- 7. writer errors ---------------------------------------------------------------------

TEST(BagWriterErrors, RefusesMisuse) {
  TempDir dir;
  const fs::path occupied = dir / "occupied";
  fs::create_directories(occupied);
  write_file(occupied / "notes.txt", "mine");
  try {
    BagWriter writer(occupied.string());
    FAIL() << "wrote into a non-empty directory";
  } catch (const BagError& e) {
    EXPECT_THAT(e.what(), HasSubstr(occupied.string()));
    EXPECT_THAT(e.what(), HasSubstr("not empty"));
  }
  EXPECT_EQ(read_file(occupied / "notes.txt"), "mine");

  write_file(dir / "file", "x");
  EXPECT_THROW(BagWriter((dir / "file").string()), BagError);

  // An existing empty directory is fine; the name comes from it even with a trailing slash.
  fs::create_directories(dir / "empty");
  BagWriter writer((dir / "empty").string() + "/");
  EXPECT_TRUE(fs::exists(dir / "empty" / "empty_0.db3"));
  uint32_t topic = writer.add_topic({"/a", "std_msgs/msg/Empty", "cdr", {}});
  try {
    writer.add_topic({"/a", "std_msgs/msg/String", "cdr", {}});
    FAIL() << "a topic added twice";
  } catch (const BagError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/a"));
    EXPECT_THAT(e.what(), HasSubstr("twice"));
  }
  for (uint32_t bad : {0u, topic + 1, 99u}) {
    try {
      writer.write(bad, kEpoch, sequence_payload(1, 20));
      FAIL() << "wrote to topic id " << bad;
    } catch (const BagError& e) {
      EXPECT_THAT(e.what(), HasSubstr(fmt::format("unknown topic id {}", bad)));
      EXPECT_THAT(e.what(), HasSubstr("empty_0.db3"));
    }
  }
  writer.write(topic, kEpoch, sequence_payload(1, 20));
  writer.close();
  EXPECT_THROW(writer.write(topic, kEpoch, sequence_payload(2, 20)), BagError);
  EXPECT_THROW(writer.add_topic({"/b", "std_msgs/msg/Empty", "cdr", {}}), BagError);
  writer.commit();  // nothing to do, no error
  BagReader reader((dir / "empty").string());
  EXPECT_EQ(reader.metadata().message_count, 1u);
}

TEST(BagWriterErrors, EmptyBagIsReadable) {
  TempDir dir;
  { BagWriter writer((dir / "nothing").string()); }
  BagReader reader((dir / "nothing").string());
  EXPECT_EQ(reader.metadata().message_count, 0u);
  EXPECT_TRUE(reader.metadata().topics.empty());
  BagMessage message;
  EXPECT_FALSE(reader.next(message));
  EXPECT_TRUE(reader.problems().empty());
}

}  // namespace
