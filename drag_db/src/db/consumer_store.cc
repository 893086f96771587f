// Storage of consumer scenes, results and regression baselines (consumer_results.h) in the
// tables of schema version 5. The API checks what it can name clearly (unknown scene, law,
// result; an active baseline in the way) before writing; the triggers of migration 5 refuse the
// same for every other client.
#include <sqlite3.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "db/schema.h"
#include "db/sqlite_util.h"
#include "drag_db_version.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"

namespace draglab {
namespace {

using db::Statement;
using db::Transaction;

constexpr int kConsumerSchema = 5;

void require_consumer_schema(sqlite3* handle, const std::string& what) {
  const int version = db::read_schema_version(handle);
  if (version < kConsumerSchema) {
    throw Error(ErrorCode::kDatabase,
                "database '" + db::database_path(handle) + "' has schema version " +
                    std::to_string(version) + ", " + what + " needs version " +
                    std::to_string(kConsumerSchema) + ": run `draglab db migrate` on it");
  }
}

bool has_consumer_schema(sqlite3* handle) {
  return db::read_schema_version(handle) >= kConsumerSchema;
}

/// A stored JSON text; a damaged one is a database error naming `what`.
nlohmann::json parse_stored_json(const std::string& text, const std::string& what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(ErrorCode::kDatabase, what + ": not valid JSON (" + e.what() + ")");
  }
}

double json_number(const nlohmann::json& j, const char* key, const std::string& what) {
  if (!j.contains(key) || !j.at(key).is_number()) {
    throw Error(ErrorCode::kDatabase, what + ": field '" + key + "' is missing or not a number");
  }
  return j.at(key).get<double>();
}

constexpr const char* kSceneSelect =
    "SELECT hash, name, toml, registered_at, code_version FROM consumer_scenes ";

ConsumerScene scene_from_row(const Statement& row) {
  ConsumerScene s;
  s.hash = row.text(0);
  s.name = row.text(1);
  s.toml = row.text(2);
  s.registered_at = row.text(3);
  s.code_version = row.text(4);
  return s;
}

constexpr const char* kResultSelect =
    "SELECT id, scene_name, scene_hash, law_name, law_version, law_content_hash, code_version, "
    "created_at, metrics_json, result_json FROM consumer_results ";

ConsumerResult result_from_row(const Statement& row) {
  ConsumerResult r;
  r.id = row.integer(0);
  r.scene_name = row.text(1);
  r.scene_hash = row.text(2);
  r.law_name = row.text(3);
  r.law_version = static_cast<int>(row.integer(4));
  r.law_content_hash = row.text(5);
  r.code_version = row.text(6);
  r.created_at = row.text(7);
  r.metrics = ConsumerMetrics::FromJson(row.text(8));
  r.result_json = row.text(9);
  return r;
}

ConsumerResult get_result_in_transaction(sqlite3* handle, std::int64_t id) {
  Statement q(handle, std::string(kResultSelect) + "WHERE id = ?1");
  q.bind(1, id);
  if (!q.step()) {
    throw Error(ErrorCode::kNotFound, "no consumer result with id " + std::to_string(id) + " in '" +
                                          db::database_path(handle) + "'");
  }
  return result_from_row(q);
}

constexpr const char* kBaselineSelect =
    "SELECT id, scene_hash, law_name, result_id, tolerances_json, registered_at, superseded_at, "
    "supersedes FROM consumer_baselines ";

ConsumerBaseline baseline_from_row(sqlite3* handle, const Statement& row) {
  ConsumerBaseline b;
  b.id = row.integer(0);
  b.scene_hash = row.text(1);
  b.law_name = row.text(2);
  b.result_id = row.integer(3);
  b.tolerances = RegressionTolerances::FromJson(row.text(4));
  b.registered_at = row.text(5);
  b.superseded_at = row.is_null(6) ? "" : row.text(6);
  b.supersedes = row.is_null(7) ? 0 : row.integer(7);
  b.result = get_result_in_transaction(handle, b.result_id);
  return b;
}

std::optional<ConsumerBaseline> active_in_transaction(sqlite3* handle,
                                                      const std::string& scene_hash,
                                                      const std::string& law_name) {
  Statement q(handle, std::string(kBaselineSelect) +
                          "WHERE scene_hash = ?1 AND law_name = ?2 AND superseded_at IS NULL");
  q.bind(1, scene_hash).bind(2, law_name);
  if (!q.step()) return std::nullopt;
  return baseline_from_row(handle, q);
}

ConsumerBaseline insert_baseline(sqlite3* handle, const ConsumerResult& result,
                                 const RegressionTolerances& tolerances, std::int64_t supersedes) {
  Statement insert(handle,
                   "INSERT INTO consumer_baselines (scene_hash, law_name, result_id, "
                   "tolerances_json, registered_at, supersedes) VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
  insert.bind(1, result.scene_hash).bind(2, result.law_name).bind(3, result.id);
  insert.bind(4, tolerances.ToJson()).bind(5, db::utc_now_iso8601());
  if (supersedes > 0) {
    insert.bind(6, supersedes);
  } else {
    insert.bind_null(6);
  }
  insert.run();
  return *active_in_transaction(handle, result.scene_hash, result.law_name);
}

void check_tolerances(const RegressionTolerances& tolerances) {
  std::string why;
  if (!tolerances.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, why);
}

}  // namespace

std::string ConsumerMetrics::ToJson() const {
  nlohmann::json j = {{"umf_m_s", umf_m_s},
                      {"background_m_s", background_m_s},
                      {"t_ref_s", t_ref_s},
                      {"bubble_present", bubble_present},
                      {"max_bed_height_m", max_bed_height_m},
                      {"wall_s", wall_s}};
  j["bubble_diameter_m"] = bubble_present ? nlohmann::json(bubble_diameter_m) : nullptr;
  j["bubble_centroid_m"] = bubble_present ? nlohmann::json(bubble_centroid_m) : nullptr;
  return j.dump();
}

ConsumerMetrics ConsumerMetrics::FromJson(const std::string& text) {
  const std::string what = "consumer result metrics";
  const nlohmann::json j = parse_stored_json(text, what);
  ConsumerMetrics m;
  m.umf_m_s = json_number(j, "umf_m_s", what);
  m.background_m_s = json_number(j, "background_m_s", what);
  m.t_ref_s = json_number(j, "t_ref_s", what);
  m.max_bed_height_m = json_number(j, "max_bed_height_m", what);
  m.wall_s = json_number(j, "wall_s", what);
  if (!j.contains("bubble_present") || !j.at("bubble_present").is_boolean()) {
    throw Error(ErrorCode::kDatabase, what + ": field 'bubble_present' is missing or not a bool");
  }
  m.bubble_present = j.at("bubble_present").get<bool>();
  if (m.bubble_present) {
    m.bubble_diameter_m = json_number(j, "bubble_diameter_m", what);
    m.bubble_centroid_m = json_number(j, "bubble_centroid_m", what);
  }
  return m;
}

bool RegressionTolerances::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!(std::isfinite(diameter_abs_m) && diameter_abs_m >= 0.0)) {
    return fail("tolerances.diameter_abs_m = " + std::to_string(diameter_abs_m) +
                " is out of range (allowed: finite, >= 0 m)");
  }
  if (!(diameter_rel >= 0.0 && diameter_rel <= 10.0)) {
    return fail("tolerances.diameter_rel = " + std::to_string(diameter_rel) +
                " is out of range (allowed: [0, 10], a fraction of the baseline diameter)");
  }
  if (!(umf_rel >= 0.0 && umf_rel <= 10.0)) {
    return fail("tolerances.umf_rel = " + std::to_string(umf_rel) +
                " is out of range (allowed: [0, 10], a fraction of the baseline U_mf)");
  }
  return true;
}

std::string RegressionTolerances::ToJson() const {
  return nlohmann::json{
      {"diameter_abs_m", diameter_abs_m}, {"diameter_rel", diameter_rel}, {"umf_rel", umf_rel}}
      .dump();
}

RegressionTolerances RegressionTolerances::FromJson(const std::string& text) {
  const std::string what = "baseline tolerances";
  const nlohmann::json j = parse_stored_json(text, what);
  RegressionTolerances t;
  t.diameter_abs_m = json_number(j, "diameter_abs_m", what);
  t.diameter_rel = json_number(j, "diameter_rel", what);
  t.umf_rel = json_number(j, "umf_rel", what);
  return t;
}

ConsumerScene register_consumer_scene(Database& database, const std::string& name,
                                      const std::string& toml) {
  if (name.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "consumer scene: the name is empty");
  }
  if (toml.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "consumer scene '" + name + "': the text is empty");
  }
  sqlite3* handle = database.handle();
  const std::string hash = sha256_hex(toml);
  Transaction t(handle, Transaction::Kind::kWrite);
  require_consumer_schema(handle, "registering a scene");
  {
    Statement existing(handle, std::string(kSceneSelect) + "WHERE hash = ?1");
    existing.bind(1, hash);
    if (existing.step()) return scene_from_row(existing);  // same text: same scene
  }
  ConsumerScene scene{hash, name, toml, db::utc_now_iso8601(), kDragDbVersion};
  Statement insert(handle,
                   "INSERT INTO consumer_scenes (hash, name, toml, registered_at, code_version) "
                   "VALUES (?1, ?2, ?3, ?4, ?5)");
  insert.bind(1, scene.hash).bind(2, scene.name).bind(3, scene.toml);
  insert.bind(4, scene.registered_at).bind(5, scene.code_version);
  insert.run();
  t.commit();
  return scene;
}

std::vector<ConsumerScene> list_consumer_scenes(const Database& database) {
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kRead);
  if (!has_consumer_schema(handle)) return {};
  Statement q(handle, std::string(kSceneSelect) + "ORDER BY registered_at, rowid");
  std::vector<ConsumerScene> all;
  while (q.step()) all.push_back(scene_from_row(q));
  return all;
}

ConsumerScene get_consumer_scene(const Database& database, const std::string& hash_or_prefix) {
  const bool hex = !hash_or_prefix.empty() &&
                   hash_or_prefix.find_first_not_of("0123456789abcdef") == std::string::npos;
  if (!hex || hash_or_prefix.size() < 4) {
    throw Error(ErrorCode::kNotFound, "scene '" + hash_or_prefix +
                                          "': a scene is named by at least 4 lower-case hex "
                                          "digits of its hash (see `draglab regress list`)");
  }
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kRead);
  require_consumer_schema(handle, "reading a registered scene");
  Statement q(handle, std::string(kSceneSelect) + "WHERE hash >= ?1 AND hash < ?2 ORDER BY hash");
  q.bind(1, hash_or_prefix).bind(2, hash_or_prefix + "g");  // 'g' sorts after every hex digit
  std::vector<ConsumerScene> found;
  while (q.step()) found.push_back(scene_from_row(q));
  if (found.empty()) {
    throw Error(ErrorCode::kNotFound, "no registered scene '" + hash_or_prefix + "' in '" +
                                          database.path() + "' (see `draglab regress list`)");
  }
  if (found.size() > 1) {
    throw Error(ErrorCode::kNotFound, "scene prefix '" + hash_or_prefix + "' is ambiguous (" +
                                          std::to_string(found.size()) +
                                          " scenes): give more digits");
  }
  return found.front();
}

ConsumerResult store_consumer_result(Database& database, ConsumerResult result) {
  const std::string what =
      "consumer result of " + result.law_reference() + " on scene '" + result.scene_name + "'";
  const ConsumerMetrics& m = result.metrics;
  for (const auto& [field, value] : {std::pair<const char*, double>{"umf_m_s", m.umf_m_s},
                                     {"background_m_s", m.background_m_s},
                                     {"t_ref_s", m.t_ref_s},
                                     {"bubble_diameter_m", m.bubble_diameter_m},
                                     {"bubble_centroid_m", m.bubble_centroid_m},
                                     {"max_bed_height_m", m.max_bed_height_m},
                                     {"wall_s", m.wall_s}}) {
    if (!(std::isfinite(value) && value >= 0.0)) {
      throw Error(ErrorCode::kInvalidArgument, what + ": metrics." + field + " = " +
                                                   std::to_string(value) +
                                                   " is out of range (allowed: finite, >= 0)");
    }
  }
  if (!nlohmann::json::accept(result.result_json)) {
    throw Error(ErrorCode::kInvalidArgument, what + ": result_json is not valid JSON");
  }
  if (result.code_version.empty()) result.code_version = kDragDbVersion;
  if (result.created_at.empty()) result.created_at = db::utc_now_iso8601();
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kWrite);
  require_consumer_schema(handle, "storing a consumer result");
  {
    Statement scene(handle, "SELECT 1 FROM consumer_scenes WHERE hash = ?1");
    scene.bind(1, result.scene_hash);
    if (!scene.step()) {
      throw Error(ErrorCode::kNotFound, what + ": scene hash " + result.scene_hash +
                                            " is not registered (register the scene first)");
    }
  }
  {
    Statement law(handle, "SELECT content_hash FROM laws WHERE name = ?1 AND version = ?2");
    law.bind(1, result.law_name).bind(2, result.law_version);
    if (!law.step()) {
      throw Error(ErrorCode::kNotFound, what + ": law " + result.law_reference() + " is not in '" +
                                            database.path() + "'");
    }
    if (law.text(0) != result.law_content_hash) {
      throw Error(ErrorCode::kInvalidArgument,
                  what + ": law content hash " + result.law_content_hash.substr(0, 12) +
                      " is not the stored version's (" + law.text(0).substr(0, 12) +
                      "): the draft changed since it was run");
    }
  }
  Statement insert(handle,
                   "INSERT INTO consumer_results (scene_name, scene_hash, law_name, law_version, "
                   "law_content_hash, code_version, created_at, metrics_json, result_json) "
                   "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)");
  insert.bind(1, result.scene_name).bind(2, result.scene_hash).bind(3, result.law_name);
  insert.bind(4, result.law_version).bind(5, result.law_content_hash);
  insert.bind(6, result.code_version).bind(7, result.created_at);
  insert.bind(8, result.metrics.ToJson()).bind(9, result.result_json);
  insert.run();
  result.id = sqlite3_last_insert_rowid(handle);
  ConsumerResult stored = get_result_in_transaction(handle, result.id);
  t.commit();
  return stored;
}

ConsumerResult get_consumer_result(const Database& database, std::int64_t id) {
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kRead);
  require_consumer_schema(handle, "reading a consumer result");
  return get_result_in_transaction(handle, id);
}

std::vector<ConsumerResult> list_consumer_results(const Database& database,
                                                  const ConsumerResultFilter& filter) {
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kRead);
  if (!has_consumer_schema(handle)) return {};
  // Empty / zero filter values match everything (bound, never spliced into the SQL).
  Statement q(handle, std::string(kResultSelect) +
                          "WHERE (?1 = '' OR scene_hash = ?1) AND (?2 = '' OR law_name = ?2) "
                          "AND (?3 = 0 OR law_version = ?3) AND (?4 = '' OR law_content_hash = ?4) "
                          "ORDER BY id");
  q.bind(1, filter.scene_hash).bind(2, filter.law_name).bind(3, filter.law_version);
  q.bind(4, filter.law_content_hash);
  std::vector<ConsumerResult> all;
  while (q.step()) all.push_back(result_from_row(q));
  return all;
}

ConsumerBaseline register_consumer_baseline(Database& database, std::int64_t result_id,
                                            const RegressionTolerances& tolerances) {
  check_tolerances(tolerances);
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kWrite);
  require_consumer_schema(handle, "registering a baseline");
  const ConsumerResult result = get_result_in_transaction(handle, result_id);
  if (const auto active = active_in_transaction(handle, result.scene_hash, result.law_name)) {
    throw Error(ErrorCode::kImmutable,
                "scene '" + result.scene_name + "' has a baseline for law " + result.law_name +
                    " already (" + active->result.law_reference() + ", registered " +
                    active->registered_at +
                    "); replace it explicitly (draglab regress register --replace), which keeps "
                    "the old one as superseded");
  }
  ConsumerBaseline baseline = insert_baseline(handle, result, tolerances, 0);
  t.commit();
  return baseline;
}

ConsumerBaseline replace_consumer_baseline(Database& database, std::int64_t result_id,
                                           const RegressionTolerances& tolerances) {
  check_tolerances(tolerances);
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kWrite);
  require_consumer_schema(handle, "replacing a baseline");
  const ConsumerResult result = get_result_in_transaction(handle, result_id);
  std::int64_t old_id = 0;
  if (const auto active = active_in_transaction(handle, result.scene_hash, result.law_name)) {
    old_id = active->id;
    Statement supersede(handle, "UPDATE consumer_baselines SET superseded_at = ?1 WHERE id = ?2");
    supersede.bind(1, db::utc_now_iso8601()).bind(2, old_id);
    supersede.run();
  }
  ConsumerBaseline baseline = insert_baseline(handle, result, tolerances, old_id);
  t.commit();
  return baseline;
}

ConsumerBaseline store_consumer_baseline_run(Database& database, const std::string& scene_name,
                                             const std::string& scene_toml, ConsumerResult result,
                                             const RegressionTolerances& tolerances, bool replace) {
  check_tolerances(tolerances);
  sqlite3* handle = database.handle();
  // The calls below join this transaction: the scene, the result and the baseline are stored
  // together or not at all.
  Transaction t(handle, Transaction::Kind::kWrite);
  const ConsumerScene scene = register_consumer_scene(database, scene_name, scene_toml);
  if (result.scene_hash != scene.hash) {
    throw Error(ErrorCode::kInvalidArgument,
                "baseline of " + result.law_reference() + ": the result's scene hash " +
                    result.scene_hash.substr(0, 12) + " is not the hash of the scene text (" +
                    scene.hash.substr(0, 12) + ")");
  }
  if (result.id == 0) result = store_consumer_result(database, result);
  ConsumerBaseline baseline = replace ? replace_consumer_baseline(database, result.id, tolerances)
                                      : register_consumer_baseline(database, result.id, tolerances);
  t.commit();
  return baseline;
}

std::optional<ConsumerBaseline> active_consumer_baseline(const Database& database,
                                                         const std::string& scene_hash,
                                                         const std::string& law_name) {
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kRead);
  if (!has_consumer_schema(handle)) return std::nullopt;
  return active_in_transaction(handle, scene_hash, law_name);
}

std::vector<ConsumerBaseline> list_consumer_baselines(const Database& database,
                                                      bool include_superseded) {
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kRead);
  if (!has_consumer_schema(handle)) return {};
  Statement q(handle, std::string(kBaselineSelect) +
                          "WHERE ?1 OR superseded_at IS NULL ORDER BY scene_hash, law_name, id");
  q.bind(1, include_superseded ? 1 : 0);
  std::vector<ConsumerBaseline> all;
  while (q.step()) all.push_back(baseline_from_row(handle, q));
  return all;
}

}  // namespace draglab
