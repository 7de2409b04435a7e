// Recording throughput of BagWriter (both storages: sqlite3, and MCAP with zstd chunks and
// without compression), and of the Recorder in front of it, against raw SQLite doing the same
// work, measured in the same run. The payloads are random bytes, which no compressor shrinks:
// zstd's cost without its gain, the worst case for MCAP. Raw SQLite: rosbag2's schema, WAL with
// synchronous=NORMAL, one prepared INSERT, transactions of 1000 messages. Two loads: 1280x720 mono8
// images as sensor_msgs/Image CDR (921 600 bytes of pixels and a ~60-byte header) and small
// ~100-byte messages. Writes into a temporary directory under /tmp (deleted afterwards), so the
// numbers are those of the file system of /tmp, which the output names.
//   build/bin/bag_record_bench [--quick]
#include <sqlite3.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <mocap/bag/bag_writer.hpp>
#include <mocap/bag/recorder.hpp>
#include <sensor_msgs/msg/image.hpp>

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Load {
  std::string name;
  size_t payload_bytes;
  int messages;
};

struct Result {
  double seconds = 0;
  uint64_t bytes = 0;
  int messages = 0;
  double per_second() const { return messages / seconds; }
  double megabytes_per_second() const { return static_cast<double>(bytes) / 1e6 / seconds; }
};

std::vector<std::vector<uint8_t>> make_payloads(size_t size, int distinct) {
  std::mt19937 random(1);
  std::vector<std::vector<uint8_t>> payloads(static_cast<size_t>(distinct));
  for (auto& payload : payloads) {
    payload.resize(size);
    for (uint8_t& byte : payload) byte = static_cast<uint8_t>(random());
  }
  return payloads;
}

void check(int code, sqlite3* db, const char* what) {
  if (code != SQLITE_OK && code != SQLITE_DONE && code != SQLITE_ROW) {
    throw std::runtime_error(fmt::format("{}: {}", what, sqlite3_errmsg(db)));
  }
}

// What a first implementation would write: rosbag2's schema and pragmas, straight SQLite.
Result raw_sqlite(const fs::path& directory, const Load& load,
                  const std::vector<std::vector<uint8_t>>& payloads) {
  fs::create_directories(directory);
  sqlite3* db = nullptr;
  const auto start = Clock::now();
  check(sqlite3_open_v2((directory / "raw_0.db3").c_str(), &db,
                        SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr),
        db, "open");
  check(sqlite3_exec(db,
                     "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;"
                     "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT "
                     "NULL);"
                     "INSERT INTO schema VALUES (3, 'humble');"
                     "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT "
                     "NULL,metadata TEXT NOT NULL);"
                     "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT "
                     "NOT NULL,serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT "
                     "NULL);"
                     "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT "
                     "NULL,timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
                     "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
                     "INSERT INTO topics VALUES (1, '/bench', 'sensor_msgs/msg/Image', 'cdr', "
                     "'');",
                     nullptr, nullptr, nullptr),
        db, "schema");
  sqlite3_stmt* insert = nullptr;
  check(sqlite3_prepare_v2(db, "INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)",
                           -1, &insert, nullptr),
        db, "prepare");
  Result result;
  for (int i = 0; i < load.messages; ++i) {
    if (i % 1000 == 0) check(sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr), db, "begin");
    const auto& payload = payloads[static_cast<size_t>(i) % payloads.size()];
    sqlite3_bind_int64(insert, 1, 1'700'000'000'000'000'000 + i);
    sqlite3_bind_int64(insert, 2, 1);
    sqlite3_bind_blob64(insert, 3, payload.data(), payload.size(), SQLITE_STATIC);
    check(sqlite3_step(insert), db, "insert");
    sqlite3_reset(insert);
    result.bytes += payload.size();
    if (i % 1000 == 999) check(sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr), db, "commit");
  }
  if (sqlite3_get_autocommit(db) == 0) {
    check(sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr), db, "commit");
  }
  sqlite3_finalize(insert);
  check(sqlite3_close(db), db, "close");
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.messages = load.messages;
  return result;
}

Result bag_writer(const fs::path& directory, const Load& load,
                  const std::vector<std::vector<uint8_t>>& payloads,
                  const std::string& storage = "sqlite3", const std::string& compression = "") {
  const auto start = Clock::now();
  mocap::bag::BagWriterOptions options;
  options.storage = storage;
  options.compression = compression;
  options.commit_messages = 1000;
  // Transactions of 1000 as the raw reference; the time limit only ends the last one.
  options.commit_interval = std::chrono::hours(1);
  mocap::bag::BagWriter writer(directory.string(), options);
  const uint32_t topic = writer.add_topic({"/bench", "sensor_msgs/msg/Image", "cdr", {}});
  for (int i = 0; i < load.messages; ++i) {
    writer.write(topic, 1'700'000'000'000'000'000 + i,
                 payloads[static_cast<size_t>(i) % payloads.size()]);
  }
  writer.close();
  Result result;
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.messages = load.messages;
  result.bytes = writer.bytes_written();
  return result;
}

// The recorder as mocap_bag record (raw CDR) and the bag_recorder component (typed messages,
// serialized by its writer thread) use it: a queue in front of a BagWriter on its own thread.
// `image`: record typed 1280x720 sensor_msgs/Image messages instead of the raw payloads.
Result recorder(const fs::path& directory, const Load& load,
                const std::vector<std::vector<uint8_t>>& payloads, bool image) {
  std::vector<std::shared_ptr<const void>> messages;
  for (const auto& payload : payloads) {
    if (image) {
      auto typed = std::make_shared<sensor_msgs::msg::Image>();
      typed->height(720);
      typed->width(1280);
      typed->encoding("mono8");
      typed->step(1280);
      typed->data(std::vector<uint8_t>(payload.begin(), payload.begin() + 1280 * 720));
      messages.push_back(std::move(typed));
    } else {
      messages.push_back(std::make_shared<const std::vector<uint8_t>>(payload));
    }
  }
  const mocap::MessageType* type =
      image ? &mocap::message_type<sensor_msgs::msg::Image>() : nullptr;
  const auto start = Clock::now();
  mocap::bag::RecorderOptions options;
  options.writer.storage = "mcap";  // as mocap_bag record and bag_recorder write by default
  options.writer.commit_messages = 1000;
  options.writer.commit_interval = std::chrono::hours(1);
  mocap::bag::Recorder recorder(directory.string(), options);
  const uint32_t topic = recorder.add_topic({"/bench", "sensor_msgs/msg/Image", "cdr", {}});
  for (int i = 0; i < load.messages; ++i) {
    recorder.record(topic, 1'700'000'000'000'000'000 + i,
                    messages[static_cast<size_t>(i) % messages.size()], type);
  }
  if (auto error = recorder.close()) throw std::runtime_error(*error);
  Result result;
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.messages = static_cast<int>(recorder.stats().written);
  result.bytes = recorder.stats().bytes;
  return result;
}

std::string file_system_of(const fs::path& path) {
  // The mount whose point is the longest prefix of `path`.
  std::ifstream mounts("/proc/mounts");
  std::string device, point, type, rest, best = "?";
  size_t best_length = 0;
  const std::string target = fs::canonical(path).string();
  while (mounts >> device >> point >> type && std::getline(mounts, rest)) {
    if (target.rfind(point, 0) == 0 && point.size() >= best_length) {
      best_length = point.size();
      best = fmt::format("{} ({} on {})", point, type, device);
    }
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const int rounds = quick ? 1 : 3;
  const fs::path root =
      fs::temp_directory_path() / fmt::format("bag_record_bench_{}", std::random_device()());
  fs::create_directories(root);
  fmt::print(
      "Bag recording throughput: BagWriter and the Recorder against raw SQLite inserts (same "
      "schema, WAL, "
      "synchronous=NORMAL, one prepared INSERT, transactions of 1000).\n");
  fmt::print("Disk: {}. Best of {} alternating rounds each.\n\n", file_system_of(root), rounds);

  // 1280x720 mono8 Image: header (stamp, frame_id, height, width, encoding, is_bigendian,
  // step, data length) ~60 bytes of CDR before the pixels.
  const std::vector<Load> loads = {
      {"1280x720 mono8 images", 4 + 60 + 1280 * 720, quick ? 60 : 300},
      {"small messages", 100, quick ? 40'000 : 200'000},
  };
  int status = 0;
  try {
    fmt::print("| load | writer | messages | messages/s | MB/s | ratio to raw |\n");
    fmt::print("|---|---|---:|---:|---:|---:|\n");
    int run = 0;
    for (const Load& load : loads) {
      const auto payloads = make_payloads(load.payload_bytes, load.payload_bytes > 10000 ? 4 : 256);
      // Rounds of raw then BagWriter, the best of each: on a shared machine one run of either
      // varies by tens of percent, which alternating and taking the best evens out.
      const bool images = load.payload_bytes > 10000;
      Result raw, ours, mcap_zstd, mcap_plain, queued, typed;
      for (int round = 0; round < rounds; ++round) {
        Result r = raw_sqlite(root / fmt::format("raw{}", run++), load, payloads);
        Result b = bag_writer(root / fmt::format("bag{}", run++), load, payloads);
        Result z = bag_writer(root / fmt::format("mcap{}", run++), load, payloads, "mcap", "zstd");
        Result p = bag_writer(root / fmt::format("mcap{}", run++), load, payloads, "mcap", "");
        Result q = recorder(root / fmt::format("rec{}", run++), load, payloads, false);
        if (round == 0 || r.seconds < raw.seconds) raw = r;
        if (round == 0 || b.seconds < ours.seconds) ours = b;
        if (round == 0 || z.seconds < mcap_zstd.seconds) mcap_zstd = z;
        if (round == 0 || p.seconds < mcap_plain.seconds) mcap_plain = p;
        if (round == 0 || q.seconds < queued.seconds) queued = q;
        if (images) {
          Result t = recorder(root / fmt::format("typed{}", run++), load, payloads, true);
          if (round == 0 || t.seconds < typed.seconds) typed = t;
        }
        std::error_code ignored;
        for (const auto& entry : fs::directory_iterator(root, ignored)) {
          fs::remove_all(entry, ignored);
        }
      }
      std::vector<std::pair<const char*, const Result&>> rows = {
          {"raw SQLite", raw},
          {"BagWriter, sqlite3", ours},
          {"BagWriter, MCAP, zstd chunks (the default)", mcap_zstd},
          {"BagWriter, MCAP, chunks uncompressed", mcap_plain},
          {"Recorder, MCAP (queue, writer thread; raw CDR as mocap_bag record)", queued}};
      if (images)
        rows.push_back(
            {"Recorder, MCAP, typed Image serialized by its thread (bag_recorder)", typed});
      for (const auto& [name, result] : rows) {
        fmt::print("| {} ({} B) | {} | {} | {:.0f} | {:.1f} | {:.2f} |\n", load.name,
                   load.payload_bytes, name, result.messages, result.per_second(),
                   result.megabytes_per_second(), result.per_second() / raw.per_second());
      }
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "bag_record_bench: {}\n", e.what());
    status = 1;
  }
  std::error_code ignored;
  fs::remove_all(root, ignored);
  return status;
}
