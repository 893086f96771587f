// workflows/bed_results.h: the JSON forms of bed-model results (scene run, regression check,
// sensitivity and work-precision bundles), one serializer each.
//
// Set-up: results filled by hand, so every field's value is known. References:
//  - a run's numerical uncertainty without a model estimate is one gas cell, the larger side
//    max(W/nx, H/ny) (the bound of a bubble boundary on the grid); with a model estimate (the
//    DBM's batch means) it is that estimate; without a bubble there is none (null);
//  - a number that is not finite is written as null, never as a string or a JSON error;
//  - a failed regression entry has no metrics and no result id;
//  - the bundles carry the format names scripts/draglab_fig4.py checks.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "draglab/workflows/bed_results.h"

namespace draglab {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

consumers::Scene scene_10cm_by_40cm() {
  consumers::Scene scene;
  scene.geometry.width_m = 0.10;
  scene.geometry.height_m = 0.40;
  scene.grid.cells_x = 20;  // 5 mm
  scene.grid.cells_y = 40;  // 10 mm: the larger side
  return scene;
}

consumers::BedResult jet_bubble_result(bool bubble) {
  consumers::BedResult r;
  r.model = "dpm";
  r.metrics.bubble_present = bubble;
  r.metrics.bubble_diameter_m = 0.031;
  r.result_json = R"({"solver": "dpm", "series": []})";
  return r;
}

TEST(SceneRunJson, UncertaintyIsOneCellTheLargerSide) {
  const nlohmann::json j =
      workflows::scene_run_json(scene_10cm_by_40cm(), jet_bubble_result(true), 7);
  EXPECT_DOUBLE_EQ(j["numerical_uncertainty"].get<double>(), 0.01);
  EXPECT_EQ(j["result_id"], 7);
  EXPECT_EQ(j["model"], "dpm");
  EXPECT_EQ(j["solver"], "dpm");  // the model's own result is kept whole
}

TEST(SceneRunJson, NoBubbleNoUncertaintyAndUnstoredRunHasNullId) {
  const nlohmann::json j =
      workflows::scene_run_json(scene_10cm_by_40cm(), jet_bubble_result(false), 0);
  EXPECT_TRUE(j["numerical_uncertainty"].is_null());
  EXPECT_TRUE(j["result_id"].is_null());
}

TEST(SceneRunJson, TheModelsOwnEstimateWins) {
  consumers::BedResult r = jet_bubble_result(true);
  r.headline_uncertainty = 0.0042;
  r.headline_uncertainty_method = "batch means";
  const nlohmann::json j = workflows::scene_run_json(scene_10cm_by_40cm(), r, 1);
  EXPECT_DOUBLE_EQ(j["numerical_uncertainty"].get<double>(), 0.0042);
  EXPECT_EQ(j["numerical_uncertainty_method"], "batch means");
}

TEST(RegressJson, CountsNullsAndFailedEntries) {
  workflows::RegressSummary s;
  workflows::RegressEntry moved;
  moved.scene_name = "tiny";
  moved.law = "x@2";
  moved.baseline_law = "x@1";
  moved.outcome = workflows::RegressOutcome::kMoved;
  moved.result_id = 5;
  moved.metrics.umf_m_s = 0.9;
  moved.headline = {{"holdup", kNaN}};
  moved.comparisons.push_back({"bubble_diameter_m", 0.03, kNaN, kNaN, 0.002, true});
  workflows::RegressEntry failed;
  failed.law = "x@3";
  failed.outcome = workflows::RegressOutcome::kFailed;
  failed.error = "diverged";
  failed.result_id = 9;  // ignored: nothing stored for a failed run
  s.entries = {moved, failed};
  s.runs = 2;
  const nlohmann::json j = workflows::regress_json(s);
  EXPECT_EQ(j["moved"], 1);
  EXPECT_EQ(j["failed"], 1);
  EXPECT_EQ(j["ok"], 0);
  EXPECT_EQ(j["runs"], 2);
  const auto& e0 = j["entries"][0];
  EXPECT_EQ(e0["outcome"], "moved");
  EXPECT_EQ(e0["result_id"], 5);
  EXPECT_TRUE(e0["baseline_result_id"].is_null());
  EXPECT_DOUBLE_EQ(e0["metrics"]["umf_m_s"].get<double>(), 0.9);
  EXPECT_TRUE(e0["metrics"]["bubble_diameter_m"].is_null());  // no bubble in these metrics
  EXPECT_TRUE(e0["headline"]["holdup"].is_null());
  EXPECT_TRUE(e0["comparisons"][0]["new"].is_null());
  EXPECT_TRUE(e0["error"].is_null());
  const auto& e1 = j["entries"][1];
  EXPECT_TRUE(e1["metrics"].is_null());
  EXPECT_TRUE(e1["result_id"].is_null());
  EXPECT_EQ(e1["error"], "diverged");
}

TEST(SensitivityBundle, FormatLawsRunsAndSnapshotsOnRequest) {
  const consumers::Scene scene = scene_10cm_by_40cm();
  workflows::SensitivitySummary s;
  s.scene = "tiny";
  s.t_ref_s = 0.2;
  workflows::SensitivityLawResult law;
  law.law = "gidaspow@1";
  law.diameter.mean_m = 0.03;
  law.diameter.total_m = 0.004;
  workflows::SensitivityRun run;
  run.seed = 3;
  run.bubble_diameter_m = 0.03;
  law.runs = {run};
  law.bubbles_found = 1;
  s.laws = {law};
  const nlohmann::json with = workflows::sensitivity_bundle_json(scene, s, true);
  EXPECT_EQ(with["format"], workflows::kSensitivityBundleFormat);
  EXPECT_EQ(with["laws"][0]["law"], "gidaspow@1");
  EXPECT_TRUE(with["laws"][0]["bubble_found"].get<bool>());  // every run found one
  EXPECT_DOUBLE_EQ(with["laws"][0]["uncertainty_m"].get<double>(), 0.004);
  EXPECT_EQ(with["laws"][0]["runs"][0]["seed"], 3);
  EXPECT_TRUE(with["laws"][0].contains("snapshot"));
  EXPECT_TRUE(with["laws"][0]["snapshot"].is_null());  // no snapshot was taken
  EXPECT_DOUBLE_EQ(with["geometry"]["height_m"].get<double>(), 0.40);
  const nlohmann::json without = workflows::sensitivity_bundle_json(scene, s, false);
  EXPECT_FALSE(without["laws"][0].contains("snapshot"));
}

TEST(WorkPrecisionBundle, ObservedOrderOnlyWithRichardson) {
  workflows::WorkPrecisionResult w;
  w.law = "ergun@1";
  w.time_resolution_name = "contact_steps";
  w.reference_method = "finest as reference";
  w.observed_order = 1.7;
  workflows::WorkPrecisionRow row;
  row.cells_x = 8;
  row.cells_y = 24;
  row.time_resolution = 20;
  row.error_m = kNaN;
  row.is_reference = true;
  w.rows = {row};
  nlohmann::json j = workflows::work_precision_bundle_json(w);
  EXPECT_EQ(j["format"], workflows::kWorkPrecisionBundleFormat);
  EXPECT_TRUE(j["observed_order"].is_null());
  EXPECT_TRUE(j["rows"][0]["error_m"].is_null());
  EXPECT_EQ(j["rows"][0]["contact_steps"], 20);  // the model's own name for the step
  w.reference_method = "richardson";
  j = workflows::work_precision_bundle_json(w);
  EXPECT_DOUBLE_EQ(j["observed_order"].get<double>(), 1.7);
}

}  // namespace
}  // namespace draglab
