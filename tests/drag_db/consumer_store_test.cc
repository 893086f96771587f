// Consumer scenes, results and regression baselines in the database (consumer_results.h,
// schema version 5).
//
// Set-up: a fresh database file per test (seeded with the literature laws, so ergun@1 exists);
// results are hand-written (no consumer run: this is storage only).
// What is checked, and the reference for each:
//  - a file written with schema 4 (campaigns and datasets, no consumer tables) migrates to 5 on
//    open, its laws and datasets survive, check() finds every trigger, and the consumer API on a
//    read-only open of the old file says to run `draglab db migrate` (docs/database.md);
//  - a store/load round trip returns every metric bit for bit (JSON doubles round-trip), a
//    missing bubble is null in the stored JSON, registering the same scene text twice returns
//    the first registration, and filters select by scene, law version and content hash;
//  - invalid input (unregistered scene, unknown law, a content hash that is not the stored
//    version's, a NaN metric, invalid tolerances) is refused with the field named and nothing
//    is written;
//  - the rows are immutable for every client (sqlite3 C API: UPDATE, DELETE, INSERT OR REPLACE
//    of scenes, results and baselines; a baseline naming another law's result; re-activating a
//    superseded baseline);
//  - baselines: a second registration is refused (kImmutable) until replaced explicitly; a
//    replacement keeps the old row as superseded, names it, and leaves one active row; storing a
//    baseline run is all-or-nothing (scene, result and baseline).
#include "draglab/drag_db/consumer_results.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

namespace draglab {
namespace {

namespace fs = std::filesystem;

using TempDir = test::TempDir;

template <typename F>
Error error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no draglab::Error thrown";
  return Error(ErrorCode::kOk, "");
}

const char* kSceneText = "[scene]\nname = \"tiny\"\n# a scene text; storage does not parse it\n";

ConsumerResult sample_result(const Database& db, const std::string& scene_hash,
                             double scale = 1.0) {
  const LawRecord ergun = db.resolve("ergun@1");
  ConsumerResult r;
  r.scene_name = "tiny";
  r.scene_hash = scene_hash;
  r.law_name = ergun.name;
  r.law_version = ergun.version;
  r.law_content_hash = ergun.content_hash;
  r.metrics.umf_m_s = 1.2345678901234567 * scale;
  r.metrics.background_m_s = 1.3 * scale;
  r.metrics.t_ref_s = 0.05;
  r.metrics.bubble_present = true;
  r.metrics.bubble_diameter_m = 0.021234567890123456;
  r.metrics.bubble_centroid_m = 0.0317;
  r.metrics.max_bed_height_m = 0.0456;
  r.metrics.wall_s = 3.5;
  r.result_json = R"({"solver": "dpm", "series": [1, 2, 3]})";
  return r;
}

std::int64_t count_rows(const Database& db, const std::string& table) {
  sqlite3_stmt* stmt = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db.handle(), ("SELECT count(*) FROM " + table).c_str(), -1, &stmt,
                               nullptr),
            SQLITE_OK);
  sqlite3_step(stmt);
  const std::int64_t n = sqlite3_column_int64(stmt, 0);
  sqlite3_finalize(stmt);
  return n;
}

// Runs `sql` through the plain sqlite3 C API (another client) and returns its error message
// ("" if it succeeded).
std::string exec_raw(const std::string& path, const std::string& sql) {
  sqlite3* raw = nullptr;
  EXPECT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  char* message = nullptr;
  const int rc = sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, &message);
  std::string text = rc == SQLITE_OK ? "" : (message ? message : "error without message");
  sqlite3_free(message);
  sqlite3_close(raw);
  return text;
}

TEST(ConsumerStore, SchemaFourFileIsMigratedAndTheConsumerApiNeedsIt) {
  TempDir dir;
  const std::string path = dir.file("v4.db");
  std::string dataset_id;
  {
    // What a schema-4 draglab wrote: laws and a dataset, no consumer tables.
    DatabaseOptions raw;
    raw.migrate = false;
    Database db(path, raw);
    EXPECT_EQ(db.migrate(4), (std::vector<int>{1, 2, 3, 4}));
    db.seed_literature();
    Dataset d;
    d.name = "old";
    DatasetPoint p;
    p.phi = 0.3;
    p.re = 1.0;
    p.re_target = 1.0;
    p.F = 5.0;
    p.F_uncertainty = 0.1;
    d.points = {p};
    dataset_id = store_dataset(db, d).id;
  }
  {
    DatabaseOptions ro;
    ro.read_only = true;
    Database db(path, ro);
    EXPECT_EQ(db.schema_version(), 4);
    EXPECT_TRUE(list_consumer_scenes(db).empty());  // lists read an old file as empty
    EXPECT_TRUE(list_consumer_baselines(db).empty());
    const Error e = error_of([&] { get_consumer_result(db, 1); });
    EXPECT_EQ(e.code(), ErrorCode::kDatabase);
    EXPECT_NE(std::string(e.what()).find("draglab db migrate"), std::string::npos) << e.what();
  }
  Database db(path);  // current code: migrates
  EXPECT_EQ(db.schema_version(), Database::current_schema_version());
  EXPECT_GE(db.schema_version(), 5);
  EXPECT_EQ(load_dataset(db, dataset_id).points.size(), 1u);
  EXPECT_NO_THROW(db.load("ergun@1"));
  const DatabaseCheckReport report = db.check();
  EXPECT_TRUE(report.ok) << report.FullReport();
  const ConsumerScene scene = register_consumer_scene(db, "tiny", kSceneText);
  const ConsumerResult stored = store_consumer_result(db, sample_result(db, scene.hash));
  EXPECT_EQ(get_consumer_result(db, stored.id).metrics.umf_m_s, stored.metrics.umf_m_s);

  // A dropped guard is reported by check().
  EXPECT_EQ(exec_raw(path, "DROP TRIGGER consumer_results_immutable_update"), "");
  const DatabaseCheckReport after = db.check();
  EXPECT_FALSE(after.ok);
  EXPECT_NE(after.FullReport().find("consumer_results_immutable_update"), std::string::npos)
      << after.FullReport();
}

TEST(ConsumerStore, RoundTripIsExactAndScenesAreIdentifiedByTheirText) {
  TempDir dir;
  Database db(dir.file("c.db"));
  const ConsumerScene scene = register_consumer_scene(db, "tiny", kSceneText);
  EXPECT_EQ(scene.hash, sha256_hex(kSceneText));
  EXPECT_EQ(scene.toml, kSceneText);
  EXPECT_FALSE(scene.code_version.empty());
  const ConsumerScene again = register_consumer_scene(db, "tiny", kSceneText);
  EXPECT_EQ(again.registered_at, scene.registered_at);
  EXPECT_EQ(list_consumer_scenes(db).size(), 1u);
  EXPECT_EQ(get_consumer_scene(db, scene.hash.substr(0, 6)).toml, kSceneText);
  EXPECT_EQ(error_of([&] { get_consumer_scene(db, "zz"); }).code(), ErrorCode::kNotFound);

  const ConsumerResult original = sample_result(db, scene.hash);
  const ConsumerResult stored = store_consumer_result(db, original);
  EXPECT_GT(stored.id, 0);
  EXPECT_FALSE(stored.created_at.empty());
  EXPECT_FALSE(stored.code_version.empty());
  const ConsumerResult loaded = get_consumer_result(db, stored.id);
  EXPECT_EQ(loaded.metrics.umf_m_s, original.metrics.umf_m_s);  // bit for bit
  EXPECT_EQ(loaded.metrics.bubble_diameter_m, original.metrics.bubble_diameter_m);
  EXPECT_EQ(loaded.metrics.bubble_centroid_m, original.metrics.bubble_centroid_m);
  EXPECT_EQ(loaded.metrics.max_bed_height_m, original.metrics.max_bed_height_m);
  EXPECT_EQ(loaded.metrics.background_m_s, original.metrics.background_m_s);
  EXPECT_TRUE(loaded.metrics.bubble_present);
  EXPECT_EQ(loaded.result_json, original.result_json);
  EXPECT_EQ(loaded.law_reference(), "ergun@1");

  // No bubble: null in the stored JSON, absent after loading.
  ConsumerResult none = original;
  none.metrics.bubble_present = false;
  none.metrics.bubble_diameter_m = 0.0;
  none.metrics.bubble_centroid_m = 0.0;
  const ConsumerResult stored_none = store_consumer_result(db, none);
  EXPECT_FALSE(get_consumer_result(db, stored_none.id).metrics.bubble_present);
  {
    sqlite3_stmt* stmt = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db.handle(),
                                 "SELECT json_type(metrics_json, '$.bubble_diameter_m') FROM "
                                 "consumer_results WHERE id = ?1",
                                 -1, &stmt, nullptr),
              SQLITE_OK);
    sqlite3_bind_int64(stmt, 1, stored_none.id);
    ASSERT_EQ(sqlite3_step(stmt), SQLITE_ROW);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0))), "null");
    sqlite3_finalize(stmt);
  }

  // Filters.
  EXPECT_EQ(list_consumer_results(db).size(), 2u);
  ConsumerResultFilter filter;
  filter.scene_hash = scene.hash;
  filter.law_name = "ergun";
  filter.law_version = 1;
  filter.law_content_hash = original.law_content_hash;
  EXPECT_EQ(list_consumer_results(db, filter).size(), 2u);
  filter.law_version = 2;
  EXPECT_TRUE(list_consumer_results(db, filter).empty());
  filter.law_version = 0;
  filter.law_content_hash = std::string(64, '0');
  EXPECT_TRUE(list_consumer_results(db, filter).empty());
  EXPECT_EQ(error_of([&] { get_consumer_result(db, 999); }).code(), ErrorCode::kNotFound);
}

TEST(ConsumerStore, InvalidResultsAreRefusedAndNothingIsWritten) {
  TempDir dir;
  Database db(dir.file("c.db"));
  const ConsumerScene scene = register_consumer_scene(db, "tiny", kSceneText);
  auto expect_refused = [&](ConsumerResult r, ErrorCode code, const std::string& names) {
    const Error e = error_of([&] { store_consumer_result(db, r); });
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(names), std::string::npos) << e.what();
  };
  ConsumerResult r = sample_result(db, std::string(64, 'a'));
  expect_refused(r, ErrorCode::kNotFound, "not registered");
  r = sample_result(db, scene.hash);
  r.law_version = 99;
  expect_refused(r, ErrorCode::kNotFound, "ergun@99");
  r = sample_result(db, scene.hash);
  r.law_content_hash = std::string(64, 'b');
  expect_refused(r, ErrorCode::kInvalidArgument, "content hash");
  r = sample_result(db, scene.hash);
  r.metrics.bubble_diameter_m = std::numeric_limits<double>::quiet_NaN();
  expect_refused(r, ErrorCode::kInvalidArgument, "bubble_diameter_m");
  r = sample_result(db, scene.hash);
  r.metrics.umf_m_s = -1.0;
  expect_refused(r, ErrorCode::kInvalidArgument, "umf_m_s");
  r = sample_result(db, scene.hash);
  r.result_json = "{not json";
  expect_refused(r, ErrorCode::kInvalidArgument, "result_json");
  EXPECT_EQ(count_rows(db, "consumer_results"), 0);

  const ConsumerResult stored = store_consumer_result(db, sample_result(db, scene.hash));
  RegressionTolerances bad;
  bad.diameter_abs_m = -0.01;
  const Error e = error_of([&] { register_consumer_baseline(db, stored.id, bad); });
  EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(std::string(e.what()).find("diameter_abs_m"), std::string::npos) << e.what();
  bad = RegressionTolerances();
  bad.umf_rel = 11.0;
  EXPECT_EQ(error_of([&] { register_consumer_baseline(db, stored.id, bad); }).code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(error_of([&] { register_consumer_baseline(db, 999, RegressionTolerances()); }).code(),
            ErrorCode::kNotFound);
  EXPECT_EQ(count_rows(db, "consumer_baselines"), 0);
}

TEST(ConsumerStore, RowsAreImmutableForEveryClient) {
  TempDir dir;
  const std::string path = dir.file("c.db");
  std::int64_t result_id = 0;
  {
    Database db(path);
    const ConsumerScene scene = register_consumer_scene(db, "tiny", kSceneText);
    result_id = store_consumer_result(db, sample_result(db, scene.hash)).id;
    const ConsumerResult second = store_consumer_result(db, sample_result(db, scene.hash, 2.0));
    register_consumer_baseline(db, result_id, RegressionTolerances());
    replace_consumer_baseline(db, second.id, RegressionTolerances());  // row 1 superseded
  }
  const std::string all_result_columns =
      "id, scene_name, scene_hash, law_name, law_version, law_content_hash, code_version, "
      "created_at, metrics_json, result_json";
  for (const std::string& sql : std::vector<std::string>{
           "UPDATE consumer_results SET metrics_json = '{}'",
           "DELETE FROM consumer_results",
           "INSERT OR REPLACE INTO consumer_results (" + all_result_columns + ") SELECT " +
               all_result_columns + " FROM consumer_results WHERE id = 1",
           std::string("UPDATE consumer_scenes SET toml = 'x'"),
           std::string("DELETE FROM consumer_scenes"),
           std::string("INSERT OR REPLACE INTO consumer_scenes SELECT hash, 'x', toml, "
                       "registered_at, code_version FROM consumer_scenes"),
           std::string("UPDATE consumer_baselines SET tolerances_json = '{}' WHERE id = 2"),
           std::string("UPDATE consumer_baselines SET superseded_at = NULL WHERE id = 1"),
           std::string("DELETE FROM consumer_baselines"),
           // A second active baseline by REPLACE would silently delete the active one.
           std::string("INSERT OR REPLACE INTO consumer_baselines (scene_hash, law_name, "
                       "result_id, tolerances_json, registered_at) SELECT scene_hash, law_name, "
                       "1, tolerances_json, registered_at FROM consumer_baselines WHERE id = 2"),
       }) {
    const std::string message = exec_raw(path, sql);
    EXPECT_FALSE(message.empty()) << "not refused: " << sql;
    EXPECT_NE(message.find("create a new version instead"), std::string::npos) << message;
  }
  // Integrity guards: a result naming a law content that is not stored, a baseline naming a
  // result of another law.
  EXPECT_NE(exec_raw(path, "INSERT INTO consumer_results (" + all_result_columns +
                               ") SELECT NULL, scene_name, scene_hash, law_name, law_version, "
                               "'" +
                               std::string(64, 'c') +
                               "', code_version, created_at, metrics_json, result_json FROM "
                               "consumer_results WHERE id = 1")
                .find("current content hash"),
            std::string::npos);
  EXPECT_NE(exec_raw(path,
                     "INSERT INTO consumer_baselines (scene_hash, law_name, result_id, "
                     "tolerances_json, registered_at) SELECT scene_hash, 'bvk2007', 1, "
                     "tolerances_json, registered_at FROM consumer_baselines WHERE id = 2")
                .find("names a result of its own scene and law name"),
            std::string::npos);

  Database db(path);
  EXPECT_EQ(count_rows(db, "consumer_results"), 2);
  EXPECT_EQ(count_rows(db, "consumer_scenes"), 1);
  EXPECT_EQ(count_rows(db, "consumer_baselines"), 2);
  EXPECT_EQ(get_consumer_result(db, result_id).scene_name, "tiny");
  EXPECT_EQ(list_consumer_baselines(db).size(), 1u);
}

TEST(ConsumerStore, BaselinesAreReplacedOnlyExplicitlyAndKeepTheirHistory) {
  TempDir dir;
  Database db(dir.file("c.db"));
  const ConsumerScene scene = register_consumer_scene(db, "tiny", kSceneText);
  const ConsumerResult first = store_consumer_result(db, sample_result(db, scene.hash));
  const ConsumerResult second = store_consumer_result(db, sample_result(db, scene.hash, 1.5));
  RegressionTolerances tol;
  tol.diameter_abs_m = 0.015;
  tol.diameter_rel = 0.1;
  tol.umf_rel = 0.01;

  EXPECT_FALSE(active_consumer_baseline(db, scene.hash, "ergun").has_value());
  const ConsumerBaseline b1 = register_consumer_baseline(db, first.id, tol);
  EXPECT_TRUE(b1.active());
  EXPECT_EQ(b1.result.id, first.id);
  EXPECT_EQ(b1.tolerances.diameter_abs_m, 0.015);
  EXPECT_EQ(b1.supersedes, 0);

  // A second registration is refused and changes nothing.
  const Error e = error_of([&] { register_consumer_baseline(db, second.id, tol); });
  EXPECT_EQ(e.code(), ErrorCode::kImmutable);
  EXPECT_NE(std::string(e.what()).find("replace it explicitly"), std::string::npos) << e.what();
  EXPECT_EQ(active_consumer_baseline(db, scene.hash, "ergun")->result_id, first.id);

  // The explicit replacement keeps the old baseline as superseded.
  tol.umf_rel = 0.02;
  const ConsumerBaseline b2 = replace_consumer_baseline(db, second.id, tol);
  EXPECT_TRUE(b2.active());
  EXPECT_EQ(b2.supersedes, b1.id);
  EXPECT_EQ(b2.tolerances.umf_rel, 0.02);
  const std::optional<ConsumerBaseline> active = active_consumer_baseline(db, scene.hash, "ergun");
  ASSERT_TRUE(active.has_value());
  EXPECT_EQ(active->id, b2.id);
  EXPECT_EQ(active->result.metrics.umf_m_s, second.metrics.umf_m_s);
  const std::vector<ConsumerBaseline> history = list_consumer_baselines(db, true);
  ASSERT_EQ(history.size(), 2u);
  EXPECT_EQ(history[0].id, b1.id);
  EXPECT_FALSE(history[0].active());
  EXPECT_FALSE(history[0].superseded_at.empty());
  EXPECT_EQ(list_consumer_baselines(db).size(), 1u);

  // store_consumer_baseline_run is all or nothing: with an active baseline and no replace, the
  // new scene and result are not stored either.
  const std::string other_scene = std::string(kSceneText) + "# another scene\n";
  ConsumerResult r = sample_result(db, sha256_hex(other_scene));
  store_consumer_baseline_run(db, "tiny2", other_scene, r, tol, false);  // first: fine
  EXPECT_EQ(count_rows(db, "consumer_scenes"), 2);
  const std::int64_t results_before = count_rows(db, "consumer_results");
  const std::string third_scene = std::string(kSceneText) + "# a third scene\n";
  r = sample_result(db, sha256_hex(third_scene));
  RegressionTolerances bad = tol;
  bad.diameter_rel = -1.0;
  EXPECT_EQ(error_of([&] {
              store_consumer_baseline_run(db, "tiny3", third_scene, r, bad, false);
            }).code(),
            ErrorCode::kInvalidArgument);
  r.scene_hash = std::string(64, 'd');  // not the hash of the text
  EXPECT_EQ(error_of([&] {
              store_consumer_baseline_run(db, "tiny3", third_scene, r, tol, false);
            }).code(),
            ErrorCode::kInvalidArgument);
  r = sample_result(db, sha256_hex(other_scene));
  EXPECT_EQ(error_of([&] {
              store_consumer_baseline_run(db, "tiny2", other_scene, r, tol, false);
            }).code(),
            ErrorCode::kImmutable);
  EXPECT_EQ(count_rows(db, "consumer_scenes"), 2);
  EXPECT_EQ(count_rows(db, "consumer_results"), results_before);
  EXPECT_EQ(count_rows(db, "consumer_baselines"), 3);
  // With replace, it goes through and supersedes.
  const ConsumerBaseline b4 = store_consumer_baseline_run(db, "tiny2", other_scene, r, tol, true);
  EXPECT_GT(b4.supersedes, 0);
  EXPECT_EQ(count_rows(db, "consumer_results"), results_before + 1);
}

}  // namespace
}  // namespace draglab
