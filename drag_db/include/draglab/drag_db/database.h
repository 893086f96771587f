// draglab/drag_db/database.h: the SQLite drag-law database.
//
// Holds every law version with its provenance (law.h: LawRecord). Published versions are
// immutable, enforced by SQL triggers as well as here: any change is a new version. Retracted
// versions stay loadable with a warning. A read-write open puts the file in WAL mode so readers
// keep working while a writer commits; every write is one transaction (nothing is ever
// half-written). A read-only open never writes the file (DatabaseOptions::read_only), so a solver
// can read a shared installation it has no write permission on.
//
// References: "name" or "name@latest" (latest published version), "name@3" (version 3),
// "name@<hex>" (the version whose content hash starts with <hex>, at least 4 digits).
//
// Schema: a schema_version table and forward migrations (docs/database.md). A file written by
// a newer draglab (higher schema version) is refused with Error(kSchemaTooNew).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "draglab/drag_db/law.h"

struct sqlite3;

namespace draglab {

/// The rule for law names, in one place (the database applies it to every stored version; the
/// command line applies it before long work, e.g. the pipeline before its LBM campaign): 1 to
/// 100 characters from A-Z a-z 0-9 _ . -, starting with a letter or digit (so no '@', which
/// separates name and version). Throws Error(kInvalidArgument) naming the name and the rule.
void check_law_name(const std::string& name);

/// Options for Database::open.
struct DatabaseOptions {
  bool create_if_missing = true;  ///< Create (and seed) a new file if none exists.
  bool seed_literature = true;    ///< Seed the literature library into a newly created file.
  /// Open read-only: SQLite mode=ro; never creates, migrates, seeds or changes the journal mode,
  /// never writes the database file, and works on a file (and directory) the caller cannot
  /// write. SQLite's reader of a WAL file uses the -wal and -shm files next to it and creates
  /// them where the directory allows (they may stay after closing). In a directory the caller
  /// cannot write, without both of them, the file is opened immutable (see `immutable`) if no
  /// -wal or -journal file holds changes, else Error(kDatabase) says what to do. A schema older
  /// than this build's is read as it is: each read checks the schema version it needs and
  /// otherwise says to run `draglab db migrate`.
  bool read_only = false;
  /// Open with SQLite's immutable=1 (implies read_only): no locks, no -wal/-shm files, nothing
  /// written anywhere. Only for files nothing writes to while they are open (read-only media,
  /// snapshots, shared installations): changes made by another connection are not seen, and a
  /// file changed under an immutable reader can give wrong results or kNotADatabase.
  bool immutable = false;
  bool migrate = true;         ///< Apply forward migrations to an older schema on open.
  int busy_timeout_ms = 5000;  ///< How long a writer waits for a lock before failing.
  bool IsValid(std::string* error) const;
};

/// Result of Database::check().
struct DatabaseCheckReport {
  bool ok = true;
  int schema_version = 0;
  int laws_checked = 0;
  std::vector<std::string> problems;  ///< One line per problem (integrity, hash mismatch, ...).
  std::string BriefReport() const;
  std::string FullReport() const;
};

/// One entry of the append-only history of a law version (schema version 2, table law_events).
/// Written by SQL triggers, so changes made outside draglab (sqlite3 shell) are recorded too.
struct LawEvent {
  std::string name;
  int version = 0;
  std::string event;         ///< "created", "updated", "published", "retracted" or "deleted".
  std::string at;            ///< ISO 8601 UTC, second resolution.
  std::string content_hash;  ///< Content hash of the version after the event.
  std::string detail;        ///< Retraction reason, or what an update changed.
};

/// An open draglab database. Not thread-safe: use one Database per thread (Law objects loaded
/// from it are thread-safe and independent of it).
class Database {
 public:
  /// The schema version this build writes.
  static int current_schema_version();
  /// Default path: $DRAGLAB_DB if set and non-empty, else "./draglab.db".
  static std::string default_path();

  /// Opens (creating, migrating and seeding as the options say). Throws Error naming the path:
  /// kInvalidArgument for an empty path, a directory, or a path whose directory does not exist;
  /// kNotFound for a missing file that is not to be created (read_only or !create_if_missing);
  /// kNotADatabase for a corrupt or non-SQLite file; kSchemaTooNew for a newer schema; kDatabase
  /// for I/O and permission errors (e.g. a read-write open of a file the caller cannot write).
  explicit Database(const std::string& path, const DatabaseOptions& options = DatabaseOptions());
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  const std::string& path() const { return path_; }
  /// True if opened read-only (DatabaseOptions::read_only or immutable).
  bool is_read_only() const { return read_only_; }
  /// True if opened with SQLite's immutable=1: asked for, or the read-only fallback for a
  /// directory the caller cannot write (DatabaseOptions). Concurrent writers are not seen.
  bool is_immutable() const { return immutable_; }
  int schema_version() const;
  /// Applies forward migrations up to `target` (default: current); returns the versions applied.
  std::vector<int> migrate(int target = -1);

  /// All versions of all laws (or of `name`), ordered by name then version.
  std::vector<LawRecord> list(const std::string& name = "", bool include_drafts = true) const;
  /// Resolves a reference (see file comment); throws Error(kNotFound) with a helpful message.
  LawRecord resolve(const std::string& reference) const;
  /// Resolves and binds to the registered form. A retracted version loads with `*warning` set
  /// (if given); a draft loads with a warning too.
  std::shared_ptr<Law> load(const std::string& reference, RangePolicy policy = RangePolicy::kError,
                            std::string* warning = nullptr) const;

  /// Stores a new draft version of record.name (version = last + 1), validating the form,
  /// parameters and validity box and computing the content hash. Returns the stored record.
  LawRecord add_draft(LawRecord record);
  /// Replaces the parameters/covariance/notes of a draft (published versions: kImmutable).
  /// Also taken from `record`: validity box and provenance; name, version, form, convention,
  /// status and created_at stay as stored. The content hash is recomputed.
  LawRecord update_draft(const LawRecord& record);
  /// Draft -> published (immutable from now on).
  LawRecord publish(const std::string& name, int version);
  /// Convenience: add_draft + publish in one transaction.
  LawRecord add_published(LawRecord record);
  /// Published -> retracted, with a reason (kept loadable, with a warning).
  LawRecord retract(const std::string& name, int version, const std::string& reason);
  /// Deletes a draft (published or retracted versions cannot be deleted: kImmutable).
  void delete_draft(const std::string& name, int version);

  /// Seeds the literature library (one published version 1 per registered literature form that
  /// is not yet present). Returns the number of laws added.
  int seed_literature();

  /// SQLite integrity check, schema version, recomputed content hashes, known forms.
  DatabaseCheckReport check() const;

  /// History of law `name` (all its versions, or only `version` if > 0), oldest first.
  /// Needs schema version 2 or later. An unknown name gives an empty list (deleted drafts keep
  /// their history).
  std::vector<LawEvent> history(const std::string& name, int version = 0) const;

  /// The raw handle, for modules that add their own tables through migrations.
  sqlite3* handle() const { return db_; }

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
  bool read_only_ = false;
  bool immutable_ = false;
};

}  // namespace draglab
