// draglab/workflows/bed_results.h: the JSON forms of bed-model results, one serializer each,
// shared by every command and program that prints or stores them:
//  - a scene run (`draglab scene run --json`): the model's full result plus the stored result id
//    and the run's numerical uncertainty;
//  - a regression check (`draglab regress --json`, the end of `draglab pipeline`);
//  - the sensitivity bundle (DIR/sensitivity.json, format "draglab_sensitivity") and the
//    work-precision bundle (DIR/work_precision.json, format "draglab_work_precision") that
//    scripts/draglab_fig4.py draws from. docs/scenes.md describes the bundles' fields.
// Lengths in m, times in s, velocities in m/s; a number that is not finite is written as null.
#pragma once

#include <cstdint>

#include <nlohmann/json.hpp>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/workflows/regress.h"
#include "draglab/workflows/sensitivity.h"

namespace draglab {
namespace workflows {

constexpr const char* kSensitivityBundleFormat = "draglab_sensitivity";
constexpr const char* kWorkPrecisionBundleFormat = "draglab_work_precision";

/// x, or null when x is not finite.
nlohmann::json number_or_null(double x);

/// {diameter_abs_m, diameter_rel, umf_rel}.
nlohmann::json tolerances_json(const RegressionTolerances& t);
/// {umf_m_s, background_m_s, t_ref_s, bubble_present, bubble_diameter_m, bubble_centroid_m
///  (null without a bubble), max_bed_height_m, wall_s}.
nlohmann::json metrics_json(const ConsumerMetrics& m);
/// Headline numbers as an object by name (null for a value that is not finite).
nlohmann::json headline_json(const workflows::HeadlineNumbers& numbers);

/// The numerical uncertainty of one run and how it was estimated: the model's own estimate
/// where it has one (the DBM's batch means of the hold-up), else one gas cell (the larger side)
/// on the bubble boundary (null without a bubble); the packing-realization spread is not in it.
struct RunUncertainty {
  double value = -1.0;  ///< negative: none (no bubble)
  std::string method;
};
RunUncertainty run_uncertainty(const consumers::Scene& scene, const consumers::BedResult& r);

/// `scene run --json`: the model's full result (r.result_json) with "result_id" (null when not
/// stored), "model", "numerical_uncertainty" and "numerical_uncertainty_method".
nlohmann::json scene_run_json(const consumers::Scene& scene, const consumers::BedResult& r,
                              std::int64_t result_id);

/// {"moved", "ok", "failed", "outside_validity", "baselines_registered", "no_baseline", "runs",
///  "wall_s", "entries": [{scene, scene_hash, law, baseline, outcome, ran, result_id,
///  baseline_result_id, tolerances, metrics, headline, comparisons: [{metric, baseline, new,
///  delta, tolerance, moved}], error, warnings, wall_s}]}.
nlohmann::json regress_json(const workflows::RegressSummary& summary);

/// The sensitivity bundle: scene, t_ref, uncertainty method and grids, packings, per law the
/// bubble diameter (mean, estimate, uncertainty and its parts), the runs with their series and
/// headline numbers, and (with_snapshots) the bed at t_ref for the figure.
nlohmann::json sensitivity_bundle_json(const consumers::Scene& scene,
                                       const workflows::SensitivitySummary& s, bool with_snapshots);

/// The work-precision bundle: per configuration (grid, time resolution) the bubble diameter or
/// headline numbers, the difference to the reference and the wall time.
nlohmann::json work_precision_bundle_json(const workflows::WorkPrecisionResult& w);

}  // namespace workflows
}  // namespace draglab
