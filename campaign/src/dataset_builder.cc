// build_dataset: a campaign's finished units -> one dataset point per (phi, Re target).
//
// Per point: realizations are paired across resolutions (the same packings at every d), so the
// extrapolation in d compares like with like; the realization mean at each resolution is
// extrapolated with the spec's method (internal::extrapolate_*); the standard error over
// realizations is taken at the finest resolution and scaled to F_inf.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "campaign_internal.h"
#include "db/sqlite_util.h"
#include "drag_db_version.h"
#include "draglab/campaign/campaign.h"
#include "draglab/core/text.h"
#include "draglab/drag_db/database.h"
#include "draglab/error.h"

namespace draglab {
namespace campaign {
namespace {

struct DoneUnit {
  int realization;
  int resolution_index;
  double F, re, error_estimate, wall_s, F_body_standard_error;
};

struct PointUnits {
  double phi = 0, re_target = 0, wall_s = 0;
  int units = 0, failed = 0;
  std::vector<DoneUnit> done;
  std::vector<std::string> diagnoses;
};

std::string format_g(double x) { return core::format_number(x, 6); }

}  // namespace

Dataset build_dataset(Database& db, std::int64_t campaign_id, std::vector<std::string>* skipped) {
  const CampaignSpec spec = stored_spec(db, campaign_id);
  const CampaignStatus status = campaign_status(db, std::to_string(campaign_id));
  std::map<std::pair<int, int>, PointUnits> points;
  {
    db::Statement s(db.handle(),
                    "SELECT phi_index, re_index, phi, re_target, realization, resolution_index, "
                    "status, F, re, error_estimate, wall_s, result_json, diagnosis FROM "
                    "campaign_units WHERE campaign_id = ?");
    s.bind(1, campaign_id);
    while (s.step()) {
      PointUnits& p = points[{static_cast<int>(s.integer(0)), static_cast<int>(s.integer(1))}];
      p.phi = s.real(2);
      p.re_target = s.real(3);
      ++p.units;
      const std::string st = s.text(6);
      if (!s.is_null(10)) p.wall_s += s.real(10);
      if (st == "failed") {
        ++p.failed;
        if (!s.is_null(12)) p.diagnoses.push_back(s.text(12));
      }
      if (st != "done") continue;
      DoneUnit u;
      u.realization = static_cast<int>(s.integer(4));
      u.resolution_index = static_cast<int>(s.integer(5));
      u.F = s.real(7);
      u.re = s.is_null(8) ? 0.0 : s.real(8);
      u.error_estimate = s.is_null(9) ? 0.0 : s.real(9);
      u.wall_s = s.is_null(10) ? 0.0 : s.real(10);
      u.F_body_standard_error = 0.0;
      if (!s.is_null(11)) {
        const auto j = nlohmann::json::parse(s.text(11), nullptr, false);
        if (j.is_object() && j.contains("F_standard_error") && j["F_standard_error"].is_number()) {
          u.F_body_standard_error = j["F_standard_error"].get<double>();
        }
      }
      p.done.push_back(u);
    }
  }

  Dataset dataset;
  dataset.campaign_id = campaign_id;
  dataset.name = spec.name;
  std::vector<std::string> skipped_points;
  nlohmann::json notes = nlohmann::json::array();
  int single_realization_points = 0;
  for (auto& [key, p] : points) {
    const std::string label = "phi = " + format_g(p.phi) + ", Re = " + format_g(p.re_target);
    // Resolutions with a converged unit, and realizations converged at all of them (paired, so
    // that the extrapolation compares the same packings). Dropping coarse resolutions can bring
    // back realizations that failed there: keep the finest-resolution suffix with the most paired
    // realizations (sampling error usually dominates), and of those the most resolutions.
    std::set<int> res_set;
    for (const auto& u : p.done) res_set.insert(u.resolution_index);
    if (res_set.empty()) {
      skipped_points.push_back(label + ": no converged unit (" + std::to_string(p.failed) +
                               " failed" + (p.diagnoses.empty() ? "" : ": " + p.diagnoses.front()) +
                               ")");
      continue;
    }
    std::vector<int> all_res(res_set.begin(), res_set.end());
    std::sort(all_res.begin(), all_res.end(),
              [&spec](int a, int b) { return spec.resolutions[a] < spec.resolutions[b]; });
    std::vector<int> res;
    std::set<int> paired;
    for (std::size_t drop = 0; drop < all_res.size(); ++drop) {
      const std::vector<int> candidate(all_res.begin() + static_cast<long>(drop), all_res.end());
      std::map<int, int> count;
      for (const auto& u : p.done) {
        if (std::find(candidate.begin(), candidate.end(), u.resolution_index) != candidate.end()) {
          ++count[u.realization];
        }
      }
      std::set<int> both;
      for (const auto& [r, c] : count) {
        if (c == static_cast<int>(candidate.size())) both.insert(r);
      }
      if (both.size() > paired.size()) {
        paired = both;
        res = candidate;
      }
    }
    if (res.size() < spec.resolutions.size()) {
      notes.push_back(
          label + ": " + std::to_string(spec.resolutions.size() - res.size()) +
          " resolution(s) left out (to keep the realizations that converged at the finer ones)");
    }
    // Realization means per resolution, and the spread at the finest.
    DatasetPoint dp;
    dp.phi = p.phi;
    dp.re_target = p.re_target;
    dp.wall_s = p.wall_s;
    dp.realizations = static_cast<int>(paired.size());
    std::vector<double> d_values, F_means;
    double finest_mean = 0, finest_var = 0, finest_engine_error = 0, finest_body_se = 0,
           finest_re = 0;
    for (std::size_t k = 0; k < res.size(); ++k) {
      std::vector<const DoneUnit*> units;
      for (const auto& u : p.done) {
        if (u.resolution_index == res[k] && paired.count(u.realization)) units.push_back(&u);
      }
      double mean = 0;
      for (const auto* u : units) mean += u->F;
      mean /= static_cast<double>(units.size());
      d_values.push_back(spec.resolutions[res[k]]);
      F_means.push_back(mean);
      if (k + 1 == res.size()) {
        finest_mean = mean;
        for (const auto* u : units) {
          finest_var += (u->F - mean) * (u->F - mean);
          finest_engine_error += u->error_estimate;
          finest_body_se += u->F_body_standard_error;
          finest_re += u->re;
        }
        const double n = static_cast<double>(units.size());
        finest_var = n > 1 ? finest_var / (n - 1) : 0.0;
        finest_engine_error /= n;
        finest_body_se /= n;
        finest_re /= n;
      }
    }
    dp.resolutions = d_values;
    dp.F_at_resolution = F_means;
    dp.re = finest_re;
    internal::Extrapolation e;
    if (spec.extrapolation == "richardson") {
      e = internal::extrapolate_richardson(d_values, F_means);
    } else if (spec.extrapolation == "inverse_d") {
      e = internal::extrapolate_inverse_d(d_values, F_means);
    } else {
      e.F_inf = finest_mean;
      e.method = "finest";
    }
    if (e.method == "finest") {
      // No extrapolation: the engine's a-priori error of one run is the discretisation estimate.
      e.F_inf = finest_mean;
      e.discretisation_error = finest_engine_error * finest_mean;
    }
    if (!e.note.empty()) notes.push_back(label + ": " + e.note);
    dp.F = e.F_inf;
    dp.order = e.order;
    dp.extrapolation = e.method;
    dp.F_discretisation_error = e.discretisation_error;
    // Sampling error of the geometry, relative, at the finest resolution, carried to F_inf.
    const double n = static_cast<double>(paired.size());
    double relative_se;
    if (paired.size() > 1) {
      relative_se = std::sqrt(finest_var / n) / finest_mean;
    } else {
      // One realization: the spread of the per-sphere drags over sqrt(N) stands in for the
      // realization-to-realization spread (said so in `method`).
      relative_se = finest_body_se / finest_mean;
      ++single_realization_points;
    }
    dp.F_standard_error = std::fabs(relative_se * dp.F);
    dp.F_uncertainty = std::sqrt(dp.F_standard_error * dp.F_standard_error +
                                 dp.F_discretisation_error * dp.F_discretisation_error);
    if (!(std::isfinite(dp.F) && dp.F > 0.0 && std::isfinite(dp.F_uncertainty))) {
      skipped_points.push_back(label + ": extrapolated F = " + format_g(dp.F) +
                               " is not a finite positive value");
      continue;
    }
    if (dp.F_uncertainty <= 0.0) {
      // Exactly repeated values (one realization, zero spread): keep a floor of the engine's
      // own error so that the point carries a usable weight.
      dp.F_uncertainty = std::max(finest_engine_error, 1e-6) * dp.F;
    }
    dataset.points.push_back(dp);
  }
  if (dataset.points.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                "campaign '" + spec.name + "' has no (phi, Re) point with a converged unit (" +
                    std::to_string(status.units_done) + " done, " +
                    std::to_string(status.units_failed) + " failed, " +
                    std::to_string(status.units_pending + status.units_running) +
                    " not run): no dataset");
  }
  nlohmann::json method = {
      {"source", "campaign"},
      {"campaign_id", campaign_id},
      {"campaign", spec.name},
      {"spec_hash", status.spec_hash},
      {"extrapolation", spec.extrapolation},
      {"resolutions", spec.resolutions},
      {"realizations", spec.realizations},
      {"units_total", status.units_total},
      {"units_done", status.units_done},
      {"units_failed", status.units_failed},
      {"units_not_run", status.units_pending + status.units_running},
      {"points", dataset.points.size()},
      {"skipped", skipped_points},
      {"notes", notes},
      {"standard_error",
       single_realization_points == 0
           ? "over realizations at the finest resolution, scaled to F_inf"
           : "over realizations at the finest resolution, scaled to F_inf; " +
                 std::to_string(single_realization_points) +
                 " point(s) with a single converged realization use the engine's per-sphere "
                 "spread / sqrt(N) instead"},
      {"discretisation_error", spec.extrapolation == "finest"
                                   ? "engine error_estimate x F at the resolution"
                                   : "|F_inf - F(finest resolution)|"},
  };
  dataset.method = method.dump();
  dataset.code_version = kDragDbVersion;
  if (skipped) *skipped = skipped_points;
  return store_dataset(db, dataset);
}

}  // namespace campaign
}  // namespace draglab
