#include <mocap/bag/bag_writer.hpp>

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>

#include <fmt/format.h>

#include "mcap_writer.hpp"
#include "sqlite_database.hpp"

namespace mocap::bag {
namespace {

namespace fs = std::filesystem;
using SteadyClock = std::chrono::steady_clock;

// The schema of rosbag2_storage_sqlite3 version 3, character for character as ROS 2 Humble
// creates it: sqlite_master keeps the text, and tools that compare schemas compare it.
constexpr const char* kCreateSchema =
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);"
    "INSERT INTO schema (schema_version, ros_distro) VALUES (3, 'humble');"
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,"
    "metadata TEXT NOT NULL);"
    "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
    "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);"
    "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
    "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);";
constexpr int kMetadataVersion = 5;
// The database never holds less than this many pages whatever max_bytes says: the schema
// alone needs six.
constexpr int64_t kMinimumPages = 16;
// Pages a transaction may take beyond the estimate of its messages: interior b-tree pages,
// index pages, rounding.
constexpr double kSparePages = 4;
// What an MCAP file's close adds after its last chunk besides the chunk indexes (which
// FileWriter counts), at most for a bag of a few dozen topics: the metadata, DataEnd, the
// summary's schemas, channels and statistics, its offsets, the footer; and the index of the
// chunk a commit closes.
constexpr uint64_t kMcapCloseReserve = 64 * 1024;

std::string errno_text() { return std::strerror(errno); }

// Replaces `path` by `text` so that a reader (or a crash) sees the old file or the new one,
// never a mix.
void write_file_atomically(const fs::path& path, const std::string& text) {
  fs::path temporary = path;
  temporary += ".tmp";
  auto fail = [&](std::string_view what) {
    std::string message = fmt::format("{}: cannot {}: {}", path.string(), what, errno_text());
    ::unlink(temporary.c_str());
    throw BagError(message);
  };
  int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("create");
  for (size_t done = 0; done < text.size();) {
    ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      int saved = errno;
      ::close(fd);
      errno = saved;
      fail("write");
    }
    done += static_cast<size_t>(n);
  }
  // Without the sync a power cut after the rename may leave an empty file on some file
  // systems, where the old one was at least readable.
  if (::fsync(fd) != 0) {
    int saved = errno;
    ::close(fd);
    errno = saved;
    fail("write");
  }
  if (::close(fd) != 0) fail("write");
  if (::rename(temporary.c_str(), path.c_str()) != 0) fail("rename");
}

void extend_end(int64_t& start_ns, int64_t& duration_ns, uint64_t count, int64_t stamp) {
  if (count == 0) {
    start_ns = stamp;
    duration_ns = 0;
    return;
  }
  const int64_t end = start_ns + duration_ns;
  start_ns = std::min(start_ns, stamp);
  duration_ns = std::max(end, stamp) - start_ns;
}

}  // namespace

struct BagWriter::State {
  std::string directory;
  fs::path file_path, yaml_path;    // the .db3 or .mcap file, and metadata.yaml
  std::string file_name_in_errors;  // the file as errors name it
  BagWriterOptions options;
  // sqlite3
  sqlite::Database db;
  sqlite::Statement insert;
  // mcap: the file, each topic's channel, each type's schema
  std::optional<mcap::FileWriter> mcap;
  std::vector<uint16_t> channel_of;
  std::map<std::string, uint16_t> schema_of;

  // Everything write() accepted, and the part of it that is committed: a failed transaction
  // takes the counts back to `committed` (changed under committed_mutex, which
  // write_committed_metadata() takes from other threads).
  BagMetadata metadata, committed;
  mutable std::mutex committed_mutex;
  mutable std::mutex yaml_mutex;  // one metadata.yaml writer at a time
  uint64_t bytes = 0, committed_bytes = 0;

  size_t transaction_messages = 0;
  SteadyClock::time_point transaction_start;

  int64_t page_size = 4096;
  int64_t limit_pages = 0;     // max_bytes in pages, 0: none
  int64_t page_limit_now = 0;  // max_page_count in force: limit_pages less the reserve

  // Room accounting. SQLite answers a full disk (or max_page_count) during a plain INSERT by
  // rolling back the whole transaction, so a message that might not fit is written in a
  // transaction of its own, after committing the others: a full disk costs that one message
  // rather than the last commit_interval of them.
  int64_t committed_pages = 0;        // the database's size at the last commit
  double transaction_pages = 0;       // what the open transaction adds, estimated
  std::optional<uint64_t> disk_free;  // bytes free to us at the last commit
  bool failed = false;                // a write failed: only close() is left
  bool closed = false;

  void check_open(std::string_view what) const {
    if (closed) throw BagError(fmt::format("{}: {} after close()", file_name_in_errors, what));
    if (failed) {
      throw BagError(fmt::format("{}: {} after an earlier write error (only close() is left)",
                                 file_name_in_errors, what));
    }
  }

  // Keeps room below max_bytes for the metadata row close() adds, so that a bag that ran
  // into its limit still gets one.
  void apply_page_limit() {
    if (limit_pages == 0 || mcap) return;
    const auto yaml_size = static_cast<int64_t>(format_metadata_yaml(metadata).size());
    const int64_t reserve = 2 + 2 * yaml_size / page_size;
    page_limit_now = db.pragma_int(
        fmt::format("max_page_count = {}", std::max(kMinimumPages, limit_pages - reserve)));
  }

  // Pages a payload takes: what exceeds a leaf's share goes to whole overflow pages (SQLite's
  // file format); leaves run about 70% full after splits; the index adds ~20 bytes a row.
  double pages_for(size_t size) const {
    const auto page = static_cast<double>(page_size);
    const double max_local = page - 35, min_local = (page - 12) * 32 / 255 - 23;
    double local = static_cast<double>(size), overflow = 0;
    if (local > max_local) {
      overflow = std::ceil((local - min_local) / (page - 4));
      local = min_local;
    }
    return overflow + (local + 50) / (page * 0.7);
  }

  bool has_room_for(double message_pages) const {
    const double pages = transaction_pages + message_pages + kSparePages;
    if (limit_pages > 0 &&
        static_cast<double>(committed_pages) + pages > static_cast<double>(page_limit_now)) {
      return false;
    }
    // Each page goes to the log and, at the next checkpoint, to the database file.
    return !disk_free ||
           pages * static_cast<double>(page_size + 24) * 2 <= static_cast<double>(*disk_free);
  }

  void measure_room() {
    transaction_pages = 0;
    if (mcap) return;
    try {
      committed_pages = db.pragma_int("page_count");
    } catch (const sqlite::SqliteError&) {
      // Only an estimate: the next insert finds out.
    }
    struct statvfs fs_info {};
    if (::statvfs(directory.c_str(), &fs_info) == 0) {
      disk_free = static_cast<uint64_t>(fs_info.f_bavail) * fs_info.f_frsize;
    } else {
      disk_free.reset();
    }
  }

  void write_yaml(const std::string& text) const {
    std::lock_guard lock(yaml_mutex);
    write_file_atomically(yaml_path, text);
  }

  void set_committed() {
    std::lock_guard lock(committed_mutex);
    committed = metadata;
    committed_bytes = bytes;
  }

  void begin() {
    db.exec("BEGIN", "begin");
    transaction_start = SteadyClock::now();
    transaction_messages = 0;
  }

  // `accepted`: the messages write() has returned for, when the last one counted in
  // `metadata` is still being written.
  void commit_now(std::optional<uint64_t> accepted = std::nullopt) {
    if (mcap) {
      if (transaction_messages == 0) return;
      try {
        mcap->flush();
      } catch (const BagError& e) {
        fail_mcap(e);
      }
      set_committed();
      transaction_messages = 0;
      return;
    }
    if (!db.in_transaction()) return;
    try {
      db.exec("COMMIT", "commit");
    } catch (const sqlite::SqliteError& e) {
      fail(e, accepted);
    }
    set_committed();
    transaction_messages = 0;
    measure_room();
  }

  // After a failed insert or commit: keeps what can be kept, brings the counts back to what
  // the database holds, and throws the error write() reports.
  [[noreturn]] void fail(const sqlite::SqliteError& error,
                         std::optional<uint64_t> accepted_before = std::nullopt) {
    failed = true;
    const uint64_t accepted = accepted_before.value_or(metadata.message_count);
    if (db.in_transaction()) {
      // SQLite undid the failed statement but kept the transaction (it rolls the whole of it
      // back itself after a full disk during a plain INSERT, not after every error): what it
      // holds is worth a commit. If that fails too, it is rolled back.
      try {
        db.exec("COMMIT", "commit");
        set_committed();
      } catch (const sqlite::SqliteError&) {
        try {
          db.exec("ROLLBACK", "rollback");
        } catch (const sqlite::SqliteError&) {
          // Nothing more to do: an uncommitted transaction is dropped when the file closes.
        }
      }
    }
    metadata = committed;
    bytes = committed_bytes;
    if (error.primary_code() == SQLITE_FULL) {
      throw BagError(fmt::format(
          "{}: the disk is full (or max_bytes reached) after {} messages; the bag keeps the {} "
          "committed before",
          file_name_in_errors, accepted, committed.message_count));
    }
    throw BagError(fmt::format("{}; the bag keeps the {} messages committed before", error.what(),
                               committed.message_count));
  }

  // After a failed write or flush of the MCAP file: the counts go back to what whole chunks
  // hold, and write() reports the error.
  [[noreturn]] void fail_mcap(const BagError& error) {
    failed = true;
    metadata = committed;
    bytes = committed_bytes;
    throw BagError(fmt::format("{}; the bag keeps the {} messages committed before", error.what(),
                               committed.message_count));
  }

  void open_database() {
    db = sqlite::Database(file_path.string(), SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE,
                          file_name_in_errors);
    // Write-ahead logging: a commit appends to the log, so a writer killed at any point
    // leaves the last commit intact. NORMAL synchronisation: no fsync per commit (a killed
    // process loses nothing the OS has; a power cut may lose the last commits, never the
    // database).
    db.pragma_text("journal_mode=WAL");
    db.exec("PRAGMA synchronous=NORMAL");
    page_size = std::max<int64_t>(512, db.pragma_int("page_size"));
    if (options.max_bytes > 0) {
      limit_pages = std::max(kMinimumPages, static_cast<int64_t>(options.max_bytes) / page_size);
      apply_page_limit();
    }
    db.exec(std::string("BEGIN;") + kCreateSchema + "COMMIT;", "create the schema");
    // The schema in the database file itself rather than only in the log: a reader that can
    // not use the log (read-only directory) still finds the tables.
    db.pragma_text("wal_checkpoint(PASSIVE)");
    insert =
        sqlite::Statement(db, "INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)");
  }

  // The open chunk is written whole once past max_bytes would be reached: the bag keeps
  // every whole chunk before, and this write() reports the limit.
  void write_mcap(uint32_t topic_id, int64_t timestamp_ns, std::span<const uint8_t> data) {
    const uint64_t record = mcap::kRecordPrefix + mcap::kMessageHeaderSize + data.size();
    auto closing = [&] { return mcap->chunk_index_bytes() + kMcapCloseReserve; };
    if (options.max_bytes > 0 &&
        mcap->file_bytes() + mcap->open_chunk_bytes() + record + closing() > options.max_bytes) {
      commit_now();
      if (mcap->file_bytes() + record + closing() > options.max_bytes) {
        failed = true;
        throw BagError(fmt::format(
            "{}: max_bytes reached after {} messages; the bag keeps the {} committed before",
            file_name_in_errors, metadata.message_count, committed.message_count));
      }
    }
    if (transaction_messages == 0) transaction_start = SteadyClock::now();
    try {
      // MCAP's times are unsigned: a stamp before 1970 is not a receive time.
      mcap->write(channel_of[topic_id - 1],
                  static_cast<uint64_t>(std::max<int64_t>(0, timestamp_ns)),
                  static_cast<uint64_t>(std::max<int64_t>(0, timestamp_ns)), data);
    } catch (const BagError& e) {
      fail_mcap(e);
    }
  }

  void add_topic_row(uint32_t id, const BagTopic& topic) {
    try {
      sqlite::Statement statement(db,
                                  "INSERT INTO topics (id, name, type, serialization_format, "
                                  "offered_qos_profiles) VALUES (?, ?, ?, ?, ?)");
      const std::string qos = format_offered_qos_profiles(topic.offered_qos);
      statement.bind(1, id)
          .bind_text(2, topic.name)
          .bind_text(3, topic.type)
          .bind_text(4, topic.serialization_format)
          .bind_text(5, qos);
      statement.step();
    } catch (const sqlite::SqliteError& e) {
      fail(e);
    }
    try {
      // Into the database file, like the schema: a reader left without the log still knows
      // the topic of what was checkpointed.
      db.pragma_text("wal_checkpoint(PASSIVE)");
    } catch (const sqlite::SqliteError&) {
      // Only an optimisation for damaged bags; the log has the topic.
    }
  }

  // Removes what the constructor made when it fails half way, so that the caller may retry
  // in the same directory.
  void remove_partial(bool created_directory) {
    db = {};
    mcap.reset();
    std::error_code ignored;
    for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
      fs::path file = file_path;
      file += suffix;
      fs::remove(file, ignored);
    }
    fs::remove(yaml_path, ignored);
    if (created_directory) fs::remove(directory, ignored);
  }
};

BagWriter::BagWriter(const std::string& directory, BagWriterOptions options)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.directory = directory;
  s.options = options;
  if (directory.empty()) throw BagError("BagWriter: the bag directory is empty");
  const bool mcap = options.storage == "mcap";
  if (!mcap && options.storage != "sqlite3") {
    throw BagError(
        fmt::format("{}: unknown storage '{}' (sqlite3 or mcap)", directory, options.storage));
  }

  std::error_code error;
  bool created_directory = false;
  if (fs::exists(directory, error)) {
    if (!fs::is_directory(directory, error)) {
      throw BagError(fmt::format("{}: exists and is not a directory", directory));
    }
    if (!fs::is_empty(directory, error)) {
      throw BagError(fmt::format(
          "{}: exists and is not empty (a bag is never written into another)", directory));
    }
  } else {
    if (!fs::create_directories(directory, error) || error) {
      throw BagError(fmt::format("{}: cannot create the directory: {}", directory,
                                 error ? error.message() : "unknown error"));
    }
    created_directory = true;
  }

  // The name rosbag2 gives the file: the directory's last component, however the path is
  // spelt ("runs/walk/", ".").
  fs::path absolute = fs::weakly_canonical(fs::absolute(directory), error);
  if (error || absolute.filename().empty()) absolute = fs::absolute(directory).lexically_normal();
  if (absolute.filename().empty()) absolute = absolute.parent_path();
  const std::string file_name = absolute.filename().string() + (mcap ? "_0.mcap" : "_0.db3");
  s.file_path = fs::path(directory) / file_name;
  s.yaml_path = fs::path(directory) / "metadata.yaml";
  s.file_name_in_errors = s.file_path.string();

  try {
    if (mcap) {
      s.mcap.emplace(s.file_path.string(),
                     mcap::FileWriterOptions{.compression = options.compression});
      s.metadata.storage_identifier = "mcap";
    } else {
      s.open_database();
    }
    s.metadata.files.push_back({file_name, 0, 0, 0});
    s.committed = s.metadata;
    s.measure_room();
    s.write_yaml(format_metadata_yaml(s.metadata));
  } catch (const BagError&) {
    s.remove_partial(created_directory);
    throw;
  }
}

BagWriter::~BagWriter() {
  try {
    close();
  } catch (const std::exception& e) {
    fmt::print(stderr, "BagWriter: {}\n", e.what());
  }
}

uint32_t BagWriter::add_topic(const BagTopic& topic) {
  State& s = *state_;
  s.check_open("add_topic");
  if (topic.name.empty())
    throw BagError(fmt::format("{}: add_topic: empty topic name", s.file_name_in_errors));
  for (const BagTopic& known : s.metadata.topics) {
    if (known.name == topic.name) {
      throw BagError(fmt::format("{}: topic {} added twice", s.file_name_in_errors, topic.name));
    }
  }
  // Committed first, so that the topic's row never waits in a transaction with messages of
  // other topics that a crash would take away together.
  s.commit_now();
  const auto id = static_cast<uint32_t>(s.metadata.topics.size() + 1);
  if (s.mcap) {
    // One schema per type, as rosbag2 writes them. The schema is where MCAP keeps the type's
    // name, so a type whose definition is unknown still gets one: no encoding and no data, as
    // the specification has it for a schema without a definition.
    auto [known, added] = s.schema_of.emplace(topic.type, 0);
    if (added) {
      known->second = topic.type_definition.empty()
                          ? s.mcap->add_schema(topic.type, "", "")
                          : s.mcap->add_schema(topic.type, "ros2idl", topic.type_definition);
    }
    const uint16_t schema = known->second;
    s.channel_of.push_back(s.mcap->add_channel(
        topic.name, schema, topic.serialization_format,
        {{"offered_qos_profiles", format_offered_qos_profiles(topic.offered_qos)}}));
  } else {
    s.add_topic_row(id, topic);
  }
  BagTopic added = topic;
  added.message_count = 0;
  s.metadata.topics.push_back(added);
  s.committed.topics.push_back(added);
  s.apply_page_limit();
  s.measure_room();
  s.write_yaml(format_metadata_yaml(s.metadata));
  return id;
}

void BagWriter::write(uint32_t topic_id, int64_t timestamp_ns, std::span<const uint8_t> data) {
  State& s = *state_;
  s.check_open("write");
  if (topic_id == 0 || topic_id > s.metadata.topics.size()) {
    throw BagError(fmt::format("{}: write: unknown topic id {} ({} topics added)",
                               s.file_name_in_errors, topic_id, s.metadata.topics.size()));
  }
  double pages = 0;
  bool short_of_room = false;
  if (s.mcap) {
    s.write_mcap(topic_id, timestamp_ns, data);
  } else {
    // Short of room, the messages before go to the database first and this one alone, so
    // that a full disk costs this message only and is reported by this write().
    pages = s.pages_for(data.size());
    short_of_room = !s.has_room_for(pages);
    if (short_of_room && s.transaction_messages > 0) s.commit_now();
    try {
      if (!s.db.in_transaction()) s.begin();
      s.insert.bind(1, timestamp_ns).bind(2, topic_id).bind_blob(3, data);
      s.insert.step();
      s.insert.reset();
    } catch (const sqlite::SqliteError& e) {
      s.insert.reset();
      s.fail(e);
    }
  }

  BagMetadata& m = s.metadata;
  extend_end(m.start_ns, m.duration_ns, m.message_count, timestamp_ns);
  ++m.message_count;
  ++m.topics[topic_id - 1].message_count;
  BagFile& file = m.files.front();
  file.start_ns = m.start_ns;
  file.duration_ns = m.duration_ns;
  file.message_count = m.message_count;
  s.bytes += data.size();
  s.transaction_pages += pages;

  if (++s.transaction_messages >= s.options.commit_messages || short_of_room ||
      SteadyClock::now() - s.transaction_start >= s.options.commit_interval) {
    s.commit_now(m.message_count - 1);
  }
}

void BagWriter::commit() {
  State& s = *state_;
  if (s.closed || s.failed) return;
  s.commit_now();
}

void BagWriter::write_committed_metadata() const {
  const State& s = *state_;
  BagMetadata committed;
  {
    std::lock_guard lock(s.committed_mutex);
    committed = s.committed;
  }
  s.write_yaml(format_metadata_yaml(committed));
}

void BagWriter::close() {
  State& s = *state_;
  if (s.closed) return;
  s.closed = true;
  // After a write error the caller has been told already; what close() cannot do then
  // (the disk is still full) is only worth a line on stderr.
  std::optional<std::string> first_error;
  auto report = [&](const std::exception& e) {
    if (s.failed) {
      fmt::print(stderr, "BagWriter: closing after an error: {}\n", e.what());
    } else if (!first_error) {
      first_error = e.what();
    }
  };

  if (!s.failed) {
    try {
      s.commit_now();
    } catch (const BagError& e) {
      report(e);
    }
  }
  const std::string yaml = format_metadata_yaml(s.metadata);
  try {
    if (s.mcap) {
      // rosbag2 (Jazzy on) keeps the bag's metadata in the file too.
      s.mcap->set_metadata("rosbag2", {{"serialized_metadata", yaml}});
      s.mcap->close();
    } else {
      if (s.limit_pages > 0) s.db.pragma_int(fmt::format("max_page_count = {}", s.limit_pages));
      sqlite::Statement statement(
          s.db, "INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)");
      statement.bind(1, kMetadataVersion).bind_text(2, yaml);
      statement.step();
    }
  } catch (const BagError& e) {
    report(e);
  }
  try {
    s.write_yaml(yaml);
  } catch (const BagError& e) {
    report(e);
  }
  if (s.mcap) {
    if (first_error) throw BagError(*first_error);
    return;
  }
  try {
    // Back to a rollback journal: the log is merged into the database and removed, and the
    // closed bag is one self-contained file that read-only media and copies handle. When
    // that fails (a reader still has it open, the disk is full) the log stays, which readers
    // handle too.
    s.insert = {};
    s.db.pragma_text("journal_mode=DELETE");
  } catch (const BagError&) {
  }
  try {
    s.db.close();
  } catch (const BagError& e) {
    report(e);
  }
  if (first_error) throw BagError(*first_error);
}

const std::string& BagWriter::directory() const { return state_->directory; }

const BagMetadata& BagWriter::metadata() const { return state_->metadata; }

uint64_t BagWriter::bytes_written() const { return state_->bytes; }

}  // namespace mocap::bag
