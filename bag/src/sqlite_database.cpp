#include "sqlite_database.hpp"

#include <sqlite3.h>

#include <fmt/format.h>

#include <utility>

namespace mocap::bag::sqlite {

bool SqliteError::is_damage() const {
  switch (primary_code()) {
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
    case SQLITE_IOERR:
    case SQLITE_FORMAT:
    case SQLITE_CANTOPEN:
    case SQLITE_EMPTY:
    case SQLITE_SCHEMA:
    case SQLITE_PROTOCOL:
      return true;
    default:
      return false;
  }
}

bool SqliteError::is_wal_access() const {
  switch (code()) {
    case SQLITE_IOERR_SHMOPEN:
    case SQLITE_IOERR_SHMSIZE:
    case SQLITE_IOERR_SHMMAP:
    case SQLITE_IOERR_SHMLOCK:
      return true;
    default:
      break;
  }
  switch (primary_code()) {
    case SQLITE_CANTOPEN:
    case SQLITE_READONLY:  // _RECOVERY, _CANTINIT, _CANTLOCK: the -shm needs a writer
    case SQLITE_BUSY:      // _RECOVERY: someone else rebuilds the -shm
    case SQLITE_PROTOCOL:
      return true;
    default:
      return false;
  }
}

std::string SqliteError::reason() const {
  std::string text = what();
  auto first = text.find(": ");
  auto second = first == std::string::npos ? first : text.find(": ", first + 2);
  return second == std::string::npos ? text : text.substr(second + 2);
}

void throw_error(sqlite3* db, int code, std::string_view name, std::string_view what) {
  // sqlite3_errmsg describes the last failure on the connection, which may be older than
  // `code` when the failing call does not set it (sqlite3_open_v2 without a handle).
  std::string detail = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(code);
  if (detail.empty() || detail == "not an error") detail = sqlite3_errstr(code);
  throw SqliteError(code, fmt::format("{}: {}: {}", name, what, detail));
}

Database::Database(const std::string& path, int flags, std::string name) : name_(std::move(name)) {
  int code = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr);
  if (code != SQLITE_OK) {
    std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : sqlite3_errstr(code);
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw SqliteError(code, fmt::format("{}: cannot open: {}", name_, message));
  }
  sqlite3_extended_result_codes(db_, 1);
  // Another connection to the same file (a reader of a bag being recorded, `mocap_bag info`,
  // the sqlite3 shell) holds its locks for moments: wait them out instead of failing with
  // "database is locked", which would end a recording.
  sqlite3_busy_timeout(db_, 5000);
  // A bag may come from anywhere: its schema's views, triggers and defaults are not allowed to
  // call functions with side effects (SQLite's advice for files of unknown origin).
  sqlite3_db_config(db_, SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, nullptr);
}

Database::~Database() {
  if (db_ != nullptr) sqlite3_close_v2(db_);
}

Database::Database(Database&& other) noexcept
    : db_(std::exchange(other.db_, nullptr)), name_(std::move(other.name_)) {}

Database& Database::operator=(Database&& other) noexcept {
  if (this != &other) {
    if (db_ != nullptr) sqlite3_close_v2(db_);
    db_ = std::exchange(other.db_, nullptr);
    name_ = std::move(other.name_);
  }
  return *this;
}

void Database::fail(int code, std::string_view what) const { throw_error(db_, code, name_, what); }

void Database::exec(const std::string& sql, std::string_view what) {
  char* message = nullptr;
  int code = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message);
  if (code != SQLITE_OK) {
    std::string detail = message != nullptr ? message : sqlite3_errstr(code);
    sqlite3_free(message);
    throw SqliteError(code, fmt::format("{}: {}: {}", name_, what.empty() ? sql : what, detail));
  }
}

std::string Database::pragma_text(std::string_view pragma) {
  Statement statement(*this, fmt::format("PRAGMA {}", pragma));
  return statement.step() ? statement.column_text(0) : std::string();
}

int64_t Database::pragma_int(std::string_view pragma) {
  Statement statement(*this, fmt::format("PRAGMA {}", pragma));
  return statement.step() ? statement.column_int64(0) : 0;
}

bool Database::in_transaction() const { return db_ != nullptr && sqlite3_get_autocommit(db_) == 0; }

void Database::close() {
  if (db_ == nullptr) return;
  sqlite3* db = std::exchange(db_, nullptr);
  int code = sqlite3_close_v2(db);
  if (code != SQLITE_OK) {
    throw SqliteError(code, fmt::format("{}: close: {}", name_, sqlite3_errstr(code)));
  }
}

Statement::Statement(const Database& database, std::string_view sql)
    : db_(database.handle()), name_(database.name()) {
  int code = sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr);
  if (code != SQLITE_OK) {
    sqlite3_finalize(stmt_);
    stmt_ = nullptr;
    throw_error(db_, code, name_, fmt::format("prepare \"{}\"", sql));
  }
}

Statement::~Statement() { sqlite3_finalize(stmt_); }

Statement::Statement(Statement&& other) noexcept
    : db_(other.db_), name_(std::move(other.name_)), stmt_(std::exchange(other.stmt_, nullptr)) {}

Statement& Statement::operator=(Statement&& other) noexcept {
  if (this != &other) {
    sqlite3_finalize(stmt_);
    db_ = other.db_;
    name_ = std::move(other.name_);
    stmt_ = std::exchange(other.stmt_, nullptr);
  }
  return *this;
}

Statement& Statement::bind(int index, int64_t value) {
  int code = sqlite3_bind_int64(stmt_, index, value);
  if (code != SQLITE_OK) throw_error(db_, code, name_, "bind");
  return *this;
}

Statement& Statement::bind_blob(int index, std::span<const uint8_t> value) {
  // A null pointer would bind NULL, which NOT NULL columns refuse: an empty payload is an
  // empty blob.
  static constexpr uint8_t kEmpty = 0;
  const uint8_t* data = value.empty() ? &kEmpty : value.data();
  int code = sqlite3_bind_blob64(stmt_, index, data, value.size(), SQLITE_STATIC);
  if (code != SQLITE_OK) throw_error(db_, code, name_, "bind");
  return *this;
}

Statement& Statement::bind_text(int index, std::string_view value) {
  int code = sqlite3_bind_text64(stmt_, index, value.empty() ? "" : value.data(), value.size(),
                                 SQLITE_STATIC, SQLITE_UTF8);
  if (code != SQLITE_OK) throw_error(db_, code, name_, "bind");
  return *this;
}

bool Statement::step() {
  int code = sqlite3_step(stmt_);
  if (code == SQLITE_ROW) return true;
  if (code == SQLITE_DONE) return false;
  std::string sql = sqlite3_sql(stmt_) != nullptr ? sqlite3_sql(stmt_) : "";
  std::string what = sql.substr(0, sql.find_first_of(" (")) == "INSERT" ? "insert" : "query";
  throw_error(db_, code, name_, what);
}

void Statement::reset() { sqlite3_reset(stmt_); }

int64_t Statement::column_int64(int column) const { return sqlite3_column_int64(stmt_, column); }

std::span<const uint8_t> Statement::column_blob(int column) const {
  // Blob first, then its size: the order SQLite documents as safe.
  const auto* data = static_cast<const uint8_t*>(sqlite3_column_blob(stmt_, column));
  auto size = static_cast<size_t>(sqlite3_column_bytes(stmt_, column));
  return data != nullptr ? std::span<const uint8_t>(data, size) : std::span<const uint8_t>();
}

std::string Statement::column_text(int column) const {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, column));
  return text != nullptr
             ? std::string(text, static_cast<size_t>(sqlite3_column_bytes(stmt_, column)))
             : std::string();
}

bool Statement::column_is_null(int column) const {
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

}  // namespace mocap::bag::sqlite
