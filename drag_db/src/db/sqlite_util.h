// Small RAII helpers over the SQLite C API: a prepared statement, a transaction and the
// translation of SQLite result codes into draglab::Error. Private to drag_db.
//
// Every value reaches SQL through a bound parameter (Statement::bind); SQL text is never built
// from user input.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <string>

#include "draglab/error.h"

namespace draglab {
namespace db {

/// Marker our immutability triggers put in their messages (schema.cc); SQL errors that carry it
/// are reported as ErrorCode::kImmutable.
constexpr const char* kImmutableMarker = "create a new version instead";

/// The file name of the main database of `db` ("" for an in-memory database).
std::string database_path(sqlite3* db);

/// Throws the draglab::Error matching SQLite result code `rc` on `db`: kNotADatabase for
/// SQLITE_NOTADB / SQLITE_CORRUPT (naming the file), kImmutable for our trigger aborts,
/// kDatabase otherwise. `context` says what was being done ("storing law x@2").
[[noreturn]] void throw_sqlite_error(sqlite3* db, int rc, const std::string& context);

/// Runs one or more SQL statements without parameters (schema scripts, pragmas).
void exec(sqlite3* db, const std::string& sql, const std::string& context);

/// A prepared statement, finalized on destruction. Columns and parameters are 0-based for
/// columns (as sqlite3_column_*) and 1-based for parameters (as sqlite3_bind_*).
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int index, const std::string& value);
  Statement& bind(int index, const char* value) { return bind(index, std::string(value)); }
  Statement& bind(int index, double value);
  Statement& bind(int index, int value) { return bind(index, static_cast<std::int64_t>(value)); }
  Statement& bind(int index, std::int64_t value);
  Statement& bind_null(int index);

  /// Advances to the next row: true if a row is available, false when done. Throws on error.
  bool step();
  /// Steps to completion (for INSERT/UPDATE/DELETE).
  void run();
  /// Makes the statement reusable with new bindings.
  void reset();

  bool is_null(int column) const;
  std::string text(int column) const;
  double real(int column) const;
  std::int64_t integer(int column) const;

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string sql_;
};

/// A transaction scope. BEGIN IMMEDIATE (write) or BEGIN DEFERRED (read snapshot) on
/// construction, ROLLBACK on destruction unless commit() was called. If the connection is
/// already inside a transaction the scope joins it and does nothing itself, so that public
/// methods can call each other and still form one transaction.
class Transaction {
 public:
  enum class Kind { kRead, kWrite };
  Transaction(sqlite3* db, Kind kind);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  sqlite3* db_;
  bool owner_ = false;
  bool done_ = false;
};

/// Current time as ISO 8601 UTC, second resolution ("2024-05-01T12:34:56Z").
std::string utc_now_iso8601();

}  // namespace db
}  // namespace draglab
