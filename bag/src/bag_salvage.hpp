// A damaged rosbag2 sqlite3 file's salvage: every row whose id, topic and timestamp can still be
// read, found by walking the messages table's b-tree by ranges of ids and seeking past each
// damaged stretch to where it walks again (as LevelDB keeps db/repair.cc beside db_impl.cc,
// this is the reader's repair, kept beside it). One problem line per damaged stretch.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sqlite_database.hpp"

namespace mocap::bag {

// A message of a sqlite3 file as the reader indexes it: where it is in time, and its row.
struct Row {
  int64_t timestamp, id, topic_id;
  auto key() const { return std::pair(timestamp, id); }
};

// Keeps the row a "SELECT id, topic_id, timestamp" statement is on, or counts it in `untimed`
// when its timestamp is NULL (it cannot be placed in time).
void keep_row(const sqlite::Statement& row, std::vector<Row>& rows, uint64_t& untimed);

struct SalvagedRows {
  std::vector<Row> rows;  // unsorted
  uint64_t untimed = 0;   // rows found without a timestamp
};

// The rows of `db`'s messages table that can still be read. `file_name` names the file in the
// problem lines; `expected_count` (metadata.yaml's) says how many there were where the file
// cannot; `first_reason` is why reading failed first. Each problem line goes to `problem`.
SalvagedRows salvage_rows(sqlite::Database& db, const std::string& file_name,
                          std::optional<uint64_t> expected_count, std::string first_reason,
                          const std::function<void(std::string)>& problem);

}  // namespace mocap::bag
