// A thin RAII layer over sqlite3 for the bag storage: every failure becomes a SqliteError
// (a BagError) whose message names the database file, what was being done and SQLite's own
// words, and which keeps SQLite's result code so that callers can tell a full disk or a
// damaged file from a programming error.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <mocap/bag/bag_error.hpp>

struct sqlite3;
struct sqlite3_stmt;

namespace mocap::bag::sqlite {

class SqliteError : public BagError {
 public:
  SqliteError(int code, const std::string& message) : BagError(message), code_(code) {}
  int code() const { return code_; }                 // extended result code
  int primary_code() const { return code_ & 0xff; }  // SQLITE_FULL, SQLITE_CORRUPT...
  // The file cannot be read as it is (as opposed to a misuse or a full disk): the reader
  // salvages what it can instead of failing.
  bool is_damage() const;
  // Opening failed because of the write-ahead log or its shared-memory index (a killed
  // writer's leftovers in a directory we may not write to).
  bool is_wal_access() const;
  // The part of the message after "<file>: <what>: ", for problem lines that name the file
  // themselves.
  std::string reason() const;

 private:
  int code_;
};

// Throws SqliteError "<name>: <what>: <sqlite3_errmsg>".
[[noreturn]] void throw_error(sqlite3* db, int code, std::string_view name, std::string_view what);

class Database {
 public:
  Database() = default;
  // `flags`: SQLITE_OPEN_*; `name` is what errors call the file (SQLite opens lazily, so a
  // file that is not a database fails only at the first statement).
  Database(const std::string& path, int flags, std::string name);
  ~Database();
  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  bool is_open() const { return db_ != nullptr; }
  sqlite3* handle() const { return db_; }
  const std::string& name() const { return name_; }

  // Runs one or more statements that return nothing of interest. `what` says in errors what
  // was being done ("begin", "create the schema"); by default the SQL itself.
  void exec(const std::string& sql, std::string_view what = {});
  // The first column of the first row of `PRAGMA <pragma>` (e.g. "journal_mode=WAL").
  std::string pragma_text(std::string_view pragma);
  int64_t pragma_int(std::string_view pragma);
  // True while a transaction is open (BEGIN without COMMIT/ROLLBACK yet).
  bool in_transaction() const;
  // Closes now; errors are thrown (the handle is released anyway).
  void close();

  [[noreturn]] void fail(int code, std::string_view what) const;

 private:
  sqlite3* db_ = nullptr;
  std::string name_;
};

class Statement {
 public:
  Statement() = default;
  Statement(const Database& database, std::string_view sql);
  ~Statement();
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&& other) noexcept;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  bool is_prepared() const { return stmt_ != nullptr; }

  // Parameters count from 1, as in SQLite. The blob and text are not copied: they must stay
  // valid until the statement is stepped to its end or reset.
  Statement& bind(int index, int64_t value);
  Statement& bind_blob(int index, std::span<const uint8_t> value);
  Statement& bind_text(int index, std::string_view value);

  // True: a row is ready; false: done. Throws SqliteError.
  bool step();
  // Ready for stepping again with the same bindings. Never throws: the error of a failed step
  // was thrown by step() already.
  void reset();

  int64_t column_int64(int column) const;
  std::span<const uint8_t> column_blob(int column) const;
  std::string column_text(int column) const;
  bool column_is_null(int column) const;

 private:
  // The handle and the name rather than the Database, so that a Database may be moved.
  sqlite3* db_ = nullptr;
  std::string name_;
  sqlite3_stmt* stmt_ = nullptr;
};

}  // namespace mocap::bag::sqlite
