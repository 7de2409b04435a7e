#include <mocap/bag/bag_reader.hpp>

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <unordered_map>

#include <fmt/format.h>

#include "bag_salvage.hpp"
#include "mcap_reader.hpp"
#include "sqlite_database.hpp"
#include "stamps.hpp"

namespace mocap::bag {
namespace {

namespace fs = std::filesystem;

std::string uri_for(const std::string& path) {
  std::string uri = "file:";
  for (char c : fs::absolute(path).string()) {
    if (c == '%' || c == '?' || c == '#' || static_cast<unsigned char>(c) < 0x21) {
      uri += fmt::format("%{:02X}", static_cast<unsigned char>(c));
    } else {
      uri += c;
    }
  }
  return uri + "?immutable=1";
}

// "run_2.db3" before "run_10.db3", as rosbag2 numbers its split files.
bool natural_less(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      size_t i_end = i, j_end = j;
      while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
      while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
      std::string_view x(a.data() + i, i_end - i), y(b.data() + j, j_end - j);
      while (x.size() > 1 && x.front() == '0') x.remove_prefix(1);
      while (y.size() > 1 && y.front() == '0') y.remove_prefix(1);
      if (x.size() != y.size()) return x.size() < y.size();
      if (x != y) return x < y;
      i = i_end;
      j = j_end;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

struct FileState {
  std::string path;                        // what is opened
  std::string name;                        // what problems call it: relative to the bag directory
  std::optional<uint64_t> expected_count;  // from metadata.yaml, for salvage estimates
  sqlite::Database db;
  // An MCAP file instead: read in index mode, a Row's id being its place in messages().
  std::unique_ptr<mcap::FileReader> mcap;
  // topics.id (MCAP: the channel id) -> index in metadata().topics
  std::unordered_map<int64_t, size_t> topic_of;
  BagFile summary;

  // Stream: the database orders the rows (through timestamp_idx) and they are stepped one at
  // a time. Index: the (timestamp, id) of every row is in memory and payloads are fetched by
  // id; used where the database cannot stream in order (no index) or is damaged.
  bool indexed = false;
  sqlite::Statement cursor;   // stream mode, prepared lazily from the position
  std::vector<Row> rows;      // index mode, in reading order
  size_t next_row = 0;        // index mode
  sqlite::Statement payload;  // index mode: SELECT data ... WHERE id = ?
  // Rows with a NULL timestamp (our writer's schema refuses them; another's may not): they
  // cannot be placed in time, so they are skipped and counted, in both modes.
  uint64_t untimed = 0;

  // The last message returned from this file (both modes), where a switch to salvage resumes.
  std::optional<std::pair<int64_t, int64_t>> position;

  // Payloads that could not be read since the last one that could: one problem line each
  // stretch.
  struct Loss {
    uint64_t count = 0;
    int64_t first_ns = 0, last_ns = 0;
    std::string reason;
  } loss;
};

}  // namespace

struct BagReader::State {
  std::string path;
  BagMetadata metadata;
  std::vector<std::string> problems;
  std::set<std::string> reported;
  std::vector<std::unique_ptr<FileState>> files;
  std::vector<bool> wanted;  // per topic; empty: every topic
  size_t current = 0;
  // metadata.yaml's topics: the QoS of a schema version 1 database, which has no column
  // for it.
  std::vector<BagTopic> yaml_topics;

  void problem(std::string line) {
    if (reported.insert(line).second) problems.push_back(std::move(line));
  }

  bool is_wanted(size_t topic) const { return wanted.empty() || wanted[topic]; }

  // ---- construction -------------------------------------------------------------------

  // The files of the bag in reading order, with metadata.yaml's view of them when it has one.
  std::vector<std::unique_ptr<FileState>> list_files() {
    std::error_code error;
    const fs::file_status status = fs::status(path, error);
    if (!fs::exists(status)) {
      throw BagError(fmt::format("{}: no such file or directory", path));
    }
    std::vector<std::unique_ptr<FileState>> listed;
    if (!fs::is_directory(status)) {
      auto file = std::make_unique<FileState>();
      file->path = path;
      file->name = path;
      file->summary.path = fs::path(path).filename().string();
      listed.push_back(std::move(file));
      return listed;
    }

    std::optional<BagMetadata> from_yaml;
    const fs::path yaml_path = fs::path(path) / "metadata.yaml";
    if (fs::exists(yaml_path, error)) {
      std::ifstream in(yaml_path);
      std::stringstream text;
      text << in.rdbuf();
      if (!in) {
        problem(fmt::format(
            "{}: cannot read; reading the .mcap and .db3 files of the directory instead",
            yaml_path.string()));
      } else {
        try {
          from_yaml = parse_metadata_yaml(text.str(), yaml_path.string());
        } catch (const BagError& e) {
          problem(fmt::format("{}; reading the .mcap and .db3 files of the directory instead",
                              e.what()));
        }
      }
    }
    if (from_yaml) {
      for (const BagFile& file : from_yaml->files) {
        const fs::path file_path = fs::path(path) / file.path;
        if (!fs::is_regular_file(file_path, error)) {
          problem(fmt::format("{}: listed in metadata.yaml but missing", file.path));
          continue;
        }
        auto state = std::make_unique<FileState>();
        state->path = file_path.string();
        state->name = file.path;
        state->summary.path = file.path;
        if (file.message_count > 0) state->expected_count = file.message_count;
        listed.push_back(std::move(state));
      }
      yaml_topics = std::move(from_yaml->topics);
    }
    if (listed.empty()) {
      std::vector<std::string> names;
      for (const fs::directory_entry& entry : fs::directory_iterator(path, error)) {
        const fs::path extension = entry.path().extension();
        if ((extension == ".db3" || extension == ".mcap") && entry.is_regular_file(error)) {
          names.push_back(entry.path().filename().string());
        }
      }
      std::sort(names.begin(), names.end(), natural_less);
      for (const std::string& name : names) {
        auto state = std::make_unique<FileState>();
        state->path = (fs::path(path) / name).string();
        state->name = name;
        state->summary.path = name;
        listed.push_back(std::move(state));
      }
    }
    if (listed.empty()) {
      throw BagError(fmt::format("{}: not a bag: no .mcap or .db3 file{}", path,
                                 problems.empty() ? "" : " (" + problems.front() + ")"));
    }
    return listed;
  }

  // Opens read-only. A database left in WAL mode by a killed writer is read through its log,
  // which needs the -shm index to be usable; where a read-only connection cannot set that up,
  // a read-write one (that never writes and never checkpoints) may; where neither can (a
  // directory we may not write to), the database file alone is read, without the log.
  void open(FileState& file) {
    auto configure_and_probe = [&](sqlite::Database& db) {
      sqlite3_db_config(db.handle(), SQLITE_DBCONFIG_NO_CKPT_ON_CLOSE, 1, nullptr);
      // writable_schema: SQLite refuses a file shorter than its header says (a truncated
      // bag) unless it is set; reading stays read-only (query_only).
      db.exec("PRAGMA query_only=ON; PRAGMA writable_schema=ON; PRAGMA cell_size_check=ON",
              "configure");
      sqlite::Statement probe(db, "SELECT count(*) FROM sqlite_master");
      probe.step();
    };
    try {
      file.db = sqlite::Database(file.path, SQLITE_OPEN_READONLY, file.name);
      configure_and_probe(file.db);
      return;
    } catch (const sqlite::SqliteError& e) {
      if (!e.is_wal_access() || !fs::exists(file.path + "-wal")) throw;
    }
    try {
      file.db = sqlite::Database(file.path, SQLITE_OPEN_READWRITE, file.name);
      configure_and_probe(file.db);
      return;
    } catch (const sqlite::SqliteError& e) {
      file.db =
          sqlite::Database(uri_for(file.path), SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, file.name);
      configure_and_probe(file.db);
      problem(fmt::format(
          "{}: its write-ahead log {}-wal cannot be used ({}); the messages only in the log "
          "are missing (copy the bag to a directory you may write to, to read them)",
          file.name, fs::path(file.path).filename().string(), e.reason()));
    }
  }

  std::set<std::string> columns(sqlite::Database& db, const std::string& table) {
    std::set<std::string> names;
    sqlite::Statement info(db, fmt::format("PRAGMA table_info({})", table));
    while (info.step()) names.insert(info.column_text(1));
    return names;
  }

  // Topics (schema versions 1 to 4: offered_qos_profiles appears in 2, type_description_hash
  // in 4) merged by name into metadata.topics.
  void read_topics(FileState& file) {
    std::set<std::string> tables;
    {
      sqlite::Statement list(file.db, "SELECT name FROM sqlite_master WHERE type = 'table'");
      while (list.step()) tables.insert(list.column_text(0));
    }
    for (const char* table : {"topics", "messages"}) {
      if (!tables.contains(table)) {
        throw BagError(fmt::format("{}: not a rosbag2 database (no {} table)", file.name, table));
      }
    }
    if (tables.contains("schema")) {
      // Versions 1 and 2 have no schema table; 3 (Humble) and 4 (Jazzy) differ only in columns
      // read by name below. A later version may have moved things: said, then tried anyway.
      sqlite::Statement version(file.db, "SELECT max(schema_version) FROM schema");
      if (version.step() && version.column_int64(0) > 4) {
        problem(
            fmt::format("{}: schema version {} is newer than this reader knows (1 to 4); read "
                        "as version 4",
                        file.name, version.column_int64(0)));
      }
    }
    const std::set<std::string> topic_columns = columns(file.db, "topics");
    const bool has_format = topic_columns.contains("serialization_format");
    const bool has_qos = topic_columns.contains("offered_qos_profiles");
    sqlite::Statement topics(file.db,
                             fmt::format("SELECT id, name, type, {}, {} FROM topics ORDER BY id",
                                         has_format ? "serialization_format" : "'cdr'",
                                         has_qos ? "offered_qos_profiles" : "''"));
    while (topics.step()) {
      BagTopic topic;
      topic.name = topics.column_text(1);
      topic.type = topics.column_text(2);
      topic.serialization_format = topics.column_text(3);
      topic.offered_qos = parse_offered_qos_profiles(topics.column_text(4));
      auto known = std::find_if(metadata.topics.begin(), metadata.topics.end(),
                                [&](const BagTopic& t) { return t.name == topic.name; });
      if (known == metadata.topics.end()) {
        if (topic.offered_qos.empty()) {
          // Schema version 1 has no QoS column; metadata.yaml may still know.
          for (const BagTopic& listed : yaml_topics) {
            if (listed.name == topic.name) topic.offered_qos = listed.offered_qos;
          }
        }
        metadata.topics.push_back(std::move(topic));
        known = metadata.topics.end() - 1;
      } else if (known->offered_qos.empty()) {
        known->offered_qos = topic.offered_qos;
      }
      file.topic_of[topics.column_int64(0)] = static_cast<size_t>(known - metadata.topics.begin());
    }
  }

  std::string stream_sql(const FileState& file, bool with_filter) const {
    std::string ids;
    for (const auto& [id, topic] : file.topic_of) {
      if (with_filter && !is_wanted(topic)) continue;
      ids += (ids.empty() ? "" : ",") + std::to_string(id);
    }
    // The position as "timestamp >= ?1" lets SQLite walk timestamp_idx from there; the index
    // holds the row id after the timestamp, so (timestamp, id) order needs no sorting.
    return fmt::format(
        "SELECT id, topic_id, timestamp, data FROM messages WHERE timestamp >= ?1 AND "
        "(timestamp > ?1 OR id > ?2) AND topic_id IN ({}) ORDER BY timestamp, id",
        ids);
  }

  // True when SQLite would sort the whole table (with the payloads) before the first row: a
  // database without timestamp_idx.
  bool needs_sort(FileState& file) {
    sqlite::Statement plan(file.db, "EXPLAIN QUERY PLAN " + stream_sql(file, false));
    plan.bind(1, INT64_MIN).bind(2, INT64_MIN);
    while (plan.step()) {
      if (plan.column_text(3).find("TEMP B-TREE") != std::string::npos) return true;
    }
    return false;
  }

  // Messages per topic and the file's time span. Applied only when complete, so that a
  // count that fails half way (damage) leaves nothing counted twice.
  void count(FileState& file) {
    std::map<int64_t, uint64_t> unknown;
    std::vector<uint64_t> per_topic(metadata.topics.size(), 0);
    BagFile summary{file.summary.path};
    auto add = [&](int64_t topic_id, uint64_t n, int64_t first, int64_t last) {
      auto topic = file.topic_of.find(topic_id);
      if (topic == file.topic_of.end()) {
        unknown[topic_id] += n;
        return;
      }
      per_topic[topic->second] += n;
      if (summary.message_count == 0) {
        summary.start_ns = first;
        summary.duration_ns = clamped_difference(last, first);
      } else {
        const int64_t end = std::max(clamped_sum(summary.start_ns, summary.duration_ns), last);
        summary.start_ns = std::min(summary.start_ns, first);
        summary.duration_ns = clamped_difference(end, summary.start_ns);
      }
      summary.message_count += n;
    };
    if (file.indexed) {
      for (const Row& row : file.rows) add(row.topic_id, 1, row.timestamp, row.timestamp);
    } else {
      // Aggregates read the rows' first columns only, never the payloads' overflow pages.
      sqlite::Statement counts(file.db,
                               "SELECT topic_id, COUNT(timestamp), MIN(timestamp), MAX(timestamp), "
                               "COUNT(*) - COUNT(timestamp) FROM messages GROUP BY topic_id");
      file.untimed = 0;
      while (counts.step()) {
        const auto timed = static_cast<uint64_t>(counts.column_int64(1));
        if (timed > 0)
          add(counts.column_int64(0), timed, counts.column_int64(2), counts.column_int64(3));
        file.untimed += static_cast<uint64_t>(counts.column_int64(4));
      }
    }
    for (size_t i = 0; i < per_topic.size(); ++i) metadata.topics[i].message_count += per_topic[i];
    file.summary = summary;
    for (const auto& [topic_id, n] : unknown) {
      problem(fmt::format("{}: {} messages of topic id {}, which the topics table lacks, skipped",
                          file.name, n, topic_id));
    }
    if (file.untimed > 0) {
      problem(fmt::format("{}: {} messages without a timestamp, skipped", file.name, file.untimed));
    }
  }

  // True for a file that begins with MCAP's magic: the storage is told by content, not name.
  static bool is_mcap(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char start[mcap::kMagic.size()] = {};
    in.read(start, sizeof start);
    return in && std::string_view(start, sizeof start) == mcap::kMagic;
  }

  // An MCAP file's channels merged by topic name into metadata.topics (the type from the
  // channel's schema, the QoS from its offered_qos_profiles), and its messages as rows.
  void prepare_mcap(FileState& file) {
    file.mcap = std::make_unique<mcap::FileReader>(file.path);
    metadata.storage_identifier = "mcap";  // a bag's files are of one storage
    const mcap::FileReader& reader = *file.mcap;
    for (const std::string& line : reader.problems()) problem(line);
    for (const auto& [id, channel] : reader.channels()) {
      BagTopic topic;
      topic.name = channel.topic;
      auto schema = reader.schemas().find(channel.schema_id);
      if (schema != reader.schemas().end()) {
        topic.type = schema->second.name;
        if (schema->second.encoding == "ros2idl") topic.type_definition = schema->second.data;
      }
      topic.serialization_format = channel.message_encoding;
      auto qos = channel.metadata.find("offered_qos_profiles");
      if (qos != channel.metadata.end())
        topic.offered_qos = parse_offered_qos_profiles(qos->second);
      auto known = std::find_if(metadata.topics.begin(), metadata.topics.end(),
                                [&](const BagTopic& t) { return t.name == topic.name; });
      if (known == metadata.topics.end()) {
        metadata.topics.push_back(std::move(topic));
        known = metadata.topics.end() - 1;
      }
      file.topic_of[id] = static_cast<size_t>(known - metadata.topics.begin());
    }
    file.indexed = true;
    file.rows.clear();
    for (size_t i = 0; i < reader.messages().size(); ++i) {
      const mcap::MessagePlace& place = reader.messages()[i];
      file.rows.push_back(
          {static_cast<int64_t>(place.log_time), static_cast<int64_t>(i), place.channel_id});
    }
    std::sort(file.rows.begin(), file.rows.end(),
              [](const Row& a, const Row& b) { return a.key() < b.key(); });
    count(file);
  }

  void prepare(FileState& file) {
    if (is_mcap(file.path)) {
      prepare_mcap(file);
      return;
    }
    open(file);
    read_topics(file);
    try {
      if (needs_sort(file)) {
        build_index(file);
        file.indexed = true;
      }
      count(file);
    } catch (const sqlite::SqliteError& e) {
      // Damage in the message table: what can be read is found row by row, and the counts
      // come from that.
      salvage(file, e);
      count(file);
    }
  }

  void build_index(FileState& file) {
    std::vector<Row> rows;
    sqlite::Statement all(file.db, "SELECT id, topic_id, timestamp FROM messages");
    file.untimed = 0;
    while (all.step()) keep_row(all, rows, file.untimed);
    std::sort(rows.begin(), rows.end(),
              [](const Row& a, const Row& b) { return a.key() < b.key(); });
    file.rows = std::move(rows);
  }

  // Indexes the rows of a damaged file that can still be read (Salvage).
  void salvage(FileState& file, const sqlite::SqliteError& first_error) {
    file.indexed = true;
    file.cursor = {};
    file.rows.clear();
    file.next_row = 0;
    file.untimed = 0;
    SalvagedRows salvaged =
        salvage_rows(file.db, file.name, file.expected_count, first_error.reason(),
                     [this](std::string line) { problem(std::move(line)); });
    std::sort(salvaged.rows.begin(), salvaged.rows.end(),
              [](const Row& a, const Row& b) { return a.key() < b.key(); });
    file.rows = std::move(salvaged.rows);
    file.untimed = salvaged.untimed;
  }

  // ---- iteration ----------------------------------------------------------------------

  void flush_loss(FileState& file) {
    FileState::Loss& loss = file.loss;
    if (loss.count == 0) return;
    problem(loss.count == 1 ? fmt::format("{}: the message at {} unreadable: {}", file.name,
                                          time_of_day(loss.first_ns), loss.reason)
                            : fmt::format("{}: {} messages between {} and {} unreadable: {}",
                                          file.name, loss.count, time_of_day(loss.first_ns),
                                          time_of_day(loss.last_ns), loss.reason));
    loss = {};
  }

  // Switches a streaming file to salvage after an error, resuming after the last message
  // returned.
  void switch_to_salvage(FileState& file, const sqlite::SqliteError& error) {
    salvage(file, error);
    if (file.position) {
      file.next_row =
          static_cast<size_t>(std::upper_bound(file.rows.begin(), file.rows.end(), *file.position,
                                               [](const std::pair<int64_t, int64_t>& key,
                                                  const Row& row) { return key < row.key(); }) -
                              file.rows.begin());
    }
  }

  void fill(BagMessage& message, const FileState& file, int64_t topic_id, int64_t stamp,
            std::span<const uint8_t> data) {
    message.topic = &metadata.topics[file.topic_of.at(topic_id)];
    message.timestamp_ns = stamp;
    message.data.assign(data.begin(), data.end());
  }

  bool next_streamed(FileState& file, BagMessage& message) {
    if (!wanted.empty() && std::none_of(file.topic_of.begin(), file.topic_of.end(),
                                        [&](const auto& entry) { return wanted[entry.second]; })) {
      return false;
    }
    try {
      if (!file.cursor.is_prepared()) {
        file.cursor = sqlite::Statement(file.db, stream_sql(file, true));
        file.cursor.bind(1, file.position ? file.position->first : INT64_MIN)
            .bind(2, file.position ? file.position->second : INT64_MIN);
      }
      if (!file.cursor.step()) {
        file.cursor = {};
        return false;
      }
      const int64_t id = file.cursor.column_int64(0);
      const int64_t stamp = file.cursor.column_int64(2);
      fill(message, file, file.cursor.column_int64(1), stamp, file.cursor.column_blob(3));
      file.position = std::pair(stamp, id);
      return true;
    } catch (const sqlite::SqliteError& e) {
      switch_to_salvage(file, e);
      return next_indexed(file, message);
    }
  }

  bool next_indexed(FileState& file, BagMessage& message) {
    while (file.next_row < file.rows.size()) {
      const Row row = file.rows[file.next_row++];
      auto topic = file.topic_of.find(row.topic_id);
      if (topic == file.topic_of.end() || !is_wanted(topic->second)) continue;
      if (file.mcap) {
        try {
          const auto& place = file.mcap->messages()[static_cast<size_t>(row.id)];
          fill(message, file, row.topic_id, row.timestamp, file.mcap->data(place));
          file.position = row.key();
          flush_loss(file);
          return true;
        } catch (const BagError& e) {
          FileState::Loss& loss = file.loss;
          if (loss.count++ == 0) loss.first_ns = row.timestamp;
          loss.last_ns = row.timestamp;
          loss.reason = e.what();
          continue;
        }
      }
      try {
        if (!file.payload.is_prepared()) {
          file.payload = sqlite::Statement(file.db, "SELECT data FROM messages WHERE id = ?");
        }
        file.payload.reset();
        file.payload.bind(1, row.id);
        if (file.payload.step()) {
          fill(message, file, row.topic_id, row.timestamp, file.payload.column_blob(0));
          file.payload.reset();
          file.position = row.key();
          flush_loss(file);
          return true;
        }
        file.payload.reset();
      } catch (const sqlite::SqliteError& e) {
        file.payload.reset();
        FileState::Loss& loss = file.loss;
        if (loss.count++ == 0) loss.first_ns = row.timestamp;
        loss.last_ns = row.timestamp;
        loss.reason = e.reason();
      }
    }
    flush_loss(file);
    return false;
  }
};

BagReader::BagReader(const std::string& path) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.path = path;
  std::vector<std::unique_ptr<FileState>> listed = s.list_files();
  std::vector<std::string> failures;
  for (auto& file : listed) {
    try {
      s.prepare(*file);
      s.files.push_back(std::move(file));
    } catch (const BagError& e) {
      failures.push_back(e.what());
      s.problem(e.what());
    }
  }
  if (s.files.empty()) {
    // One file: its error names it already. Several: each reason names its file.
    std::string reasons;
    for (const std::string& failure : failures) reasons += (reasons.empty() ? "" : "; ") + failure;
    throw BagError(listed.size() == 1 && failures.size() == 1 && listed.front()->name == path
                       ? failures.front()
                       : fmt::format("{}: no readable bag file: {}", path, reasons));
  }

  BagMetadata& m = s.metadata;
  bool any = false;
  int64_t end = 0;
  for (const auto& file : s.files) {
    m.files.push_back(file->summary);
    if (file->summary.message_count == 0) continue;
    const int64_t file_end = clamped_sum(file->summary.start_ns, file->summary.duration_ns);
    m.start_ns = any ? std::min(m.start_ns, file->summary.start_ns) : file->summary.start_ns;
    end = any ? std::max(end, file_end) : file_end;
    m.message_count += file->summary.message_count;
    any = true;
  }
  m.duration_ns = any ? clamped_difference(end, m.start_ns) : 0;
}

BagReader::~BagReader() = default;

const BagMetadata& BagReader::metadata() const { return state_->metadata; }

void BagReader::set_topic_filter(const std::vector<std::string>& topics) {
  State& s = *state_;
  s.wanted.clear();
  if (!topics.empty()) {
    s.wanted.assign(s.metadata.topics.size(), false);
    for (const std::string& name : topics) {
      for (size_t i = 0; i < s.metadata.topics.size(); ++i) {
        if (s.metadata.topics[i].name == name) s.wanted[i] = true;
      }
    }
  }
  // Streaming cursors carry the old filter in their SQL: prepared again from where they are.
  for (auto& file : s.files) file->cursor = {};
}

bool BagReader::next(BagMessage& message) {
  State& s = *state_;
  while (s.current < s.files.size()) {
    FileState& file = *s.files[s.current];
    if (file.indexed ? s.next_indexed(file, message) : s.next_streamed(file, message)) return true;
    ++s.current;
  }
  return false;
}

void BagReader::rewind() {
  State& s = *state_;
  for (auto& file : s.files) {
    file->cursor = {};
    file->position.reset();
    file->next_row = 0;
    s.flush_loss(*file);
  }
  s.current = 0;
}

const std::vector<std::string>& BagReader::problems() const { return state_->problems; }

}  // namespace mocap::bag
