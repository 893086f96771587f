// The SQLite drag-law database at the file and SQL level: immutability enforced by triggers
// against the real sqlite3 command-line shell (UPDATE, DELETE, and REPLACE conflict resolution,
// which deletes rows without firing DELETE triggers), forward migration from schema 1, a reader
// during a writer's open transaction (WAL), clear errors for bad paths and for files that are
// not draglab databases, and read-only opens of an installation the reader cannot write.
//
// Set-up: fresh database files in a temporary directory; records built from the registered form
// "bvk2007" under test names. The shell is the program named by DRAGLAB_SQLITE3_SHELL (the
// Debian `sqlite3` package), run on the database file exactly as a user would run it.
// Permissions: root ignores file modes, so checks that need them run in a child process that has
// dropped to uid/gid 65534 (nobody) when the tests run as root. "Nothing written" is checked as
// the database file's size, modification time (nanoseconds) and bytes being unchanged.
#include <grp.h>
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "draglab/drag_db/database.h"
#include "draglab/drag_db/law.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

#ifndef DRAGLAB_SQLITE3_SHELL
#define DRAGLAB_SQLITE3_SHELL "sqlite3"
#endif

namespace draglab {
namespace {

namespace fs = std::filesystem;

using TempDir = test::TempDir;

Error error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  return Error(ErrorCode::kOk, "");
}

LawRecord bvk_record(const std::string& name, double scale_a = 1.0) {
  LawRecord r = literature_record(find_law_form("bvk2007"));
  r.name = name;
  r.provenance.kind = "manual";
  r.parameters[0].value *= scale_a;
  return r;
}

DatabaseOptions unseeded() {
  DatabaseOptions o;
  o.seed_literature = false;
  return o;
}

struct ShellResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// Runs `sql` through the sqlite3 command-line shell on `db_path` (-bail: stop at the first
// error and exit non-zero, as a script would).
ShellResult run_shell(const TempDir& dir, const std::string& db_path, const std::string& sql) {
  const std::string script = dir.file("script.sql");
  {
    std::ofstream out(script);
    out << sql << "\n";
  }
  const std::string command =
      std::string(DRAGLAB_SQLITE3_SHELL) + " -bail '" + db_path + "' < '" + script + "' 2>&1";
  ShellResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::size_t directory_entries_count(const fs::path& dir) {
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

bool shell_available() {
  const std::string command = std::string(DRAGLAB_SQLITE3_SHELL) + " -version > /dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

// ---- immutability from the sqlite3 shell ---------------------------------------------------

class DatabaseShellImmutability : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(shell_available()) << "the sqlite3 command-line shell (" << DRAGLAB_SQLITE3_SHELL
                                   << ") is required for this test: install the sqlite3 package";
    path_ = dir_.file("shell.db");
    Database db(path_, unseeded());
    LawRecord with_covariance = bvk_record("frozen");
    const std::size_t n = with_covariance.parameters.size();
    with_covariance.covariance.assign(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) with_covariance.covariance[i * n + i] = 0.01;
    published_ = db.add_published(with_covariance);
    draft_ = db.add_draft(bvk_record("frozen", 1.3));
  }

  // Expects the shell to refuse `sql` with a message that names the law and says what to do.
  void expect_refused(const std::string& sql, const std::string& law_reference) {
    const ShellResult r = run_shell(dir_, path_, sql);
    EXPECT_NE(r.exit_code, 0) << sql << "\n" << r.output;
    EXPECT_NE(r.output.find(law_reference), std::string::npos) << sql << "\n" << r.output;
    EXPECT_NE(r.output.find("create a new version instead"), std::string::npos) << sql << "\n"
                                                                                << r.output;
  }

  // Everything the API sees of frozen@1 is still what was published.
  void expect_published_unchanged() {
    Database db(path_);
    const LawRecord now = db.resolve("frozen@1");
    EXPECT_EQ(now.status, published_.status);
    EXPECT_EQ(now.notes, published_.notes);
    EXPECT_EQ(now.covariance, published_.covariance);
    ASSERT_EQ(now.parameters.size(), published_.parameters.size());
    for (std::size_t i = 0; i < now.parameters.size(); ++i) {
      EXPECT_EQ(now.parameters[i].value, published_.parameters[i].value);
    }
    EXPECT_EQ(now.content_hash, content_hash_of(now));
    EXPECT_TRUE(db.check().ok) << db.check().FullReport();
  }

  TempDir dir_;
  std::string path_;
  LawRecord published_;
  LawRecord draft_;
};

constexpr const char* kFrozenId = "(SELECT id FROM laws WHERE name = 'frozen' AND version = 1)";

TEST_F(DatabaseShellImmutability, UpdateAndDeleteOfAPublishedVersionFail) {
  expect_refused("UPDATE laws SET notes = 'edited' WHERE name = 'frozen' AND version = 1;",
                 "frozen@1");
  expect_refused("UPDATE laws SET phi_max = 0.7 WHERE name = 'frozen';", "frozen@1");
  expect_refused("UPDATE laws SET status = 'draft' WHERE name = 'frozen' AND version = 1;",
                 "frozen@1");
  expect_refused("DELETE FROM laws WHERE name = 'frozen' AND version = 1;", "frozen@1");
  // Retraction may change only the status, time and reason.
  expect_refused(
      "UPDATE laws SET status = 'retracted', retraction_reason = 'x', notes = 'sneaky' "
      "WHERE name = 'frozen' AND version = 1;",
      "frozen@1");
  expect_published_unchanged();
}

TEST_F(DatabaseShellImmutability, ParameterAndCovarianceRowsOfAPublishedVersionAreFrozen) {
  const std::string id = kFrozenId;
  expect_refused("UPDATE law_parameters SET value = 99 WHERE law_id = " + id + ";", "frozen@1");
  expect_refused("DELETE FROM law_parameters WHERE law_id = " + id + ";", "frozen@1");
  expect_refused("INSERT INTO law_parameters (law_id, position, name, value, unit) VALUES (" + id +
                     ", 9, 'extra', 1.0, '1');",
                 "frozen@1");
  expect_refused("UPDATE law_covariance SET value = 5 WHERE law_id = " + id + ";", "frozen@1");
  expect_refused("DELETE FROM law_covariance WHERE law_id = " + id + ";", "frozen@1");
  // Moving a parameter row from a draft to the published version is a change of the latter.
  expect_refused("UPDATE law_parameters SET law_id = " + id +
                     ", position = 9 WHERE law_id = (SELECT id FROM laws WHERE name = 'frozen' "
                     "AND version = 2) AND position = 0;",
                 "frozen@1");
  expect_published_unchanged();
}

TEST_F(DatabaseShellImmutability, InsertingAPublishedRowDirectlyFails) {
  const ShellResult r = run_shell(
      dir_, path_,
      "INSERT INTO laws (name, version, form, force_kind, normalisation, reynolds, tfm_model, "
      "phi_min, phi_max, re_min, re_max, provenance_kind, content_hash, status, created_at) "
      "SELECT 'forged', 1, form, force_kind, normalisation, reynolds, tfm_model, phi_min, "
      "phi_max, re_min, re_max, provenance_kind, content_hash, 'published', created_at "
      "FROM laws WHERE name = 'frozen' AND version = 1;");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("inserted as a draft"), std::string::npos) << r.output;
  Database db(path_);
  EXPECT_TRUE(db.list("forged").empty());
}

TEST_F(DatabaseShellImmutability, DraftsStayEditableAndRetractionIsAllowedOnce) {
  // The guards are specific: a draft may still be edited from the shell.
  ShellResult r = run_shell(dir_, path_,
                            "UPDATE laws SET notes = 'edited in the shell' "
                            "WHERE name = 'frozen' AND version = 2;");
  EXPECT_EQ(r.exit_code, 0) << r.output;

  // Published -> retracted is the one permitted change, and it needs a reason.
  r = run_shell(dir_, path_,
                "UPDATE laws SET status = 'retracted' WHERE name = 'frozen' AND version = 1;");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("needs a reason"), std::string::npos) << r.output;
  r = run_shell(dir_, path_,
                "UPDATE laws SET status = 'retracted', retracted_at = '2024-01-02T03:04:05Z', "
                "retraction_reason = 'retracted from the shell' "
                "WHERE name = 'frozen' AND version = 1;");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  {
    Database db(path_);
    EXPECT_EQ(db.resolve("frozen@2").notes, "edited in the shell");
    std::string warning;
    db.load("frozen@1", RangePolicy::kError, &warning);
    EXPECT_NE(warning.find("retracted from the shell"), std::string::npos) << warning;
    const std::vector<LawEvent> events = db.history("frozen", 1);
    ASSERT_FALSE(events.empty());
    EXPECT_EQ(events.back().event, "retracted");
    EXPECT_EQ(events.back().detail, "retracted from the shell");
  }
  // Once retracted, nothing goes back and nothing is deleted.
  expect_refused("UPDATE laws SET status = 'published' WHERE name = 'frozen' AND version = 1;",
                 "frozen@1");
  expect_refused("DELETE FROM laws WHERE name = 'frozen' AND version = 1;", "frozen@1");
  // The history cannot be rewritten to hide it either.
  r = run_shell(dir_, path_, "DELETE FROM law_events WHERE name = 'frozen';");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("append-only"), std::string::npos) << r.output;
}

// REPLACE conflict resolution deletes the row in the way without firing DELETE triggers (unless
// PRAGMA recursive_triggers is on, which the shell does not do). Schema 3 refuses it wherever the
// row in the way is a published or retracted version or a history event.

// Every column of `laws`, and the same list as a SELECT that copies a row as a draft.
constexpr const char* kAllLawColumns =
    "id, name, version, form, force_kind, normalisation, reynolds, tfm_model, phi_min, phi_max, "
    "re_min, re_max, provenance_kind, citation, dataset_id, data_hash, fitter_settings, "
    "code_version, content_hash, status, created_at, published_at, retracted_at, "
    "retraction_reason, notes";
constexpr const char* kAllLawColumnsAsDraft =
    "id, name, version, form, force_kind, normalisation, reynolds, tfm_model, phi_min, phi_max, "
    "re_min, re_max, provenance_kind, citation, dataset_id, data_hash, fitter_settings, "
    "code_version, content_hash, 'draft', created_at, NULL, NULL, '', notes";

TEST_F(DatabaseShellImmutability, ReplacingAPublishedRowByADraftCopyFails) {
  // Swap frozen@1 for a draft copy with the same id, edit a parameter, publish it again.
  const std::string id = kFrozenId;
  expect_refused(std::string("INSERT OR REPLACE INTO laws (") + kAllLawColumns + ") SELECT " +
                     kAllLawColumnsAsDraft +
                     " FROM laws WHERE name = 'frozen' AND version = 1;\n"
                     "UPDATE law_parameters SET value = 20 WHERE law_id = " +
                     id +
                     " AND name = 'a';\n"
                     "UPDATE laws SET status = 'published' WHERE name = 'frozen' AND version = 1;",
                 "frozen@1");
  // The same through the UNIQUE (name, version) key, with a new id.
  const std::string columns_without_id = std::string(kAllLawColumns).substr(4);
  const std::string draft_copy_without_id = std::string(kAllLawColumnsAsDraft).substr(4);
  expect_refused("REPLACE INTO laws (" + columns_without_id + ") SELECT " + draft_copy_without_id +
                     " FROM laws WHERE name = 'frozen' AND version = 1;",
                 "frozen@1");
  // A version given as text is converted by the column affinity and collides all the same.
  expect_refused("INSERT OR REPLACE INTO laws (" + columns_without_id + ") SELECT " +
                     draft_copy_without_id.substr(0, draft_copy_without_id.find("version")) +
                     "'1'" +
                     draft_copy_without_id.substr(draft_copy_without_id.find("version") + 7) +
                     " FROM laws WHERE name = 'frozen' AND version = 1;",
                 "frozen@1");
  expect_published_unchanged();
}

TEST_F(DatabaseShellImmutability, UpdateOrReplaceCannotDeleteAPublishedVersion) {
  // Moving the draft frozen@2 onto the key of frozen@1 would delete frozen@1.
  const std::string draft = "WHERE name = 'frozen' AND version = 2;";
  expect_refused("UPDATE OR REPLACE laws SET version = 1 " + draft, "frozen@1");
  expect_refused(std::string("UPDATE OR REPLACE laws SET id = ") + kFrozenId + " " + draft,
                 "frozen@1");
  // rowid is the same column under another name (an UPDATE OF id trigger would miss it).
  expect_refused(std::string("UPDATE OR REPLACE laws SET rowid = ") + kFrozenId + " " + draft,
                 "frozen@1");
  expect_published_unchanged();
  Database db(path_);
  EXPECT_EQ(db.resolve("frozen@2").status, LawStatus::kDraft);
}

TEST_F(DatabaseShellImmutability, ReplaceOnChildRowsOfAPublishedVersionFails) {
  const std::string id = kFrozenId;
  const std::string draft_id = "(SELECT id FROM laws WHERE name = 'frozen' AND version = 2)";
  expect_refused(
      "INSERT OR REPLACE INTO law_parameters (law_id, position, name, value, unit) "
      "SELECT law_id, position, name, 20, unit FROM law_parameters WHERE law_id = " +
          id + " AND position = 0;",
      "frozen@1");
  expect_refused("UPDATE OR REPLACE law_parameters SET law_id = " + id +
                     " WHERE law_id = " + draft_id + " AND position = 0;",
                 "frozen@1");
  expect_refused("REPLACE INTO law_covariance (law_id, row_index, col_index, value) VALUES (" + id +
                     ", 0, 0, 99);",
                 "frozen@1");
  expect_refused(
      "REPLACE INTO law_extra_inputs (law_id, position, name, description, min_value, "
      "max_value) VALUES (" +
          id + ", 0, 'y', '', 0, 1);",
      "frozen@1");
  expect_published_unchanged();
}

TEST_F(DatabaseShellImmutability, ReplaceCannotRewriteTheHistory) {
  std::vector<LawEvent> before;
  {
    Database db(path_);
    before = db.history("frozen");
  }
  ASSERT_FALSE(before.empty());
  const ShellResult r = run_shell(
      dir_, path_,
      "INSERT OR REPLACE INTO law_events (id, name, version, event, at, content_hash, detail) "
      "VALUES ((SELECT min(id) FROM law_events WHERE name = 'frozen'), 'frozen', 1, 'created', "
      "'2000-01-01T00:00:00Z', 'forged', 'forged');");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("append-only"), std::string::npos) << r.output;
  Database db(path_);
  const std::vector<LawEvent> after = db.history("frozen");
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t i = 0; i < after.size(); ++i) {
    EXPECT_EQ(after[i].at, before[i].at);
    EXPECT_EQ(after[i].content_hash, before[i].content_hash);
    EXPECT_EQ(after[i].detail, before[i].detail);
  }
}

TEST_F(DatabaseShellImmutability, ReplaceAmongDraftsStillWorks) {
  // The schema-3 guards look only for published and retracted rows in the way.
  ShellResult r = run_shell(dir_, path_,
                            std::string("INSERT OR REPLACE INTO laws (") + kAllLawColumns +
                                ") SELECT " + kAllLawColumnsAsDraft +
                                " FROM laws WHERE name = 'frozen' AND version = 2;\n"
                                "UPDATE OR REPLACE laws SET notes = 'replaced in the shell' "
                                "WHERE name = 'frozen' AND version = 2;");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  {
    Database db(path_);
    EXPECT_EQ(db.resolve("frozen@2").notes, "replaced in the shell");
  }
  expect_published_unchanged();
}

// ---- migration from an older schema --------------------------------------------------------

TEST(DatabaseMigration, SchemaOneFileIsMigratedAndItsLawsSurvive) {
  TempDir dir;
  const std::string path = dir.file("old.db");
  LawRecord stored;
  {
    // What a schema-1 draglab wrote: create the file without migrating, migrate to 1 only.
    DatabaseOptions raw;
    raw.migrate = false;
    Database db(path, raw);
    EXPECT_EQ(db.schema_version(), 0);
    EXPECT_EQ(db.migrate(1), std::vector<int>{1});
    EXPECT_EQ(db.schema_version(), 1);
    stored = db.add_published(bvk_record("old_law"));
    db.add_published(bvk_record("old_law", 1.2));
    db.retract("old_law", 2, "typo in a");
    // Schema 1 has no history table.
    EXPECT_EQ(error_of([&] { db.history("old_law"); }).code(), ErrorCode::kDatabase);
  }
  {
    // A read-only open of the old file reads it without migrating.
    DatabaseOptions ro;
    ro.read_only = true;
    Database db(path, ro);
    EXPECT_EQ(db.schema_version(), 1);
    EXPECT_EQ(db.resolve("old_law").version, 1);
    // What needs a later schema says how to get it.
    const Error e = error_of([&] { db.history("old_law"); });
    EXPECT_EQ(e.code(), ErrorCode::kDatabase);
    EXPECT_NE(std::string(e.what()).find("draglab db migrate"), std::string::npos) << e.what();
  }
  Database db(path);  // the current code, default options: migrates
  EXPECT_EQ(db.schema_version(), Database::current_schema_version());

  const LawRecord now = db.resolve("old_law@1");
  EXPECT_EQ(now.content_hash, stored.content_hash);
  EXPECT_EQ(now.created_at, stored.created_at);
  EXPECT_EQ(now.status, LawStatus::kPublished);
  EXPECT_EQ(db.resolve("old_law@2").retraction_reason, "typo in a");
  EXPECT_NO_THROW(db.load("old_law"));
  // An existing file is not a new one: the literature library is not seeded into it.
  EXPECT_EQ(db.list().size(), 2u);
  EXPECT_TRUE(db.check().ok) << db.check().FullReport();

  // Migration 2 back-filled the history of the laws that already existed.
  std::vector<std::string> kinds;
  for (const LawEvent& e : db.history("old_law")) {
    kinds.push_back(e.event + "@" + std::to_string(e.version));
  }
  EXPECT_EQ(kinds, (std::vector<std::string>{"created@1", "created@2", "published@1", "published@2",
                                             "retracted@2"}));

  // Every applied migration is recorded with its time.
  sqlite3_stmt* stmt = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db.handle(),
                               "SELECT version, applied_at FROM schema_version ORDER BY version",
                               -1, &stmt, nullptr),
            SQLITE_OK);
  std::vector<int> versions;
  while (sqlite3_step(stmt) == SQLITE_ROW) {
    versions.push_back(sqlite3_column_int(stmt, 0));
    const std::string at = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 1));
    EXPECT_EQ(at.size(), 20u) << at;  // YYYY-MM-DDTHH:MM:SSZ
  }
  sqlite3_finalize(stmt);
  std::vector<int> expected;
  for (int v = 1; v <= Database::current_schema_version(); ++v) expected.push_back(v);
  EXPECT_EQ(versions, expected);

  // Forward only.
  EXPECT_EQ(error_of([&] { db.migrate(1); }).code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(db.migrate().empty());
}

TEST(DatabaseMigration, NewerSchemaIsRefusedWithBothNumbers) {
  TempDir dir;
  const std::string path = dir.file("future.db");
  {
    Database db(path, unseeded());
    char* err = nullptr;
    ASSERT_EQ(sqlite3_exec(db.handle(),
                           "INSERT INTO schema_version VALUES (99, 'from the future', "
                           "'2099-01-01T00:00:00Z', 'draglab 9.0')",
                           nullptr, nullptr, &err),
              SQLITE_OK);
  }
  for (bool read_only : {false, true}) {
    DatabaseOptions o;
    o.read_only = read_only;
    const Error e = error_of([&] { Database db(path, o); });
    EXPECT_EQ(e.code(), ErrorCode::kSchemaTooNew);
    const std::string message = e.what();
    EXPECT_NE(message.find("99"), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(Database::current_schema_version())), std::string::npos)
        << message;
    EXPECT_NE(message.find("upgrade draglab"), std::string::npos) << message;
  }
}

// ---- a reader while a writer holds an open transaction ------------------------------------

TEST(DatabaseConcurrency, ReaderWorksDuringAWritersOpenTransaction) {
  TempDir dir;
  const std::string path = dir.file("wal.db");
  Database writer(path);  // seeded: the reader has published laws to load
  writer.add_published(bvk_record("shared"));

  // The writer opens a transaction and writes a new version, but does not commit yet.
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(writer.handle(), "BEGIN IMMEDIATE", nullptr, nullptr, &err), SQLITE_OK);
  const LawRecord pending = writer.add_draft(bvk_record("shared", 1.5));  // joins the transaction
  EXPECT_EQ(pending.version, 2);

  DatabaseOptions reader_options;
  reader_options.busy_timeout_ms = 200;  // a reader must not need to wait at all
  Database reader(path, reader_options);
  const std::vector<LawRecord> seen = reader.list("shared");
  ASSERT_EQ(seen.size(), 1u);  // the uncommitted version 2 is invisible
  EXPECT_EQ(seen[0].version, 1);
  EXPECT_EQ(reader.load("shared")->reference(), "shared@1");
  EXPECT_FALSE(reader.list().empty());
  EXPECT_EQ(reader.resolve("bvk2007").status, LawStatus::kPublished);

  // A second writer waits for the lock, then gives up with a clear error; nothing is written.
  const Error blocked = error_of([&] { reader.add_draft(bvk_record("other")); });
  EXPECT_EQ(blocked.code(), ErrorCode::kDatabase);
  EXPECT_NE(std::string(blocked.what()).find("locked"), std::string::npos) << blocked.what();

  ASSERT_EQ(sqlite3_exec(writer.handle(), "COMMIT", nullptr, nullptr, &err), SQLITE_OK);
  EXPECT_EQ(reader.list("shared").size(), 2u);  // visible once committed
  EXPECT_TRUE(reader.list("other").empty());
}

// ---- files that are not draglab databases ----------------------------------------------------

TEST(DatabaseFiles, NonSqliteFileIsRefusedNamingThePath) {
  TempDir dir;
  const std::string path = dir.file("notes.db");
  {
    std::ofstream out(path);
    out << "These are my lab notes, not a database. Re = 10, phi = 0.3.\n";
    for (int i = 0; i < 200; ++i) out << "line " << i << "\n";
  }
  const Error e = error_of([&] { Database db(path); });
  EXPECT_EQ(e.code(), ErrorCode::kNotADatabase);
  EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  // The file is left as it was.
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "These are my lab notes, not a database. Re = 10, phi = 0.3.");
}

TEST(DatabaseFiles, CorruptDatabaseIsRefusedNamingThePath) {
  TempDir dir;
  const std::string path = dir.file("corrupt.db");
  { Database db(path); }  // closing the last connection checkpoints the WAL into the file
  ASSERT_FALSE(fs::exists(path + "-wal"));
  {
    // Overwrite the b-tree page header of page 1 (the schema table), after the 100-byte file
    // header, with garbage.
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    const std::string garbage(64, '\x5a');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  const Error e = error_of([&] { Database db(path); });
  EXPECT_EQ(e.code(), ErrorCode::kNotADatabase) << e.what();
  EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
}

TEST(DatabaseFiles, ForeignSqliteDatabaseIsRefused) {
  TempDir dir;
  const std::string path = dir.file("foreign.db");
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(raw, "CREATE TABLE measurements (t REAL, v REAL)", nullptr, nullptr, nullptr),
      SQLITE_OK);
  sqlite3_close(raw);
  const Error e = error_of([&] { Database db(path); });
  EXPECT_EQ(e.code(), ErrorCode::kNotADatabase);
  EXPECT_NE(std::string(e.what()).find("not a draglab database"), std::string::npos) << e.what();
}

TEST(DatabaseFiles, DirectoryMissingParentAndMissingFileGiveClearErrors) {
  TempDir dir;
  // Bad input (kInvalidArgument), naming the path: a directory, a directory that does not exist.
  Error e = error_of([&] { Database db(dir.path()); });
  EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find(dir.path()), std::string::npos) << e.what();

  for (bool read_only : {false, true}) {
    DatabaseOptions o;
    o.read_only = read_only;
    const std::string nowhere = dir.file("no/such/dir/laws.db");
    e = error_of([&] { Database db(nowhere, o); });
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(nowhere), std::string::npos) << e.what();
  }
  {
    // A regular file used as a directory.
    std::ofstream(dir.file("plain")) << "x";
    e = error_of([&] { Database db(dir.file("plain/laws.db")); });
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a directory"), std::string::npos) << e.what();
  }

  // A missing file that is not to be created: kNotFound naming it, and nothing is created.
  DatabaseOptions no_create;
  no_create.create_if_missing = false;
  DatabaseOptions read_only;
  read_only.read_only = true;
  DatabaseOptions immutable;
  immutable.immutable = true;
  for (const DatabaseOptions& o : {no_create, read_only, immutable}) {
    e = error_of([&] { Database db(dir.file("absent.db"), o); });
    EXPECT_EQ(e.code(), ErrorCode::kNotFound) << e.what();
    EXPECT_NE(std::string(e.what()).find(dir.file("absent.db")), std::string::npos) << e.what();
    EXPECT_FALSE(fs::exists(dir.file("absent.db")));
  }

  e = error_of([&] { Database db(""); });
  EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
}

TEST(DatabaseFiles, FileNamesWithUriCharactersAreTakenLiterally) {
  // Files are opened through SQLite URIs (for mode=ro and immutable=1): '?', '#', '%', '&',
  // spaces and non-ASCII bytes in a name must name exactly that file, read-write and read-only.
  TempDir dir;
  const std::string path = dir.file("laws?mode=memory&x=1 #%41 \xc3\xa9.db");
  {
    Database db(path, unseeded());
    db.add_published(bvk_record("odd"));
  }
  EXPECT_TRUE(fs::exists(path));
  EXPECT_EQ(directory_entries_count(dir.path()), 1u);  // no file under a mangled name
  DatabaseOptions ro;
  ro.read_only = true;
  EXPECT_EQ(Database(path, ro).resolve("odd").version, 1);
  DatabaseOptions immutable;
  immutable.immutable = true;
  EXPECT_EQ(Database(path, immutable).resolve("odd").version, 1);
}

// ---- permissions: root ignores them, so the checks that need them drop to nobody -------------

constexpr uid_t kNobody = 65534;

// Runs `check` (which returns "" when all is well, else what failed) as an unprivileged user.
// Run as root, it forks and the child drops to uid/gid 65534 with no supplementary groups, as
// `setpriv --reuid=65534 --regid=65534 --clear-groups` does (root ignores file permissions, so a
// permission check run as root would test nothing); otherwise it runs in this process, which is
// unprivileged already. The child's result comes back through a pipe.
std::string run_unprivileged(const std::function<std::string()>& check) {
  auto guarded_check = [&check]() -> std::string {
    try {
      return check();
    } catch (const std::exception& e) {
      return std::string("unexpected exception: ") + e.what();
    }
  };
  if (geteuid() != 0) return guarded_check();
  int fds[2];
  if (pipe(fds) != 0) return "pipe() failed";
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return "fork() failed";
  if (pid == 0) {
    close(fds[0]);
    std::string result;
    if (setgroups(0, nullptr) != 0 || setresgid(kNobody, kNobody, kNobody) != 0 ||
        setresuid(kNobody, kNobody, kNobody) != 0) {
      result = "cannot drop privileges to uid/gid 65534";
    } else {
      result = guarded_check();
    }
    std::size_t written = 0;
    while (written < result.size()) {
      const ssize_t n = write(fds[1], result.data() + written, result.size() - written);
      if (n <= 0) break;
      written += static_cast<std::size_t>(n);
    }
    _exit(result.empty() ? 0 : 1);  // no atexit handlers, no gtest output from the child
  }
  close(fds[1]);
  std::string result;
  char buffer[512];
  ssize_t n;
  while ((n = read(fds[0], buffer, sizeof buffer)) > 0) result.append(buffer, n);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status)) return "the unprivileged child did not exit normally: " + result;
  if (WEXITSTATUS(status) != 0 && result.empty()) return "the unprivileged child failed";
  return result;
}

// What a test compares to show that a file was not written: size, modification time and bytes.
struct FileState {
  std::uintmax_t size = 0;
  struct timespec mtime {};
  std::string bytes;
};

FileState file_state(const std::string& path) {
  FileState state;
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return state;
  state.size = static_cast<std::uintmax_t>(st.st_size);
  state.mtime = st.st_mtim;
  std::ifstream in(path, std::ios::binary);
  state.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return state;
}

void expect_same_file(const FileState& a, const FileState& b) {
  EXPECT_EQ(a.size, b.size);
  EXPECT_EQ(a.mtime.tv_sec, b.mtime.tv_sec);
  EXPECT_EQ(a.mtime.tv_nsec, b.mtime.tv_nsec);
  EXPECT_TRUE(a.bytes == b.bytes) << "the database file's content changed";
}

std::vector<std::string> directory_entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(DatabaseFiles, UnwritableFileGivesAClearError) {
  TempDir dir;
  const std::string path = dir.file("locked.db");
  { Database db(path, unseeded()); }
  ASSERT_EQ(chmod(path.c_str(), 0444), 0);
  ASSERT_EQ(chmod(dir.path().c_str(), 0755), 0);  // nobody may enter, not write
  const FileState before = file_state(path);
  const std::string failure = run_unprivileged([&]() -> std::string {
    if (access(path.c_str(), W_OK) == 0) return "the mode-0444 file is writable: no test";
    const Error e = error_of([&] { Database db(path); });
    const std::string message = e.what();
    if (e.code() != ErrorCode::kDatabase) return "expected kDatabase, got: " + message;
    if (message.find("not writable") == std::string::npos ||
        message.find(path) == std::string::npos) {
      return "the message should name the file and say it is not writable: " + message;
    }
    return "";
  });
  EXPECT_EQ(failure, "");
  expect_same_file(file_state(path), before);
}

// ---- read-only opens: a solver reading a shared installation ---------------------------------

class DatabaseReadOnly : public ::testing::Test {
 protected:
  // A seeded database with one more published law, closed (the WAL folded into the file), made
  // read-only the way a shared installation is: file 0444 in a directory 0555.
  void SetUp() override {
    path_ = dir_.file("shared.db");
    {
      Database db(path_);
      db.add_published(bvk_record("site_law", 1.1));
      expected_F_ = db.load("site_law")->F(0.3, 50.0);
    }
    ASSERT_FALSE(fs::exists(path_ + "-wal"));
    ASSERT_EQ(chmod(path_.c_str(), 0444), 0);
    ASSERT_EQ(chmod(dir_.path().c_str(), 0555), 0);
    before_ = file_state(path_);
    entries_before_ = directory_entries(dir_.path());
  }

  static DatabaseOptions read_only() {
    DatabaseOptions o;
    o.read_only = true;
    return o;
  }

  // Reads through `db` and tries every kind of write; returns what went wrong ("" if nothing).
  std::string read_and_refuse_writes(Database& db) const {
    std::string failures;
    auto fail = [&failures](const std::string& what) { failures += what + "; "; };
    if (!db.is_read_only()) fail("is_read_only() is false");
    if (db.list().size() < 2) fail("the laws are not listed");
    const double F = db.load("site_law")->F(0.3, 50.0);
    if (F != expected_F_) fail("site_law F(0.3, 50) = " + std::to_string(F));  // same bits
    if (!db.check().ok) fail("check(): " + db.check().BriefReport());
    if (error_of([&] { db.add_draft(bvk_record("new_law")); }).code() !=
        ErrorCode::kInvalidArgument) {
      fail("add_draft was not refused as bad input (kInvalidArgument)");
    }
    if (error_of([&] { db.migrate(); }).code() != ErrorCode::kInvalidArgument) {
      fail("migrate was not refused as bad input (kInvalidArgument)");
    }
    if (error_of([&] { db.seed_literature(); }).code() != ErrorCode::kInvalidArgument) {
      fail("seed_literature was not refused as bad input (kInvalidArgument)");
    }
    return failures;
  }

  TempDir dir_;
  std::string path_;
  double expected_F_ = 0.0;
  FileState before_;
  std::vector<std::string> entries_before_;
};

TEST_F(DatabaseReadOnly, ReadOnlyOpenNeverWritesTheFile) {
  {
    Database db(path_, read_only());
    EXPECT_EQ(read_and_refuse_writes(db), "");
    // Immutable only where SQLite could not create the -shm index (unprivileged user).
    EXPECT_EQ(db.is_immutable(), access(dir_.path().c_str(), W_OK) != 0);
  }
  // SQLite may leave -wal/-shm files next to it where it may create them; the file is untouched.
  expect_same_file(file_state(path_), before_);
}

TEST_F(DatabaseReadOnly, ImmutableOpenCreatesNothing) {
  DatabaseOptions o;
  o.immutable = true;
  {
    Database db(path_, o);
    EXPECT_TRUE(db.is_immutable());
    EXPECT_EQ(read_and_refuse_writes(db), "");
    EXPECT_EQ(directory_entries(dir_.path()), entries_before_);  // no -wal, -shm or journal
  }
  expect_same_file(file_state(path_), before_);
  EXPECT_EQ(directory_entries(dir_.path()), entries_before_);
}

TEST_F(DatabaseReadOnly, UnprivilegedUserReadsAnInstallationItCannotWrite) {
  const std::string failure = run_unprivileged([&]() -> std::string {
    if (access(dir_.path().c_str(), W_OK) == 0) return "the 0555 directory is writable: no test";
    std::string failures;
    {
      Database db(path_, read_only());
      if (!db.is_immutable()) failures += "expected the immutable fallback; ";
      failures += read_and_refuse_writes(db);
      if (directory_entries(dir_.path()) != entries_before_) failures += "files were created; ";
    }
    // A read-write open of the same file is refused with a clear message.
    const Error e = error_of([&] { Database db(path_); });
    if (e.code() != ErrorCode::kDatabase ||
        std::string(e.what()).find("not writable") == std::string::npos) {
      failures += std::string("read-write open: ") + e.what() + "; ";
    }
    return failures;
  });
  EXPECT_EQ(failure, "");
  expect_same_file(file_state(path_), before_);
  EXPECT_EQ(directory_entries(dir_.path()), entries_before_);
}

TEST_F(DatabaseReadOnly, LeftoverWalFilesInAnUnwritableDirectory) {
  // A read-only open where the directory was writable leaves an empty -wal and the -shm behind.
  ASSERT_EQ(chmod(dir_.path().c_str(), 0755), 0);
  {
    Database db(path_, read_only());
    db.list();
  }
  ASSERT_EQ(chmod(dir_.path().c_str(), 0555), 0);
  ASSERT_TRUE(fs::exists(path_ + "-shm"));
  ASSERT_TRUE(fs::exists(path_ + "-wal"));
  ASSERT_EQ(fs::file_size(path_ + "-wal"), 0u);
  // With both, SQLite reads through them (not immutable: a writer's commits would be seen).
  auto reads = [this](bool expect_immutable) {
    return run_unprivileged([&]() -> std::string {
      if (access(dir_.path().c_str(), W_OK) == 0) return "the 0555 directory is writable";
      Database db(path_, read_only());
      std::string failures = read_and_refuse_writes(db);
      if (db.is_immutable() != expect_immutable) failures += "wrong immutable mode; ";
      return failures;
    });
  };
  EXPECT_EQ(reads(false), "");
  // With the -shm index alone SQLite cannot open it, and the (empty) log is safe to skip.
  ASSERT_EQ(chmod(dir_.path().c_str(), 0755), 0);
  ASSERT_TRUE(fs::remove(path_ + "-wal"));
  ASSERT_EQ(chmod(dir_.path().c_str(), 0555), 0);
  EXPECT_EQ(reads(true), "");
  expect_same_file(file_state(path_), before_);
}

TEST(DatabaseReadOnlyWal, CommittedLogIsReadOrRefusedNeverIgnored) {
  // A copy taken while a writer had the file open: the last law exists only in the -wal file.
  TempDir source;
  TempDir copy;
  const std::string original = source.file("live.db");
  const std::string path = copy.file("live.db");
  Database writer(original, unseeded());
  writer.add_published(bvk_record("in_the_log"));
  ASSERT_TRUE(fs::exists(original + "-wal"));
  ASSERT_GT(fs::file_size(original + "-wal"), 0u);
  fs::copy_file(original, path);
  fs::copy_file(original + "-wal", path + "-wal");
  ASSERT_EQ(chmod(copy.path().c_str(), 0555), 0);

  // Where the -shm index cannot be created, an immutable open would silently miss the law: the
  // open is refused, naming the log.
  const std::string failure = run_unprivileged([&]() -> std::string {
    if (access(copy.path().c_str(), W_OK) == 0) return "the 0555 directory is writable: no test";
    DatabaseOptions o;
    o.read_only = true;
    const Error e = error_of([&] { Database db(path, o); });
    const std::string message = e.what();
    if (e.code() != ErrorCode::kDatabase) return "expected kDatabase, got: " + message;
    if (message.find(path + "-wal") == std::string::npos) return "log not named: " + message;
    return "";
  });
  EXPECT_EQ(failure, "");

  // Where it can (root here), a read-only open reads the log.
  if (access(copy.path().c_str(), W_OK) == 0) {
    DatabaseOptions o;
    o.read_only = true;
    Database db(path, o);
    EXPECT_FALSE(db.is_immutable());
    EXPECT_EQ(db.resolve("in_the_log").version, 1);
  }
}

TEST(DatabaseReadOnlyWal, ReadOnlyReaderSeesLaterCommits) {
  // Not immutable where the directory is writable: a writer's later commits are visible.
  TempDir dir;
  const std::string path = dir.file("live.db");
  Database writer(path, unseeded());
  DatabaseOptions o;
  o.read_only = true;
  Database reader(path, o);
  ASSERT_FALSE(reader.is_immutable());
  EXPECT_TRUE(reader.list("later").empty());
  writer.add_published(bvk_record("later"));
  EXPECT_EQ(reader.list("later").size(), 1u);
}

}  // namespace
}  // namespace draglab
