// Forward migrations of the draglab database (schema.h, docs/database.md).
//
// Immutability is enforced by triggers so that it holds for every client, the sqlite3 shell
// included. SQLite 3.40's RAISE() accepts only a literal message, which cannot name the law; the
// guards that must name it instead evaluate json_extract('{}', <message>): a JSON path that does
// not start with '$' is always an error, and SQLite quotes the path (our message) in the error
// text, so the statement is aborted with e.g.
//   JSON path error near 'draglab: law bvk2007@1 is published and immutable; ...'
// Like RAISE(ABORT), any error inside a trigger undoes the whole statement.
#include "db/schema.h"

#include "db/sqlite_util.h"

namespace draglab {
namespace db {
namespace {

// Aborts the running statement with a message naming law `id_expr` (an SQL expression for
// laws.id). Only used where the WHEN clause has established that the law row exists.
std::string abort_naming_law(const std::string& id_expr, const std::string& what) {
  return "SELECT json_extract('{}', (SELECT 'draglab: law ' || name || '@' || version || ' is ' "
         "|| status || ' and immutable (" +
         what + "); " + kImmutableMarker + "' FROM laws WHERE id = " + id_expr + "));\n";
}

// The three guards of a child table of laws (rows keyed by law_id): no insert, update or
// delete of rows that belong to a published or retracted version.
std::string child_table_guards(const std::string& table) {
  const std::string status_of = "(SELECT status FROM laws WHERE id = ";
  std::string sql;
  sql += "CREATE TRIGGER " + table + "_immutable_insert BEFORE INSERT ON " + table + "\nWHEN " +
         status_of + "NEW.law_id) <> 'draft'\nBEGIN\n  " +
         abort_naming_law("NEW.law_id", "INSERT INTO " + table) + "END;\n";
  sql +=
      "CREATE TRIGGER " + table + "_immutable_update BEFORE UPDATE ON " + table + "\nWHEN " +
      status_of + "OLD.law_id) <> 'draft' OR " + status_of + "NEW.law_id) <> 'draft'\nBEGIN\n  " +
      abort_naming_law(
          "CASE WHEN " + status_of + "OLD.law_id) <> 'draft' THEN OLD.law_id ELSE NEW.law_id END",
          "UPDATE " + table) +
      "END;\n";
  sql += "CREATE TRIGGER " + table + "_immutable_delete BEFORE DELETE ON " + table + "\nWHEN " +
         status_of + "OLD.law_id) <> 'draft'\nBEGIN\n  " +
         abort_naming_law("OLD.law_id", "DELETE FROM " + table) + "END;\n";
  return sql;
}

// Version 1: law versions with parameters, covariance and extra inputs; immutability triggers.
std::string migration_1() {
  std::string sql = R"sql(
CREATE TABLE schema_version (
  version      INTEGER PRIMARY KEY,
  description  TEXT NOT NULL,
  applied_at   TEXT NOT NULL,            -- ISO 8601 UTC
  code_version TEXT NOT NULL             -- draglab version that applied the migration
);

CREATE TABLE laws (
  id                INTEGER PRIMARY KEY,
  name              TEXT NOT NULL CHECK (length(name) BETWEEN 1 AND 100 AND instr(name, '@') = 0),
  version           INTEGER NOT NULL CHECK (version >= 1),
  form              TEXT NOT NULL,       -- registered law form key
  -- native convention (conventions.h string forms)
  force_kind        TEXT NOT NULL,
  normalisation     TEXT NOT NULL,
  reynolds          TEXT NOT NULL,
  tfm_model         TEXT NOT NULL,
  -- validity box (extra inputs: law_extra_inputs)
  phi_min           REAL NOT NULL,
  phi_max           REAL NOT NULL,
  re_min            REAL NOT NULL,
  re_max            REAL NOT NULL,
  -- provenance
  provenance_kind   TEXT NOT NULL,       -- literature / fitted / manual
  citation          TEXT NOT NULL DEFAULT '',
  dataset_id        TEXT NOT NULL DEFAULT '',
  data_hash         TEXT NOT NULL DEFAULT '',
  fitter_settings   TEXT NOT NULL DEFAULT '',
  code_version      TEXT NOT NULL DEFAULT '',
  content_hash      TEXT NOT NULL CHECK (length(content_hash) = 64),
  status            TEXT NOT NULL DEFAULT 'draft'
                    CHECK (status IN ('draft', 'published', 'retracted')),
  created_at        TEXT NOT NULL,
  published_at      TEXT,
  retracted_at      TEXT,
  retraction_reason TEXT NOT NULL DEFAULT '',
  notes             TEXT NOT NULL DEFAULT '',
  UNIQUE (name, version),
  CHECK (phi_min <= phi_max AND re_min <= re_max)
);

CREATE TABLE law_parameters (
  law_id   INTEGER NOT NULL REFERENCES laws(id) ON DELETE CASCADE,
  position INTEGER NOT NULL CHECK (position >= 0),   -- order of the form's parameters
  name     TEXT NOT NULL,
  value    REAL NOT NULL,
  unit     TEXT NOT NULL,
  PRIMARY KEY (law_id, position),
  UNIQUE (law_id, name)
) WITHOUT ROWID;

CREATE TABLE law_covariance (
  law_id    INTEGER NOT NULL REFERENCES laws(id) ON DELETE CASCADE,
  row_index INTEGER NOT NULL CHECK (row_index >= 0),
  col_index INTEGER NOT NULL CHECK (col_index >= 0),
  value     REAL NOT NULL,
  PRIMARY KEY (law_id, row_index, col_index)
) WITHOUT ROWID;

CREATE TABLE law_extra_inputs (
  law_id      INTEGER NOT NULL REFERENCES laws(id) ON DELETE CASCADE,
  position    INTEGER NOT NULL CHECK (position >= 0),
  name        TEXT NOT NULL,
  description TEXT NOT NULL DEFAULT '',
  min_value   REAL NOT NULL,
  max_value   REAL NOT NULL CHECK (min_value <= max_value),
  PRIMARY KEY (law_id, position)
) WITHOUT ROWID;

-- A version is inserted as a draft and published once its parameter rows are stored (the
-- parameter guards below refuse rows of published versions).
CREATE TRIGGER laws_insert_as_draft BEFORE INSERT ON laws
WHEN NEW.status <> 'draft'
BEGIN
  SELECT RAISE(ABORT, 'draglab: a law version is inserted as a draft and published after its parameters are stored');
END;

-- Drafts are deleted, not retracted: only published versions can be retracted.
CREATE TRIGGER laws_retract_only_published BEFORE UPDATE OF status ON laws
WHEN OLD.status = 'draft' AND NEW.status = 'retracted'
BEGIN
  SELECT RAISE(ABORT, 'draglab: only published law versions can be retracted; delete a draft instead');
END;

-- A retraction is shown to everyone who loads the version: it must say why.
CREATE TRIGGER laws_retract_needs_reason BEFORE UPDATE OF status ON laws
WHEN OLD.status = 'published' AND NEW.status = 'retracted' AND trim(NEW.retraction_reason) = ''
BEGIN
  SELECT RAISE(ABORT, 'draglab: a retraction needs a reason (set retraction_reason)');
END;

-- Published and retracted versions never change, except published -> retracted with the
-- retraction time and reason (every other column must stay as it is).
CREATE TRIGGER laws_immutable_update BEFORE UPDATE ON laws
WHEN OLD.status <> 'draft' AND NOT (
  OLD.status = 'published' AND NEW.status = 'retracted'
  AND NEW.id IS OLD.id AND NEW.name IS OLD.name AND NEW.version IS OLD.version
  AND NEW.form IS OLD.form
  AND NEW.force_kind IS OLD.force_kind AND NEW.normalisation IS OLD.normalisation
  AND NEW.reynolds IS OLD.reynolds AND NEW.tfm_model IS OLD.tfm_model
  AND NEW.phi_min IS OLD.phi_min AND NEW.phi_max IS OLD.phi_max
  AND NEW.re_min IS OLD.re_min AND NEW.re_max IS OLD.re_max
  AND NEW.provenance_kind IS OLD.provenance_kind AND NEW.citation IS OLD.citation
  AND NEW.dataset_id IS OLD.dataset_id AND NEW.data_hash IS OLD.data_hash
  AND NEW.fitter_settings IS OLD.fitter_settings AND NEW.code_version IS OLD.code_version
  AND NEW.content_hash IS OLD.content_hash AND NEW.created_at IS OLD.created_at
  AND NEW.published_at IS OLD.published_at AND NEW.notes IS OLD.notes)
BEGIN
)sql";
  sql += "  " + abort_naming_law("OLD.id", "UPDATE laws") + "END;\n";
  sql += R"sql(
CREATE TRIGGER laws_immutable_delete BEFORE DELETE ON laws
WHEN OLD.status <> 'draft'
BEGIN
)sql";
  sql += "  " + abort_naming_law("OLD.id", "DELETE FROM laws; retract it") + "END;\n";
  sql += child_table_guards("law_parameters");
  sql += child_table_guards("law_covariance");
  sql += child_table_guards("law_extra_inputs");
  return sql;
}

// Version 2: an append-only history of every law version (created, updated, published,
// retracted, deleted), written by triggers so that it also records changes made outside draglab.
std::string migration_2() {
  return R"sql(
CREATE TABLE law_events (
  id           INTEGER PRIMARY KEY,
  name         TEXT NOT NULL,
  version      INTEGER NOT NULL,
  event        TEXT NOT NULL
               CHECK (event IN ('created', 'updated', 'published', 'retracted', 'deleted')),
  at           TEXT NOT NULL,                -- ISO 8601 UTC
  content_hash TEXT NOT NULL,
  detail       TEXT NOT NULL DEFAULT ''      -- retraction reason, what changed
);
CREATE INDEX law_events_by_law ON law_events (name, version, id);

-- Backfill from the laws already stored (their times are known from the laws table).
INSERT INTO law_events (name, version, event, at, content_hash, detail)
  SELECT name, version, 'created', created_at, content_hash, 'recorded by migration 2'
  FROM laws ORDER BY id;
INSERT INTO law_events (name, version, event, at, content_hash, detail)
  SELECT name, version, 'published', published_at, content_hash, 'recorded by migration 2'
  FROM laws WHERE published_at IS NOT NULL ORDER BY id;
INSERT INTO law_events (name, version, event, at, content_hash, detail)
  SELECT name, version, 'retracted', coalesce(retracted_at, published_at, created_at),
         content_hash, retraction_reason
  FROM laws WHERE status = 'retracted' ORDER BY id;

CREATE TRIGGER law_events_on_insert AFTER INSERT ON laws
BEGIN
  INSERT INTO law_events (name, version, event, at, content_hash)
  VALUES (NEW.name, NEW.version, 'created', NEW.created_at, NEW.content_hash);
END;

CREATE TRIGGER law_events_on_draft_update AFTER UPDATE ON laws
WHEN OLD.status = 'draft' AND NEW.status = 'draft'
BEGIN
  INSERT INTO law_events (name, version, event, at, content_hash, detail)
  VALUES (NEW.name, NEW.version, 'updated', strftime('%Y-%m-%dT%H:%M:%SZ', 'now'),
          NEW.content_hash,
          CASE WHEN NEW.content_hash IS OLD.content_hash THEN 'metadata changed'
               ELSE 'content changed (was ' || OLD.content_hash || ')' END);
END;

CREATE TRIGGER law_events_on_publish AFTER UPDATE OF status ON laws
WHEN OLD.status = 'draft' AND NEW.status = 'published'
BEGIN
  INSERT INTO law_events (name, version, event, at, content_hash)
  VALUES (NEW.name, NEW.version, 'published',
          coalesce(NEW.published_at, strftime('%Y-%m-%dT%H:%M:%SZ', 'now')), NEW.content_hash);
END;

CREATE TRIGGER law_events_on_retract AFTER UPDATE OF status ON laws
WHEN OLD.status = 'published' AND NEW.status = 'retracted'
BEGIN
  INSERT INTO law_events (name, version, event, at, content_hash, detail)
  VALUES (NEW.name, NEW.version, 'retracted',
          coalesce(NEW.retracted_at, strftime('%Y-%m-%dT%H:%M:%SZ', 'now')), NEW.content_hash,
          NEW.retraction_reason);
END;

CREATE TRIGGER law_events_on_delete AFTER DELETE ON laws
BEGIN
  INSERT INTO law_events (name, version, event, at, content_hash)
  VALUES (OLD.name, OLD.version, 'deleted', strftime('%Y-%m-%dT%H:%M:%SZ', 'now'),
          OLD.content_hash);
END;

CREATE TRIGGER law_events_append_only_update BEFORE UPDATE ON law_events
BEGIN
  SELECT RAISE(ABORT, 'draglab: law_events is an append-only history and cannot be changed');
END;

CREATE TRIGGER law_events_append_only_delete BEFORE DELETE ON law_events
BEGIN
  SELECT RAISE(ABORT, 'draglab: law_events is an append-only history and cannot be changed');
END;
)sql";
}

// Version 3: no REPLACE conflict resolution against protected rows.
//
// INSERT OR REPLACE / UPDATE OR REPLACE (and REPLACE INTO) resolve a UNIQUE or PRIMARY KEY
// conflict by deleting the row in the way, and SQLite fires no DELETE trigger for that deletion
// unless PRAGMA recursive_triggers is on. Without these guards a published law could be swapped
// for a draft copy (then edited and re-published) or silently deleted, and a history event
// overwritten. Where REPLACE could reach a protected row:
//   laws: id (INTEGER PRIMARY KEY, also written as rowid) and UNIQUE (name, version), by INSERT or
//     by an UPDATE of a draft that moves its id, name or version onto a published/retracted row:
//     laws_no_replace_insert and laws_no_replace_update below. The update guard has no column
//     list on purpose: "UPDATE ... SET rowid = ..." changes id without naming it, and an
//     UPDATE OF id trigger would not fire.
//   law_parameters, law_covariance, law_extra_inputs: every key starts with law_id, so the row in
//     the way has the new row's law_id, and the version-1 guards already refuse any INSERT or
//     UPDATE whose NEW.law_id is not a draft, before the conflict is resolved.
//   law_events: id (INTEGER PRIMARY KEY) by INSERT (updates are refused outright):
//     law_events_no_replace_insert. The history triggers never give an id.
//   schema_version: not protected by triggers at all (migrations are recorded by draglab only).
// The guards fire for a plain INSERT that collides too (it would fail on the constraint anyway):
// a trigger cannot see the conflict clause, so the message says what the statement would do.
std::string migration_3() {
  const std::string protected_collision =
      "SELECT id FROM laws WHERE status <> 'draft' AND "
      "(id = NEW.id OR (name = NEW.name AND version = NEW.version))";
  std::string sql;
  sql += "CREATE TRIGGER laws_no_replace_insert BEFORE INSERT ON laws\nWHEN EXISTS (" +
         protected_collision + ")\nBEGIN\n  " +
         abort_naming_law("(" + protected_collision + " LIMIT 1)",
                          "a new row with its id or name and version would replace it") +
         "END;\n";
  sql +=
      "CREATE TRIGGER laws_no_replace_update BEFORE UPDATE ON laws\nWHEN (NEW.id IS NOT OLD.id "
      "OR NEW.name IS NOT OLD.name OR NEW.version IS NOT OLD.version) AND EXISTS (" +
      protected_collision + " AND id IS NOT OLD.id)\nBEGIN\n  " +
      abort_naming_law("(" + protected_collision + " AND id IS NOT OLD.id LIMIT 1)",
                       "an UPDATE giving another row its id or name and version would replace "
                       "it") +
      "END;\n";
  sql += R"sql(
CREATE TRIGGER law_events_no_replace_insert BEFORE INSERT ON law_events
WHEN EXISTS (SELECT 1 FROM law_events WHERE id = NEW.id)
BEGIN
  SELECT RAISE(ABORT, 'draglab: law_events is an append-only history and cannot be changed (an INSERT with the id of an existing event would replace it)');
END;
)sql";
  return sql;
}

// Version 4: drag campaigns, their units (one LBM measurement each) and datasets.
//   campaigns: one row per campaign, the spec as canonical JSON and its hash; rows are never
//     changed or deleted (a campaign with another spec is another campaign).
//   campaign_units: one row per (phi, Re, realization, resolution) of a campaign; a unit moves
//     pending -> running -> done | failed through single-statement UPDATEs (a worker claims the
//     next pending unit with UPDATE ... RETURNING, so no unit runs twice); a finished unit (done
//     or failed) is immutable, and units are never deleted. A process killed mid-run leaves its
//     claimed units 'running'; `campaign run --resume` returns them to 'pending'.
//   datasets: immutable tables of (phi, Re) points identified by the SHA-256 of their canonical
//     JSON (dataset.h); no UPDATE, DELETE or REPLACE.
std::string migration_4() {
  return R"sql(
CREATE TABLE campaigns (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  spec_json TEXT NOT NULL,
  spec_hash TEXT NOT NULL,
  created_at TEXT NOT NULL,
  code_version TEXT NOT NULL
);
CREATE TABLE campaign_units (
  id INTEGER PRIMARY KEY,
  campaign_id INTEGER NOT NULL REFERENCES campaigns(id),
  phi_index INTEGER NOT NULL,
  re_index INTEGER NOT NULL,
  realization INTEGER NOT NULL,
  resolution_index INTEGER NOT NULL,
  phi REAL NOT NULL,
  re_target REAL NOT NULL,
  resolution REAL NOT NULL,
  seed INTEGER NOT NULL,
  status TEXT NOT NULL DEFAULT 'pending'
    CHECK (status IN ('pending', 'running', 'done', 'failed')),
  attempts INTEGER NOT NULL DEFAULT 0,
  claimed_by TEXT,
  started_at TEXT,
  finished_at TEXT,
  F REAL,
  beta_d2_over_mu REAL,
  re REAL,
  error_estimate REAL,
  steps INTEGER,
  wall_s REAL,
  mflups REAL,
  converged INTEGER,
  diagnosis TEXT,
  packing_hash TEXT,
  code_version TEXT,
  result_json TEXT,
  UNIQUE (campaign_id, phi_index, re_index, realization, resolution_index)
);
CREATE INDEX campaign_units_by_status ON campaign_units (campaign_id, status);
CREATE TABLE datasets (
  id TEXT PRIMARY KEY,
  hash TEXT NOT NULL UNIQUE,
  campaign_id INTEGER,
  name TEXT NOT NULL,
  method TEXT NOT NULL,
  created_at TEXT NOT NULL,
  code_version TEXT NOT NULL,
  points_json TEXT NOT NULL
);
CREATE TRIGGER campaigns_immutable_update BEFORE UPDATE ON campaigns
BEGIN
  SELECT RAISE(ABORT, 'draglab: campaigns are immutable (a campaign with another spec is a new campaign); create a new version instead');
END;
CREATE TRIGGER campaigns_immutable_delete BEFORE DELETE ON campaigns
BEGIN
  SELECT RAISE(ABORT, 'draglab: campaigns are immutable and cannot be deleted; create a new version instead');
END;
CREATE TRIGGER campaigns_no_replace_insert BEFORE INSERT ON campaigns
WHEN EXISTS (SELECT 1 FROM campaigns WHERE id = NEW.id OR name = NEW.name)
BEGIN
  SELECT RAISE(ABORT, 'draglab: a campaign with this id or name exists (resume it, or choose another name); create a new version instead');
END;
CREATE TRIGGER campaign_units_finished_immutable BEFORE UPDATE ON campaign_units
WHEN OLD.status IN ('done', 'failed')
BEGIN
  SELECT RAISE(ABORT, 'draglab: a finished campaign unit is immutable; create a new version instead');
END;
CREATE TRIGGER campaign_units_no_delete BEFORE DELETE ON campaign_units
BEGIN
  SELECT RAISE(ABORT, 'draglab: campaign units are never deleted; create a new version instead');
END;
CREATE TRIGGER campaign_units_no_replace_insert BEFORE INSERT ON campaign_units
WHEN EXISTS (SELECT 1 FROM campaign_units WHERE id = NEW.id OR (campaign_id = NEW.campaign_id
  AND phi_index = NEW.phi_index AND re_index = NEW.re_index AND realization = NEW.realization
  AND resolution_index = NEW.resolution_index))
BEGIN
  SELECT RAISE(ABORT, 'draglab: this campaign unit exists already; create a new version instead');
END;
CREATE TRIGGER datasets_immutable_update BEFORE UPDATE ON datasets
BEGIN
  SELECT RAISE(ABORT, 'draglab: datasets are immutable; create a new version instead');
END;
CREATE TRIGGER datasets_immutable_delete BEFORE DELETE ON datasets
BEGIN
  SELECT RAISE(ABORT, 'draglab: datasets are immutable and cannot be deleted; create a new version instead');
END;
CREATE TRIGGER datasets_no_replace_insert BEFORE INSERT ON datasets
WHEN EXISTS (SELECT 1 FROM datasets WHERE id = NEW.id OR hash = NEW.hash)
BEGIN
  SELECT RAISE(ABORT, 'draglab: datasets are immutable (a dataset with this id or hash exists); create a new version instead');
END;
)sql";
}

// Version 5: consumer results, the scenes they ran and regression baselines
// (consumer_results.h, `draglab regress`).
//   consumer_scenes: the registered scenes, keyed by the SHA-256 of their TOML text, with the text
//     itself so that a regression re-runs exactly what was registered; never changed or deleted.
//   consumer_results: one row per consumer run (scene, law name@version and its content hash,
//     code version, metrics JSON, full result JSON); immutable. The law version must exist with
//     that content hash when the row is inserted (a draft changed later keeps its old results
//     under the old hash, so they are never mistaken for the new content).
//   consumer_baselines: the result a (scene, law name) is compared against, with the tolerances.
//     One active row per (scene, law name) (partial unique index); a new baseline replaces the
//     active one only by marking it superseded (superseded_at set once, nothing else may change)
//     and naming it in `supersedes`: the rows are the history. No DELETE, no REPLACE.
std::string migration_5() {
  return R"sql(
CREATE TABLE consumer_scenes (
  hash TEXT PRIMARY KEY CHECK (length(hash) = 64),
  name TEXT NOT NULL CHECK (length(name) >= 1),
  toml TEXT NOT NULL,
  registered_at TEXT NOT NULL,
  code_version TEXT NOT NULL
);
CREATE TABLE consumer_results (
  id INTEGER PRIMARY KEY,
  scene_name TEXT NOT NULL,
  scene_hash TEXT NOT NULL REFERENCES consumer_scenes(hash),
  law_name TEXT NOT NULL,
  law_version INTEGER NOT NULL CHECK (law_version >= 1),
  law_content_hash TEXT NOT NULL CHECK (length(law_content_hash) = 64),
  code_version TEXT NOT NULL,
  created_at TEXT NOT NULL,
  metrics_json TEXT NOT NULL CHECK (json_valid(metrics_json)),
  result_json TEXT NOT NULL CHECK (json_valid(result_json))
);
CREATE INDEX consumer_results_by_run ON consumer_results (scene_hash, law_name, law_version, id);
CREATE TABLE consumer_baselines (
  id INTEGER PRIMARY KEY,
  scene_hash TEXT NOT NULL REFERENCES consumer_scenes(hash),
  law_name TEXT NOT NULL,
  result_id INTEGER NOT NULL REFERENCES consumer_results(id),
  tolerances_json TEXT NOT NULL CHECK (json_valid(tolerances_json)),
  registered_at TEXT NOT NULL,
  superseded_at TEXT,
  supersedes INTEGER REFERENCES consumer_baselines(id)
);
CREATE UNIQUE INDEX consumer_baselines_one_active ON consumer_baselines (scene_hash, law_name)
  WHERE superseded_at IS NULL;

CREATE TRIGGER consumer_scenes_immutable_update BEFORE UPDATE ON consumer_scenes
BEGIN
  SELECT RAISE(ABORT, 'draglab: registered consumer scenes are immutable (another text is another scene); create a new version instead');
END;
CREATE TRIGGER consumer_scenes_immutable_delete BEFORE DELETE ON consumer_scenes
BEGIN
  SELECT RAISE(ABORT, 'draglab: registered consumer scenes are immutable and cannot be deleted; create a new version instead');
END;
CREATE TRIGGER consumer_scenes_no_replace_insert BEFORE INSERT ON consumer_scenes
WHEN EXISTS (SELECT 1 FROM consumer_scenes WHERE hash = NEW.hash)
BEGIN
  SELECT RAISE(ABORT, 'draglab: registered consumer scenes are immutable (a scene with this hash exists); create a new version instead');
END;

CREATE TRIGGER consumer_results_immutable_update BEFORE UPDATE ON consumer_results
BEGIN
  SELECT RAISE(ABORT, 'draglab: consumer results are immutable (a new run is a new result); create a new version instead');
END;
CREATE TRIGGER consumer_results_immutable_delete BEFORE DELETE ON consumer_results
BEGIN
  SELECT RAISE(ABORT, 'draglab: consumer results are immutable and cannot be deleted; create a new version instead');
END;
CREATE TRIGGER consumer_results_no_replace_insert BEFORE INSERT ON consumer_results
WHEN EXISTS (SELECT 1 FROM consumer_results WHERE id = NEW.id)
BEGIN
  SELECT RAISE(ABORT, 'draglab: consumer results are immutable (a result with this id exists); create a new version instead');
END;
CREATE TRIGGER consumer_results_law_exists BEFORE INSERT ON consumer_results
WHEN NOT EXISTS (SELECT 1 FROM laws WHERE name = NEW.law_name AND version = NEW.law_version
                 AND content_hash = NEW.law_content_hash)
BEGIN
  SELECT RAISE(ABORT, 'draglab: a consumer result must name a stored law version with its current content hash');
END;

CREATE TRIGGER consumer_baselines_insert_checks BEFORE INSERT ON consumer_baselines
WHEN NEW.superseded_at IS NOT NULL OR NOT EXISTS (SELECT 1 FROM consumer_results
  WHERE id = NEW.result_id AND scene_hash = NEW.scene_hash AND law_name = NEW.law_name)
BEGIN
  SELECT RAISE(ABORT, 'draglab: a baseline is inserted active and names a result of its own scene and law name');
END;
CREATE TRIGGER consumer_baselines_no_replace_insert BEFORE INSERT ON consumer_baselines
WHEN EXISTS (SELECT 1 FROM consumer_baselines WHERE id = NEW.id OR (scene_hash = NEW.scene_hash
  AND law_name = NEW.law_name AND superseded_at IS NULL))
BEGIN
  SELECT RAISE(ABORT, 'draglab: this scene and law name have an active baseline; replace it explicitly (draglab regress register --replace), which keeps it as superseded; create a new version instead');
END;
CREATE TRIGGER consumer_baselines_supersede_only BEFORE UPDATE ON consumer_baselines
WHEN OLD.superseded_at IS NOT NULL OR NEW.superseded_at IS NULL
  OR NEW.id IS NOT OLD.id OR NEW.scene_hash IS NOT OLD.scene_hash
  OR NEW.law_name IS NOT OLD.law_name OR NEW.result_id IS NOT OLD.result_id
  OR NEW.tolerances_json IS NOT OLD.tolerances_json OR NEW.registered_at IS NOT OLD.registered_at
  OR NEW.supersedes IS NOT OLD.supersedes
BEGIN
  SELECT RAISE(ABORT, 'draglab: baselines are immutable except for being superseded once by a new baseline; create a new version instead');
END;
CREATE TRIGGER consumer_baselines_immutable_delete BEFORE DELETE ON consumer_baselines
BEGIN
  SELECT RAISE(ABORT, 'draglab: baselines are never deleted (a replaced baseline is kept as superseded); create a new version instead');
END;
)sql";
}

}  // namespace

const std::vector<Migration>& migrations() {
  static const std::vector<Migration> all = {
      {1, "law versions, parameters, covariance, extra inputs; immutability triggers",
       migration_1()},
      {2, "law_events: append-only history of every law version", migration_2()},
      {3, "no REPLACE conflict resolution against published, retracted or history rows",
       migration_3()},
      {4, "drag campaigns, campaign units (measurements) and immutable datasets",
       migration_4()},
      {5, "consumer scenes, immutable consumer results and regression baselines",
       migration_5()},
  };
  return all;
}

int latest_schema_version() { return migrations().back().version; }

int read_schema_version(sqlite3* db) {
  Statement has_table(db,
                      "SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND "
                      "name = 'schema_version'");
  has_table.step();
  if (has_table.integer(0) == 0) return 0;
  Statement max_version(db, "SELECT coalesce(MAX(version), 0) FROM schema_version");
  max_version.step();
  return static_cast<int>(max_version.integer(0));
}

std::vector<int> apply_migrations(sqlite3* db, int from, int to, const std::string& code_version) {
  std::vector<int> applied;
  for (const Migration& m : migrations()) {
    if (m.version <= from || m.version > to) continue;
    exec(db, m.sql, "applying schema migration " + std::to_string(m.version));
    if (m.version == 1) {
      exec(db, "PRAGMA application_id = " + std::to_string(kApplicationId),
           "marking the file as a draglab database");
    }
    Statement record(db,
                     "INSERT INTO schema_version (version, description, applied_at, code_version) "
                     "VALUES (?1, ?2, ?3, ?4)");
    record.bind(1, m.version).bind(2, m.description).bind(3, utc_now_iso8601());
    record.bind(4, code_version);
    record.run();
    applied.push_back(m.version);
  }
  return applied;
}

std::vector<std::string> expected_triggers(int schema_version) {
  std::vector<std::string> names;
  if (schema_version >= 1) {
    names = {"laws_insert_as_draft", "laws_retract_only_published", "laws_retract_needs_reason",
             "laws_immutable_update", "laws_immutable_delete"};
    for (const char* table : {"law_parameters", "law_covariance", "law_extra_inputs"}) {
      for (const char* op : {"insert", "update", "delete"}) {
        names.push_back(std::string(table) + "_immutable_" + op);
      }
    }
  }
  if (schema_version >= 2) {
    for (const char* name :
         {"law_events_on_insert", "law_events_on_draft_update", "law_events_on_publish",
          "law_events_on_retract", "law_events_on_delete", "law_events_append_only_update",
          "law_events_append_only_delete"}) {
      names.push_back(name);
    }
  }
  if (schema_version >= 3) {
    for (const char* name :
         {"laws_no_replace_insert", "laws_no_replace_update", "law_events_no_replace_insert"}) {
      names.push_back(name);
    }
  }
  if (schema_version >= 4) {
    for (const char* name :
         {"campaigns_immutable_update", "campaigns_immutable_delete",
          "campaigns_no_replace_insert", "campaign_units_finished_immutable",
          "campaign_units_no_delete", "campaign_units_no_replace_insert",
          "datasets_immutable_update", "datasets_immutable_delete",
          "datasets_no_replace_insert"}) {
      names.push_back(name);
    }
  }
  if (schema_version >= 5) {
    for (const char* name :
         {"consumer_scenes_immutable_update", "consumer_scenes_immutable_delete",
          "consumer_scenes_no_replace_insert", "consumer_results_immutable_update",
          "consumer_results_immutable_delete", "consumer_results_no_replace_insert",
          "consumer_results_law_exists", "consumer_baselines_insert_checks",
          "consumer_baselines_no_replace_insert", "consumer_baselines_supersede_only",
          "consumer_baselines_immutable_delete"}) {
      names.push_back(name);
    }
  }
  return names;
}

}  // namespace db
}  // namespace draglab
