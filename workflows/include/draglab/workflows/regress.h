// draglab/workflows/regress.h: regression checks of consumer predictions against stored
// baselines (`draglab regress`, docs/scenes.md "Regression checks").
//
// A baseline (drag_db/consumer_results.h) fixes, for one registered scene and one law name, the
// result of one law version and the tolerances a later version must stay within. run_regression
// re-runs the registered scene (its stored TOML text, so exactly what was registered) with every
// version of the law newer than the baseline's (published ones; drafts on request) that has no
// stored result for that scene yet, stores each result, and compares, metric by metric:
//   - U_mf [m/s]: moved if |U - U_base| > umf_rel U_base;
//   - bubble at t_ref present / absent: moved if it appears or disappears;
//   - bubble diameter at t_ref [m] (both present): moved if |D - D_base| > diameter_abs_m +
//     diameter_rel D_base;
//   - the model's headline numbers (BedResult::headline, stored in the result JSON's "headline"
//     object; the DBM: hold-up, mean bubble diameter at the report heights, circulation), each
//     that the baseline's result has: mean_diameter_* as the bubble diameter, the others moved
//     if |x - x_base| > kHeadlineRelativeTolerance |x_base| (headline_tolerance). A number the
//     baseline has and the new result lacks has moved.
// For the DBM, whose `metrics` hold no jet bubble, "bubble at t_ref" is the time-averaged mean
// bubble diameter over the run (present when a bubble was sampled) and t_ref is 0.
// A version with a stored result for the scene (same law content hash) is compared without a new
// run. A run that fails (draglab::Error: law outside its validity box, solver instability) is
// reported as failed, not as moved, and nothing of it is stored. In single-law mode
// (RegressOptions::law = "NAME@V") that version is compared on every registered scene; where its
// law name has no baseline yet, its (published) result becomes the baseline.
// Limits: one run per (scene, version): the tolerances, not repeated runs, absorb the run-to-run
// scatter of the bubble (packing, chaotic particle motion; the DBM's injection phases); the
// headline tolerances are not stored with the baseline (RegressionTolerances has no field for
// them): they follow from the stored diameter tolerances and kHeadlineRelativeTolerance.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/consumer_results.h"

namespace draglab {
class Database;
namespace workflows {
using consumers::BedRunOptions;
using consumers::Scene;

/// Default tolerances of a baseline of `scene`: bubble diameter 2 gas cells (the larger cell
/// side) + 10 % of the baseline diameter, U_mf 1 %; a DBM scene: bubble diameter 10 % without a
/// cell part (its bubbles are Lagrangian volumes, not traced on the grid), U_mf 1 % (the reasons
/// are in regress.cc).
RegressionTolerances default_regression_tolerances(const Scene& scene);

/// Relative tolerance of a headline number that is not a bubble diameter (hold-up, circulation):
/// 0.1 (the reasons are in regress.cc).
inline constexpr double kHeadlineRelativeTolerance = 0.10;
/// Largest allowed |x - x_base| of the headline number `name`: a bubble diameter
/// ("mean_diameter_..."): diameter_abs_m + diameter_rel |x_base|; any other:
/// kHeadlineRelativeTolerance |x_base|.
double headline_tolerance(const std::string& name, double baseline,
                          const RegressionTolerances& tolerances);
/// The "headline" object of a stored result JSON (name, value; a null value is NaN), in the
/// object's (alphabetical) order; empty without one or for text that is not a JSON object.
std::vector<std::pair<std::string, double>> headline_of_result_json(const std::string& json);

/// One metric of a comparison.
struct MetricComparison {
  /// "umf_m_s", "bubble_present", "bubble_diameter_m", or a headline number's name.
  std::string metric;
  double baseline = 0.0;   ///< Baseline value (bubble_present: 1 or 0).
  double value = 0.0;      ///< Value of the checked version.
  double delta = 0.0;      ///< value - baseline.
  double tolerance = 0.0;  ///< Largest allowed |delta| (bubble_present: 0).
  bool moved = false;      ///< |delta| > tolerance.
};

/// Compares `value` with `baseline` metric by metric (the diameter only when both runs have a
/// bubble at t_ref).
std::vector<MetricComparison> compare_metrics(const ConsumerMetrics& baseline,
                                              const ConsumerMetrics& value,
                                              const RegressionTolerances& tolerances);
/// Compares the headline numbers of two stored result JSONs: one comparison per number of the
/// baseline (value NaN, moved, when the new result lacks it); none when the baseline has none.
std::vector<MetricComparison> compare_headline(const std::string& baseline_result_json,
                                               const std::string& value_result_json,
                                               const RegressionTolerances& tolerances);

enum class RegressOutcome {
  kOk,      ///< Every metric within its tolerance.
  kMoved,   ///< At least one metric moved beyond its tolerance.
  kFailed,  ///< The run failed (RegressEntry::error); nothing stored.
  /// The scene leaves the law's validity box (RegressEntry::error says where): the law cannot
  /// be used there, so there is nothing to compare; nothing stored. Not a move.
  kOutsideValidity,
  kBaselineRegistered,  ///< Single-law mode: no baseline existed; this result is it now.
  kNoBaseline,          ///< Single-law mode, draft or retracted version without a baseline.
};
/// "ok", "moved", "failed", "outside_validity", "baseline_registered", "no_baseline".
const char* to_string(RegressOutcome outcome);

/// One (scene, law version) of a regression check.
struct RegressEntry {
  std::string scene_name;
  std::string scene_hash;
  std::string law;           ///< name@version checked.
  std::string baseline_law;  ///< name@version of the baseline ("" without one).
  RegressOutcome outcome = RegressOutcome::kOk;
  bool ran = false;  ///< Run now; false: a stored result of the same scene and law content.
  std::int64_t result_id = 0;           ///< The stored result (0 when the run failed).
  std::int64_t baseline_result_id = 0;  ///< The baseline's result (0 without one).
  RegressionTolerances tolerances;      ///< Of the baseline (or of the one registered now).
  ConsumerMetrics metrics;              ///< Of the checked version (not set when failed).
  /// Its headline numbers (from its result JSON; empty for dpm and tfm, or when failed).
  std::vector<std::pair<std::string, double>> headline;
  std::vector<MetricComparison> comparisons;
  std::string error;                  ///< Why the run failed.
  std::vector<std::string> warnings;  ///< From loading the law (draft, retracted).
  double wall_s = 0.0;                ///< Of the run (0 when a stored result was used).
};

/// The outcome of run_regression / register_regression_baseline.
struct RegressSummary {
  std::vector<RegressEntry> entries;
  int runs = 0;         ///< Consumer runs done now.
  double wall_s = 0.0;  ///< Whole check.
  int count(RegressOutcome outcome) const;
  bool any_moved() const { return count(RegressOutcome::kMoved) > 0; }
  /// One line: counts per outcome.
  std::string BriefReport() const;
  /// Table: scene, law@v, baseline law@v0, metric, baseline, new, delta, tolerance, MOVED/ok;
  /// failed runs with their error; registered baselines.
  std::string FullReport() const;
};

/// What run_regression checks and how.
struct RegressOptions {
  /// "": every law name with a baseline, its versions newer than the baseline's. A reference
  /// ("NAME@V", any form Database::resolve takes): that version on the registered scenes.
  std::string law;
  bool include_drafts = false;  ///< Also check draft versions (published only by default).
  /// Only these registered scenes (full hashes); empty: all of them.
  std::vector<std::string> scene_hashes;
  /// Tolerances of baselines registered here (single-law mode, register_regression_baseline);
  /// a negative value: the scene's default (default_regression_tolerances).
  double tol_diameter_abs_m = -1.0;
  double tol_diameter_rel = -1.0;
  double tol_umf_rel = -1.0;
  /// register_regression_baseline: replace an active baseline (kept as superseded).
  bool replace_baseline = false;
  BedRunOptions run;  ///< Run controls of every model (defaults: the scene as registered).
  /// On failure *error names the field and its allowed range.
  bool IsValid(std::string* error) const;
};

/// The tolerances a baseline of `scene` gets under `options` (overrides, else defaults).
RegressionTolerances baseline_tolerances(const Scene& scene, const RegressOptions& options);

/// Progress: run index (0-based) among `runs` planned runs, the fraction of that run, a stage.
using RegressProgress =
    std::function<void(int run, int runs, double fraction, const std::string& stage)>;

/// Runs the check (see the file comment) and stores every successful run's result. Throws
/// Error(kInvalidArgument) for invalid options or a draft without include_drafts,
/// Error(kNotFound) for an unknown law reference; failures of single runs are entries.
RegressSummary run_regression(Database& db, const RegressOptions& options,
                              const RegressProgress& progress = nullptr);

/// `draglab regress register`: runs the published version options.law on `scene` (a stored
/// result of the same scene and law content is reused), then registers the scene, stores the
/// result and makes it the baseline of (scene, law name) in one transaction, with the options'
/// tolerances. An active baseline is replaced only with options.replace_baseline (else
/// Error(kImmutable), before any run). A failing run throws its Error; nothing is stored.
RegressSummary register_regression_baseline(Database& db, const Scene& scene,
                                            const RegressOptions& options,
                                            const RegressProgress& progress = nullptr);

}  // namespace workflows
}  // namespace draglab
