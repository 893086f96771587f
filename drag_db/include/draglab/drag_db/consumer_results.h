// draglab/drag_db/consumer_results.h: consumer runs stored in the database, and the baselines
// `draglab regress` compares new law versions against.
//
// Three kinds of rows (schema version 5, docs/database.md):
//  - ConsumerScene: a registered scene file (TOML text, identified by its SHA-256, the same hash
//    as consumers::Scene::hash()). The text is stored so that a regression check re-runs exactly
//    what was registered, whatever happened to the file since.
//  - ConsumerResult: what one consumer run (scene x law name@version) predicted: the metrics a
//    regression compares (U_mf, bubble at t_ref, bed height; SI units) plus the full result as
//    JSON, with the law's content hash and the code version that ran it. Immutable.
//  - ConsumerBaseline: for one (scene, law name), the result new versions of that law are compared
//    with and the tolerances of the comparison. At most one active baseline per (scene, law
//    name); replacing it is explicit (replace_consumer_baseline) and keeps the old one, marked
//    superseded, as history.
// Immutability is enforced by SQL triggers for every client (UPDATE, DELETE and REPLACE are
// refused with Error(kImmutable) through this API). Every function is one transaction: nothing is
// half-written. Storage: drag_db/src/db/consumer_store.cc. The consumers module runs the scenes
// and decides what moved (draglab/workflows/regress.h); this header only stores and reads.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "draglab/drag_db/law.h"

namespace draglab {
class Database;

/// A registered scene: its TOML text and the SHA-256 of that text.
struct ConsumerScene {
  std::string hash;           ///< SHA-256 (64 hex digits) of `toml`.
  std::string name;           ///< The scene's [scene] name.
  std::string toml;           ///< The scene file's text, as registered.
  std::string registered_at;  ///< ISO 8601 UTC.
  std::string code_version;   ///< draglab version that registered it.
};

/// The numbers a regression check compares, from one run. SI units.
struct ConsumerMetrics {
  double umf_m_s = 0.0;            ///< The law's minimum fluidization velocity (superficial).
  double background_m_s = 0.0;     ///< Background superficial velocity used.
  double t_ref_s = 0.0;            ///< Snapshot time after the jet start.
  bool bubble_present = false;     ///< A bubble was found at t_ref.
  double bubble_diameter_m = 0.0;  ///< Equivalent diameter at t_ref (0 when absent).
  double bubble_centroid_m = 0.0;  ///< Height of the bubble centroid at t_ref (0 when absent).
  double max_bed_height_m = 0.0;   ///< Highest bed surface over the run's samples.
  double wall_s = 0.0;             ///< Run time (not compared: machine dependent).
  /// JSON object; bubble_diameter_m and bubble_centroid_m are null when there is no bubble.
  std::string ToJson() const;
  /// Parses ToJson's form; throws Error(kDatabase) naming a missing or mistyped field.
  static ConsumerMetrics FromJson(const std::string& json);
};

/// One stored consumer run.
struct ConsumerResult {
  std::int64_t id = 0;  ///< Assigned when stored.
  std::string scene_name;
  std::string scene_hash;  ///< Must be a registered scene.
  std::string law_name;
  int law_version = 0;
  std::string law_content_hash;  ///< Content hash of the law version that ran (64 hex digits).
  std::string code_version;      ///< Set when stored if empty.
  std::string created_at;        ///< Set when stored if empty (ISO 8601 UTC).
  ConsumerMetrics metrics;
  std::string result_json = "{}";  ///< The full result (consumer specific JSON object).
  std::string law_reference() const { return LawReference::Format(law_name, law_version); }
};

/// Tolerances of a regression comparison. A prediction has moved when
/// |D_new - D_base| > diameter_abs_m + diameter_rel |D_base|, or |U_new - U_base| > umf_rel
/// |U_base|, or a bubble appears or disappears at t_ref.
struct RegressionTolerances {
  double diameter_abs_m = 0.0;  ///< [m], finite, >= 0.
  double diameter_rel = 0.1;    ///< Fraction of the baseline diameter, [0, 10].
  double umf_rel = 0.01;        ///< Fraction of the baseline U_mf, [0, 10].
  /// On failure *error names the field and its allowed range.
  bool IsValid(std::string* error) const;
  std::string ToJson() const;
  static RegressionTolerances FromJson(const std::string& json);
};

/// The result a (scene, law name) is compared against.
struct ConsumerBaseline {
  std::int64_t id = 0;
  std::string scene_hash;
  std::string law_name;
  std::int64_t result_id = 0;
  RegressionTolerances tolerances;
  std::string registered_at;
  std::string superseded_at;    ///< Empty while active.
  std::int64_t supersedes = 0;  ///< Id of the baseline this one replaced (0: none).
  ConsumerResult result;        ///< The baseline's result (loaded with it).
  bool active() const { return superseded_at.empty(); }
};

/// Which results list_consumer_results returns (empty / 0: any).
struct ConsumerResultFilter {
  std::string scene_hash;
  std::string law_name;
  int law_version = 0;
  std::string law_content_hash;
};

/// Stores a scene's text (hash = SHA-256 of `toml`) unless it is registered already; returns the
/// stored row either way. `name` must be non-empty. Throws Error(kInvalidArgument) for an empty
/// name or text, Error(kDatabase) for a schema older than 5 (run `draglab db migrate`).
ConsumerScene register_consumer_scene(Database& db, const std::string& name,
                                      const std::string& toml);
/// All registered scenes, oldest first.
std::vector<ConsumerScene> list_consumer_scenes(const Database& db);
/// By hash or unique hash prefix (at least 4 hex digits); Error(kNotFound) otherwise.
ConsumerScene get_consumer_scene(const Database& db, const std::string& hash_or_prefix);

/// Stores a result (id, and created_at / code_version when empty, are set) and returns it.
/// Checks first: the scene is registered, the law version exists with that content hash, the
/// metrics are finite and non-negative, result_json is valid JSON (Error(kInvalidArgument) or
/// kNotFound naming what is wrong).
ConsumerResult store_consumer_result(Database& db, ConsumerResult result);
/// One result by id; Error(kNotFound) if there is none.
ConsumerResult get_consumer_result(const Database& db, std::int64_t id);
/// Results matching the filter, oldest first (by id).
std::vector<ConsumerResult> list_consumer_results(const Database& db,
                                                  const ConsumerResultFilter& filter = {});

/// Makes `result_id` the first baseline of its (scene, law name), with `tolerances`. Throws
/// Error(kImmutable) if that pair has an active baseline (replace it explicitly with
/// replace_consumer_baseline), Error(kNotFound) for an unknown result, Error(kInvalidArgument)
/// for invalid tolerances.
ConsumerBaseline register_consumer_baseline(Database& db, std::int64_t result_id,
                                            const RegressionTolerances& tolerances);
/// Replaces the active baseline of the result's (scene, law name) by `result_id` in one
/// transaction: the old one is marked superseded (kept, with the time) and the new one names it.
/// Works like register_consumer_baseline when there is none.
ConsumerBaseline replace_consumer_baseline(Database& db, std::int64_t result_id,
                                           const RegressionTolerances& tolerances);
/// Registers the scene (if new), stores `result` (unless it is stored already: id > 0) and makes
/// it the active baseline of its (scene, law name), all in one transaction: on any error nothing
/// is stored. An active baseline is replaced (kept as superseded) only if `replace`; otherwise
/// Error(kImmutable) names it.
ConsumerBaseline store_consumer_baseline_run(Database& db, const std::string& scene_name,
                                             const std::string& scene_toml, ConsumerResult result,
                                             const RegressionTolerances& tolerances, bool replace);
/// The active baseline of (scene, law name), if any.
std::optional<ConsumerBaseline> active_consumer_baseline(const Database& db,
                                                         const std::string& scene_hash,
                                                         const std::string& law_name);
/// Baselines (active only, or with the superseded ones), ordered by scene, law name, id.
std::vector<ConsumerBaseline> list_consumer_baselines(const Database& db,
                                                      bool include_superseded = false);

}  // namespace draglab
