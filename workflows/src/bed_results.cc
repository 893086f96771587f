// workflows/src/bed_results.cc: see draglab/workflows/bed_results.h.
#include "draglab/workflows/bed_results.h"

#include <algorithm>
#include <cmath>

namespace draglab {
namespace workflows {
namespace {

nlohmann::json bubble_json(const consumers::BubbleMetrics& b) {
  return {{"found", b.found},
          {"diameter_m", b.diameter_m},
          {"area_m2", b.area_m2},
          {"cells", b.cells},
          {"centroid_x_m", b.centroid_x_m},
          {"centroid_y_m", b.centroid_y_m},
          {"top_m", b.top_m},
          {"bottom_m", b.bottom_m},
          {"touches_surface", b.touches_surface},
          {"regions_above_threshold", b.regions_above_threshold},
          {"bed_height_m", b.bed_height_m}};
}

nlohmann::json snapshot_json(const consumers::BedSnapshot& s) {
  const auto& f = s.void_fraction;
  return {{"t_s", s.t_s},
          {"layers", s.layers},
          {"x", s.x},
          {"y", s.y},
          {"diameter", s.diameter},
          {"layer", s.layer},
          {"void_fraction",
           {{"nx", f.nx},
            {"ny", f.ny},
            {"width_m", f.width_m},
            {"height_m", f.height_m},
            {"values", f.values}}},
          {"bubble", bubble_json(s.bubble)}};
}

/// [cells_x, cells_y], or [cells_x, cells_y, cells_z] on a 3-D grid (as the grid text).
nlohmann::json grid_json(int cells_x, int cells_y, int cells_z) {
  return cells_z > 1 ? nlohmann::json{cells_x, cells_y, cells_z} : nlohmann::json{cells_x, cells_y};
}

}  // namespace

nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

nlohmann::json headline_json(const workflows::HeadlineNumbers& numbers) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, value] : numbers) j[name] = number_or_null(value);
  return j;
}

RunUncertainty run_uncertainty(const consumers::Scene& scene, const consumers::BedResult& r) {
  if (r.headline_uncertainty >= 0.0) return {r.headline_uncertainty, r.headline_uncertainty_method};
  if (!r.metrics.bubble_present) return {-1.0, "no bubble: nothing to estimate"};
  // The bound of the bubble boundary on the grid: one gas cell, the larger side.
  const double cell_size_m = std::max(scene.geometry.width_m / scene.grid.cells_x,
                                      scene.geometry.height_m / scene.grid.cells_y);
  return {cell_size_m,
          "one gas cell on the bubble boundary (the larger cell side); the packing-realization "
          "spread is not included: draglab sensitivity adds it in quadrature"};
}

nlohmann::json scene_run_json(const consumers::Scene& scene, const consumers::BedResult& r,
                              std::int64_t result_id) {
  nlohmann::json out = nlohmann::json::parse(r.result_json);
  out["result_id"] = result_id > 0 ? nlohmann::json(result_id) : nlohmann::json(nullptr);
  out["model"] = r.model;
  const RunUncertainty u = run_uncertainty(scene, r);
  out["numerical_uncertainty"] = u.value >= 0.0 ? nlohmann::json(u.value) : nlohmann::json(nullptr);
  out["numerical_uncertainty_method"] = u.method;
  return out;
}

nlohmann::json tolerances_json(const RegressionTolerances& t) {
  return {{"diameter_abs_m", t.diameter_abs_m},
          {"diameter_rel", t.diameter_rel},
          {"umf_rel", t.umf_rel}};
}

nlohmann::json metrics_json(const ConsumerMetrics& m) {
  return {{"umf_m_s", m.umf_m_s},
          {"background_m_s", m.background_m_s},
          {"t_ref_s", m.t_ref_s},
          {"bubble_present", m.bubble_present},
          {"bubble_diameter_m",
           m.bubble_present ? nlohmann::json(m.bubble_diameter_m) : nlohmann::json(nullptr)},
          {"bubble_centroid_m",
           m.bubble_present ? nlohmann::json(m.bubble_centroid_m) : nlohmann::json(nullptr)},
          {"max_bed_height_m", m.max_bed_height_m},
          {"wall_s", m.wall_s}};
}

nlohmann::json regress_json(const workflows::RegressSummary& summary) {
  using workflows::RegressOutcome;
  nlohmann::json entries = nlohmann::json::array();
  for (const workflows::RegressEntry& e : summary.entries) {
    nlohmann::json comparisons = nlohmann::json::array();
    for (const workflows::MetricComparison& c : e.comparisons) {
      comparisons.push_back({{"metric", c.metric},
                             {"baseline", number_or_null(c.baseline)},
                             {"new", number_or_null(c.value)},
                             {"delta", number_or_null(c.delta)},
                             {"tolerance", c.tolerance},
                             {"moved", c.moved}});
    }
    const bool failed =
        e.outcome == RegressOutcome::kFailed || e.outcome == RegressOutcome::kOutsideValidity;
    entries.push_back(
        {{"scene", e.scene_name},
         {"scene_hash", e.scene_hash},
         {"law", e.law},
         {"baseline",
          e.baseline_law.empty() ? nlohmann::json(nullptr) : nlohmann::json(e.baseline_law)},
         {"outcome", workflows::to_string(e.outcome)},
         {"ran", e.ran},
         {"result_id", failed ? nlohmann::json(nullptr) : nlohmann::json(e.result_id)},
         {"baseline_result_id", e.baseline_result_id > 0 ? nlohmann::json(e.baseline_result_id)
                                                         : nlohmann::json(nullptr)},
         {"tolerances", tolerances_json(e.tolerances)},
         {"metrics", failed ? nlohmann::json(nullptr) : metrics_json(e.metrics)},
         {"headline", headline_json(e.headline)},
         {"comparisons", comparisons},
         {"error", failed ? nlohmann::json(e.error) : nlohmann::json(nullptr)},
         {"warnings", e.warnings},
         {"wall_s", e.wall_s}});
  }
  return {{"moved", summary.count(RegressOutcome::kMoved)},
          {"ok", summary.count(RegressOutcome::kOk)},
          {"failed", summary.count(RegressOutcome::kFailed)},
          {"outside_validity", summary.count(RegressOutcome::kOutsideValidity)},
          {"baselines_registered", summary.count(RegressOutcome::kBaselineRegistered)},
          {"no_baseline", summary.count(RegressOutcome::kNoBaseline)},
          {"runs", summary.runs},
          {"wall_s", summary.wall_s},
          {"entries", entries}};
}

nlohmann::json sensitivity_bundle_json(const consumers::Scene& scene,
                                       const workflows::SensitivitySummary& s,
                                       bool with_snapshots) {
  nlohmann::json grids = nlohmann::json::array();
  for (const auto& g : s.grids) grids.push_back(grid_json(g.cells_x, g.cells_y, g.cells_z));
  nlohmann::json headline_names = nlohmann::json::array();
  if (s.has_headline())
    for (const auto& h : s.laws.front().headline) headline_names.push_back(h.name);
  nlohmann::json packings = nlohmann::json::array();
  for (const auto& p : s.packings) {
    packings.push_back({{"seed", p.seed},
                        {"particles", p.particles},
                        {"settled_bed_height_m", p.settled_bed_height_m},
                        {"settle_wall_s", p.settle_wall_s},
                        {"reused", p.reused}});
  }
  nlohmann::json laws = nlohmann::json::array();
  for (const auto& lr : s.laws) {
    nlohmann::json runs = nlohmann::json::array();
    for (const auto& r : lr.runs) {
      // Column arrays: a few hundred samples per run stay readable and small.
      nlohmann::json t = nlohmann::json::array(), d = nlohmann::json::array(),
                     centroid = nlohmann::json::array(), bed = nlohmann::json::array(),
                     segregation = nlohmann::json::array();
      bool sizes = false;
      for (const consumers::BedSample& smp : r.series) {
        t.push_back(smp.t_s);
        d.push_back(smp.bubble_diameter_m);
        centroid.push_back(smp.bubble_centroid_m);
        bed.push_back(smp.bed_height_m);
        segregation.push_back(smp.segregation_index);
        sizes = sizes || smp.segregation_index != 0.0;
      }
      nlohmann::json series = {{"t_s", t},
                               {"bubble_diameter_m", d},
                               {"bubble_centroid_m", centroid},
                               {"bed_height_m", bed}};
      // Beds of several sizes only: the other studies' files stay as they were.
      if (sizes) series["segregation_index"] = segregation;
      runs.push_back({{"seed", r.seed},
                      {"cells_x", r.cells_x},
                      {"cells_y", r.cells_y},
                      {"cells_z", r.cells_z},
                      {"cell_size_m", r.cell_size_m},
                      {"bubble_diameter_m", r.bubble_diameter_m},
                      {"bubble_found", r.bubble_found},
                      {"reached_t_ref", r.reached_t_ref},
                      {"background_m_s", r.background_m_s},
                      {"wall_s", r.wall_s},
                      {"gas_steps", r.gas_steps},
                      {"dem_steps", r.dem_steps},
                      {"gas_dt_s", r.gas_dt_s},
                      {"dem_dt_s", r.dem_dt_s},
                      {"momentum_mismatch", r.momentum_mismatch},
                      {"max_relative_gas_mass_imbalance", r.max_relative_mass_imbalance},
                      {"void_fraction_clamps", r.void_fraction_clamps},
                      {"drag_out_of_range", r.drag_out_of_range},
                      {"reused", r.reused},
                      {"headline", headline_json(r.headline)},
                      {"series", series}});
    }
    nlohmann::json law = {{"law", lr.law},
                          {"umf_m_s", lr.umf_m_s},
                          {"background_m_s", lr.background_m_s},
                          {"background", lr.background_mode},
                          {"d_mean_m", lr.diameter.mean_m},
                          {"d_estimate_m", lr.diameter.estimate_m},
                          {"uncertainty_m", lr.diameter.total_m},
                          {"spread_m", lr.diameter.spread_m},
                          {"grid_m", lr.diameter.grid_m},
                          {"boundary_m", lr.diameter.boundary_m},
                          {"bubbles_found", lr.bubbles_found},
                          {"bubble_found", lr.bubbles_found == static_cast<int>(lr.runs.size())},
                          {"runs", runs},
                          {"wall_s", lr.wall_s},
                          {"has_snapshot", lr.has_snapshot}};
    // Each headline number: the value, its total uncertainty and the parts, per-run values.
    nlohmann::json headline = nlohmann::json::array();
    for (std::size_t n = 0; n < lr.headline.size(); ++n) {
      const auto& h = lr.headline[n];
      nlohmann::json per_run = nlohmann::json::array();
      for (const auto& r : lr.runs)
        per_run.push_back(n < r.headline.size() ? number_or_null(r.headline[n].second) : nullptr);
      headline.push_back({{"name", h.name},
                          {"estimate", h.estimate},
                          {"uncertainty", h.total},
                          {"spread", h.spread},
                          {"grid", h.grid},
                          {"per_run", per_run}});
    }
    law["headline"] = headline;
    if (with_snapshots) {
      law["snapshot"] = lr.has_snapshot ? snapshot_json(lr.snapshot) : nlohmann::json(nullptr);
    }
    laws.push_back(law);
  }
  return {{"format", kSensitivityBundleFormat},
          {"version", 1},
          {"scene", s.scene},
          {"scene_hash", s.scene_hash},
          {"t_ref_s", s.t_ref_s},
          {"eps_threshold", s.eps_threshold},
          {"geometry",
           {{"width_m", scene.geometry.width_m},
            {"height_m", scene.geometry.height_m},
            {"depth_m", scene.geometry.depth_m}}},
          {"uncertainty",
           {{"method", workflows::to_string(s.method)},
            {"description", s.method_description},
            {"grids", grids}}},
          {"realization_kind", s.realization_kind},
          {"headline_names", headline_names},
          {"packings", packings},
          {"laws", laws},
          {"wall_s", s.wall_s}};
}

nlohmann::json work_precision_bundle_json(const workflows::WorkPrecisionResult& w) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : w.rows) {
    nlohmann::json difference = nlohmann::json::object();
    for (std::size_t n = 0; n < r.headline.size() && n < r.headline_difference.size(); ++n)
      difference[r.headline[n].first] = number_or_null(r.headline_difference[n]);
    rows.push_back({{"cells_x", r.cells_x},
                    {"cells_y", r.cells_y},
                    {"cells_z", r.cells_z},
                    {"time_resolution", r.time_resolution},
                    {w.time_resolution_name, r.time_resolution},
                    {"cell_size_m", r.cell_size_m},
                    {"bubble_diameter_m", r.bubble_diameter_m},
                    {"bubble_found", r.bubble_found},
                    {"reached_t_ref", r.reached_t_ref},
                    {"error_m", number_or_null(r.error_m)},
                    {"is_reference", r.is_reference},
                    {"wall_s", r.wall_s},
                    {"gas_steps", r.gas_steps},
                    {"dem_steps", r.dem_steps},
                    {"gas_dt_s", r.gas_dt_s},
                    {"dem_dt_s", r.dem_dt_s},
                    {"headline", headline_json(r.headline)},
                    {"headline_difference", difference}});
  }
  nlohmann::json headline_names = nlohmann::json::array();
  for (const auto& [name, value] : w.reference_headline) headline_names.push_back(name);
  return {{"format", kWorkPrecisionBundleFormat},
          {"version", 1},
          {"scene", w.scene},
          {"scene_hash", w.scene_hash},
          {"law", w.law},
          {"seed", w.seed},
          {"time_resolution_name", w.time_resolution_name},
          {"umf_m_s", w.umf_m_s},
          {"background_m_s", w.background_m_s},
          {"t_ref_s", w.t_ref_s},
          {"reference_method", w.reference_method},
          {"reference_diameter_m", w.reference_diameter_m},
          {"observed_order", w.reference_method == "richardson" ? nlohmann::json(w.observed_order)
                                                                : nlohmann::json(nullptr)},
          {"reference_note", w.reference_note},
          {"headline_names", headline_names},
          {"reference_headline", headline_json(w.reference_headline)},
          {"settle_wall_s", w.settle_wall_s},
          {"rows", rows},
          {"wall_s", w.wall_s}};
}

}  // namespace workflows
}  // namespace draglab
