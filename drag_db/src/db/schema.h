// The database schema as an ordered list of forward migrations. Private to drag_db.
//
// Migration N takes a schema of version N-1 to version N. A released migration never changes:
// a new table, column or trigger is a new migration appended to the list in schema.cc (the
// campaign measurements, datasets, consumer results and baselines of later modules arrive this
// way). docs/database.md describes every version.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <string>
#include <vector>

namespace draglab {
namespace db {

/// PRAGMA application_id of draglab files ("DRLB"), so that `file` and we can tell them apart
/// from other SQLite databases.
constexpr std::int32_t kApplicationId = 0x44524C42;

struct Migration {
  int version;              ///< Schema version after this migration (1, 2, ...).
  const char* description;  ///< One line, stored in schema_version.
  std::string sql;          ///< Statements run inside the migration transaction.
};

/// All migrations, ordered by version (1, 2, ..., latest without gaps).
const std::vector<Migration>& migrations();
/// The schema version this build writes (the last migration's version).
int latest_schema_version();

/// The schema version recorded in `db`: MAX(version) of schema_version, or 0 if there is no
/// schema_version table (a new, empty file).
int read_schema_version(sqlite3* db);

/// Applies migrations (from, to] in order, recording each in schema_version with its UTC time
/// and `code_version`. Must run inside the caller's write transaction. Returns the versions
/// applied.
std::vector<int> apply_migrations(sqlite3* db, int from, int to, const std::string& code_version);

/// Names of the triggers a database of `schema_version` must have (used by Database::check()).
std::vector<std::string> expected_triggers(int schema_version);

}  // namespace db
}  // namespace draglab
