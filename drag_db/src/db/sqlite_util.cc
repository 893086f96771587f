// RAII helpers over the SQLite C API (sqlite_util.h).
#include "db/sqlite_util.h"

#include <cerrno>
#include <cstring>
#include <ctime>

namespace draglab {
namespace db {

std::string database_path(sqlite3* db) {
  const char* name = db ? sqlite3_db_filename(db, "main") : nullptr;
  return name ? std::string(name) : std::string();
}

void throw_sqlite_error(sqlite3* db, int rc, const std::string& context) {
  const std::string message = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  std::string path = database_path(db);
  if (path.empty()) path = ":memory:";
  const int primary = rc & 0xff;
  if (primary == SQLITE_NOTADB || primary == SQLITE_CORRUPT) {
    throw Error(ErrorCode::kNotADatabase,
                "'" + path + "' is not a draglab database: " +
                    (primary == SQLITE_NOTADB ? "not an SQLite file, or encrypted"
                                              : "the SQLite file is corrupt") +
                    " (SQLite: " + message + ")");
  }
  const std::size_t marker = message.find(kImmutableMarker);
  if (marker != std::string::npos) {
    // Our guard triggers raise "... near 'draglab: law x@1 is ...; create a new version
    // instead'" (schema.cc): keep our sentence, drop SQLite's wrapping.
    const std::size_t start = message.find("draglab: ");
    const std::size_t end = marker + std::string(kImmutableMarker).size();
    throw Error(ErrorCode::kImmutable, start != std::string::npos && start < marker
                                           ? message.substr(start, end - start)
                                           : message);
  }
  if (primary == SQLITE_BUSY || primary == SQLITE_LOCKED) {
    throw Error(ErrorCode::kDatabase, "database '" + path + "' is locked by another writer (" +
                                          message + ") while " + context +
                                          "; retry later or raise the busy timeout");
  }
  if (primary == SQLITE_READONLY) {
    throw Error(ErrorCode::kDatabase,
                "database '" + path + "' is read-only (" + message + ") while " + context);
  }
  if (primary == SQLITE_IOERR || primary == SQLITE_FULL) {
    // SQLite says only "disk I/O error" or "database or disk is full"; the system error, where
    // SQLite kept one, says why. A write that stops short keeps none (errno 0).
    const int os_error = db ? sqlite3_system_errno(db) : 0;
    const int extended = db ? sqlite3_extended_errcode(db) : rc;
    const bool write_failed = primary == SQLITE_FULL || os_error == ENOSPC || os_error == EFBIG ||
                              os_error == EDQUOT || extended == SQLITE_IOERR_WRITE ||
                              extended == SQLITE_IOERR_FSYNC || extended == SQLITE_IOERR_TRUNCATE ||
                              extended == SQLITE_IOERR_SHMSIZE;
    throw Error(ErrorCode::kDatabase,
                "cannot write database '" + path + "' while " + context + ": " + message +
                    (os_error != 0 ? " (" + std::string(std::strerror(os_error)) + ")" : "") +
                    (write_failed ? "; a write failed, most often because the disk, a quota "
                                    "or a file size limit is full: free space and run again (the "
                                    "unfinished change was rolled back: nothing of it is stored)"
                                  : ""));
  }
  throw Error(ErrorCode::kDatabase,
              "SQLite error while " + context + " in '" + path + "': " + message);
}

void exec(sqlite3* db, const std::string& sql, const std::string& context) {
  char* raw_error = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &raw_error);
  if (raw_error) sqlite3_free(raw_error);  // sqlite3_errmsg(db) carries the same text
  if (rc != SQLITE_OK) throw_sqlite_error(db, rc, context);
}

Statement::Statement(sqlite3* db, const std::string& sql) : db_(db), sql_(sql) {
  const int rc =
      sqlite3_prepare_v2(db_, sql.c_str(), static_cast<int>(sql.size()) + 1, &stmt_, nullptr);
  if (rc != SQLITE_OK) {
    sqlite3_finalize(stmt_);
    stmt_ = nullptr;
    throw_sqlite_error(db_, rc, "preparing '" + sql_ + "'");
  }
}

Statement::~Statement() { sqlite3_finalize(stmt_); }

Statement& Statement::bind(int index, const std::string& value) {
  const int rc = sqlite3_bind_text(stmt_, index, value.data(), static_cast<int>(value.size()),
                                   SQLITE_TRANSIENT);
  if (rc != SQLITE_OK) throw_sqlite_error(db_, rc, "binding a parameter of '" + sql_ + "'");
  return *this;
}

Statement& Statement::bind(int index, double value) {
  const int rc = sqlite3_bind_double(stmt_, index, value);
  if (rc != SQLITE_OK) throw_sqlite_error(db_, rc, "binding a parameter of '" + sql_ + "'");
  return *this;
}

Statement& Statement::bind(int index, std::int64_t value) {
  const int rc = sqlite3_bind_int64(stmt_, index, static_cast<sqlite3_int64>(value));
  if (rc != SQLITE_OK) throw_sqlite_error(db_, rc, "binding a parameter of '" + sql_ + "'");
  return *this;
}

Statement& Statement::bind_null(int index) {
  const int rc = sqlite3_bind_null(stmt_, index);
  if (rc != SQLITE_OK) throw_sqlite_error(db_, rc, "binding a parameter of '" + sql_ + "'");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  // sqlite3_step's own code is the extended one with prepare_v2; keep the message before reset.
  throw_sqlite_error(db_, rc, "running '" + sql_ + "'");
}

void Statement::run() {
  while (step()) {
  }
}

void Statement::reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

bool Statement::is_null(int column) const {
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

std::string Statement::text(int column) const {
  const unsigned char* p = sqlite3_column_text(stmt_, column);
  if (!p) return std::string();
  return std::string(reinterpret_cast<const char*>(p),
                     static_cast<std::size_t>(sqlite3_column_bytes(stmt_, column)));
}

double Statement::real(int column) const { return sqlite3_column_double(stmt_, column); }

std::int64_t Statement::integer(int column) const {
  return static_cast<std::int64_t>(sqlite3_column_int64(stmt_, column));
}

Transaction::Transaction(sqlite3* db, Kind kind) : db_(db) {
  if (sqlite3_get_autocommit(db_) == 0) return;  // already inside a transaction: join it
  // IMMEDIATE takes the write lock up front, so a writer waits (busy_timeout) at BEGIN instead of
  // failing half-way with SQLITE_BUSY on its first write; DEFERRED gives readers a snapshot.
  exec(db_, kind == Kind::kWrite ? "BEGIN IMMEDIATE" : "BEGIN DEFERRED",
       kind == Kind::kWrite ? "starting a write transaction" : "starting a read transaction");
  owner_ = true;
}

Transaction::~Transaction() {
  if (owner_ && !done_ && sqlite3_get_autocommit(db_) == 0) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
}

void Transaction::commit() {
  if (!owner_ || done_) return;
  exec(db_, "COMMIT", "committing a transaction");
  done_ = true;
}

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buf;
}

}  // namespace db
}  // namespace draglab
