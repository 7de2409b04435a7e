#include "bag_salvage.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "stamps.hpp"

namespace mocap::bag {
namespace {

// Salvage seeks past a damaged stretch up to the highest id known plus this margin (a damaged
// file may not say how many rows it had)...
constexpr int64_t kProbeMargin = 10000;
// ...one id at a time for this many seeks, ever longer steps after...
constexpr int64_t kLinearProbes = 1024;
// ...and never more than this many seeks per file, so that a file whose every page is garbage
// ends in seconds. Each damaged stretch costs at most kLinearProbes plus twice 63.
constexpr int64_t kProbeBudget = 200'000;
constexpr int kRangeBatch = 4096;

// salvage_rows()'s walk over one file.
class Salvage {
 public:
  Salvage(sqlite::Database& db, const std::string& name, std::optional<uint64_t> expected_count,
          std::string reason, const std::function<void(std::string)>& problem)
      : db_(db),
        name_(name),
        expected_count_(expected_count),
        reason_(std::move(reason)),
        problem_(problem) {}

  SalvagedRows run() {
    try {
      sqlite::Statement max(db_, "SELECT max(id) FROM messages");
      if (max.step() && !max.column_is_null(0)) max_id_ = max.column_int64(0);
    } catch (const sqlite::SqliteError&) {
    }
    try {
      range_.emplace(db_, fmt::format("SELECT id, topic_id, timestamp FROM messages WHERE "
                                      "id > ? ORDER BY id LIMIT {}",
                                      kRangeBatch));
      seek_.emplace(
          db_, "SELECT id, topic_id, timestamp FROM messages WHERE id >= ? ORDER BY id LIMIT 1");
    } catch (const sqlite::SqliteError& e) {
      problem_(fmt::format("{}: no message readable: {}", name_, e.reason()));
      return {};
    }
    for (;;) {
      walk_ranges();
      // The last row read, where one was (ids read are above 0, the cursor's start).
      const std::string before = cursor_ > 0 ? place(cursor_) : std::string();
      const Stretch damage = find_where_damage_ends();
      // Again where the damage ends, to read the row there.
      const bool row_after = damage.walks && seek_from(*damage.walks) == Seek::kRow;
      const int64_t lost = damage.walks ? *damage.walks - cursor_ - 1 : 0;
      if (row_after) {
        const int64_t next = seek_->column_int64(0);
        keep_row(*seek_, found_.rows, found_.untimed);
        seek_->reset();
        if (lost > 0) report_gap(before, next, lost, *damage.walks);
        cursor_ = next;
        continue;
      }
      seek_->reset();
      report_end(before, lost > 0 || (!damage.walks && cursor_ < damage.upper));
      return std::move(found_);
    }
  }

 private:
  static constexpr const char* kOutOfOrder = "the table's row ids are out of order";

  // Fast: ranges of ids while the b-tree can be walked, from cursor_ on.
  void walk_ranges() {
    try {
      for (bool more = true; more;) {
        range_->reset();
        range_->bind(1, cursor_);
        int n = 0;
        while (more && range_->step()) {
          // A damaged b-tree can give ids out of order: reading on from a smaller id would
          // read the same rows again.
          if (const int64_t id = range_->column_int64(0); id > cursor_) {
            cursor_ = id;
            ++n;
            keep_row(*range_, found_.rows, found_.untimed);
          } else {
            reason_ = kOutOfOrder;
            more = false;
          }
        }
        more = more && n == kRangeBatch;
      }
    } catch (const sqlite::SqliteError& e) {
      reason_ = e.reason();
    }
    range_->reset();
  }

  // A damaged stretch after cursor_: the last id whose seek failed, the first whose seek did not
  // (none: damaged to `upper`, the highest id there may be).
  struct Stretch {
    int64_t damaged = 0;
    std::optional<int64_t> walks;
    int64_t upper = 0;
  };
  // Slow: seeks past the damage until one walks again; a seek steps over absent ids. One id at
  // a time first, as a damaged leaf page hides a few hundred ids at most; then ever longer
  // steps, so that a damaged interior page or a corrupt max(id) costs tens of seeks, and a
  // binary search back to where the damage ends, so that no row past it is skipped.
  Stretch find_where_damage_ends() {
    Stretch stretch;
    stretch.upper = clamped_sum(
        std::max({cursor_, max_id_.value_or(0), static_cast<int64_t>(expected_count_.value_or(0))}),
        kProbeMargin);
    stretch.damaged = cursor_;
    int64_t step = 1;
    for (int64_t id = cursor_, tries = 0;
         id < stretch.upper && !stretch.walks && probes_ < kProbeBudget;) {
      id = stretch.upper - id > step ? id + step : stretch.upper;
      ++probes_;
      if (seek_from(id) != Seek::kDamaged) {
        stretch.walks = id;
      } else {
        stretch.damaged = id;
        if (++tries >= kLinearProbes && step <= INT64_MAX / 2) step *= 2;
      }
    }
    while (stretch.walks && *stretch.walks - stretch.damaged > 1 && probes_ < kProbeBudget) {
      ++probes_;
      const int64_t middle = stretch.damaged + (*stretch.walks - stretch.damaged) / 2;
      if (seek_from(middle) != Seek::kDamaged) {
        stretch.walks = middle;
      } else {
        stretch.damaged = middle;
      }
    }
    return stretch;
  }

  // Seeks the first row at or after `id`; on kRow, seek_ stays on it.
  enum class Seek { kRow, kEnd, kDamaged };
  Seek seek_from(int64_t id) {
    try {
      seek_->reset();
      seek_->bind(1, id);
      if (!seek_->step()) return Seek::kEnd;
      if (seek_->column_int64(0) >= id) return Seek::kRow;
      reason_ = kOutOfOrder;
      return Seek::kDamaged;
    } catch (const sqlite::SqliteError& e) {
      reason_ = e.reason();
      return Seek::kDamaged;
    }
  }

  // Where a problem line places a row: its time, or its id if it has none.
  std::string place(int64_t id) const {
    return !found_.rows.empty() && found_.rows.back().id == id
               ? time_of_day(found_.rows.back().timestamp)
               : fmt::format("id {}", id);
  }

  // `lost` ids unreadable between the row at `before` (none: the file's start) and `next`.
  void report_gap(const std::string& before, int64_t next, int64_t lost, int64_t walks) {
    reported_lost_ += static_cast<uint64_t>(lost);
    problem_(before.empty()
                 ? fmt::format("{}: messages before {} ({}, ids {}-{}) unreadable: {}", name_,
                               place(next), lost, cursor_ + 1, walks - 1, reason_)
                 : fmt::format("{}: messages between {} and {} ({}, ids {}-{}) unreadable: {}",
                               name_, before, place(next), lost, cursor_ + 1, walks - 1, reason_));
  }

  // Nothing readable after cursor_: damaged to the end (`damaged_to_the_end`), or simply the end
  // (also where the last row read has the largest id there can be).
  void report_end(const std::string& before, bool damaged_to_the_end) {
    const uint64_t found = found_.rows.size() + reported_lost_;
    if (damaged_to_the_end) {
      std::string how_many;
      if (max_id_ && *max_id_ > cursor_) {
        how_many = fmt::format("about {}", *max_id_ - cursor_);
      } else if (expected_count_ && *expected_count_ > found) {
        how_many = fmt::format("about {}", *expected_count_ - found);
      } else {
        how_many = "how many is unknown";
      }
      problem_(before.empty()
                   ? fmt::format("{}: no message readable ({}): {}", name_, how_many, reason_)
                   : fmt::format("{}: messages after {} ({}) unreadable: {}", name_, before,
                                 how_many, reason_));
    } else if (expected_count_ && *expected_count_ > found) {
      // The walk ended cleanly short of what metadata.yaml counted: the damage hid rows
      // without an error to show for it.
      problem_(fmt::format("{}: {} of the {} messages metadata.yaml counts are missing: {}", name_,
                           *expected_count_ - found, *expected_count_, reason_));
    }
  }

  sqlite::Database& db_;
  const std::string& name_;
  std::optional<uint64_t> expected_count_;
  std::string reason_;  // why the last read failed
  const std::function<void(std::string)>& problem_;
  SalvagedRows found_;
  std::optional<int64_t> max_id_;
  std::optional<sqlite::Statement> range_, seek_;
  int64_t cursor_ = 0;  // rosbag2's ids start at 1
  int64_t probes_ = 0;
  uint64_t reported_lost_ = 0;  // in the stretches reported so far
};

}  // namespace

void keep_row(const sqlite::Statement& row, std::vector<Row>& rows, uint64_t& untimed) {
  if (row.column_is_null(2)) {
    ++untimed;
    return;
  }
  rows.push_back({row.column_int64(2), row.column_int64(0), row.column_int64(1)});
}

SalvagedRows salvage_rows(sqlite::Database& db, const std::string& file_name,
                          std::optional<uint64_t> expected_count, std::string first_reason,
                          const std::function<void(std::string)>& problem) {
  return Salvage(db, file_name, expected_count, std::move(first_reason), problem).run();
}

}  // namespace mocap::bag
