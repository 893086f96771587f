// The SQLite drag-law database at the file and SQL level: immutability enforced by triggers
// against the real sqlite3 command-line shell, forward migration from schema 1, a reader during
// a writer's open transaction (WAL), and clear errors for files that are not draglab databases.
//
// Set-up: fresh database files in a temporary directory; records built from the registered form
// "bvk2007" under test names. The shell is the program named by DRAGLAB_SQLITE3_SHELL (the
// Debian `sqlite3` package), run on the database file exactly as a user would run it.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "draglab/drag_db/database.h"
#include "draglab/drag_db/error.h"
#include "draglab/drag_db/law.h"
#include "draglab/drag_db/law_form.h"

#ifndef DRAGLAB_SQLITE3_SHELL
#define DRAGLAB_SQLITE3_SHELL "sqlite3"
#endif

namespace draglab {
namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "draglab_dbsql_test_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ignored);
    fs::remove_all(path_, ignored);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

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
  Error e = error_of([&] { Database db(dir.path().string()); });
  EXPECT_EQ(e.code(), ErrorCode::kDatabase);
  EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();

  e = error_of([&] { Database db(dir.file("no/such/dir/laws.db")); });
  EXPECT_EQ(e.code(), ErrorCode::kDatabase);
  EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();

  DatabaseOptions no_create;
  no_create.create_if_missing = false;
  e = error_of([&] { Database db(dir.file("absent.db"), no_create); });
  EXPECT_EQ(e.code(), ErrorCode::kDatabase);
  EXPECT_NE(std::string(e.what()).find("absent.db"), std::string::npos) << e.what();
  EXPECT_FALSE(fs::exists(dir.file("absent.db")));

  e = error_of([&] { Database db(""); });
  EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
}

TEST(DatabaseFiles, UnwritableFileGivesAClearError) {
  TempDir dir;
  const std::string path = dir.file("locked.db");
  { Database db(path, unseeded()); }
  ASSERT_EQ(chmod(path.c_str(), 0444), 0);
  if (access(path.c_str(), W_OK) == 0) {
    GTEST_SKIP() << "running with permission to write a mode-0444 file (root?)";
  }
  const Error e = error_of([&] { Database db(path); });
  EXPECT_EQ(e.code(), ErrorCode::kDatabase);
  EXPECT_NE(std::string(e.what()).find("not writable"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
}

}  // namespace
}  // namespace draglab
