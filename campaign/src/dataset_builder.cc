// build_dataset: the finished units of one campaign, or of several campaigns that are parts of
// one grid, -> one dataset point per (phi, Re target).
//
// Per point: realizations are paired across resolutions (the same packings at every d), so the
// extrapolation in d compares like with like; the realization mean at each resolution is
// extrapolated with the spec's method (internal::extrapolate_*); the standard error over
// realizations is taken at the finest resolution and scaled to F_inf. Parts must not share a
// point, must agree on what a unit computes (packing, operator, tolerance, precision), and their
// units must come from one code version unless mixing is allowed (then it is recorded).
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
  double resolution;  ///< d of the unit (per point with resolutions = "rule").
  double F, re, error_estimate, wall_s, F_body_standard_error;
};

struct PointUnits {
  double phi = 0, re_target = 0, wall_s = 0;
  int units = 0, failed = 0;
  std::vector<DoneUnit> done;
  std::vector<std::string> diagnoses;
};

/// One campaign's units, read for the dataset.
struct Part {
  CampaignSpec spec;
  CampaignStatus status;
  std::map<std::pair<int, int>, PointUnits> points;  ///< By (phi index, Re index).
  std::set<std::string> code_versions;               ///< Of its finished units.
  std::set<std::string> hosts;                       ///< Where its units ran.
  double unit_seconds = 0.0;                         ///< Run time of its finished units.
};

/// What the reduction of the points says besides the points.
struct BuildNotes {
  std::vector<std::string> skipped;
  nlohmann::json notes = nlohmann::json::array();
  int single_realization_points = 0;
};

std::string format_g(double x) { return core::format_number(x, 6); }

[[noreturn]] void bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

Part read_part(const Database& db, std::int64_t campaign_id) {
  Part part;
  part.spec = stored_spec(db, campaign_id);
  part.status = campaign_status(db, std::to_string(campaign_id));
  db::Statement s(db.handle(),
                  "SELECT phi_index, re_index, phi, re_target, realization, resolution_index, "
                  "status, F, re, error_estimate, wall_s, result_json, diagnosis, resolution, "
                  "code_version, claimed_by FROM campaign_units WHERE campaign_id = ?");
  s.bind(1, campaign_id);
  while (s.step()) {
    PointUnits& p = part.points[{static_cast<int>(s.integer(0)), static_cast<int>(s.integer(1))}];
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
    u.resolution = s.real(13);
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
    if (!s.is_null(14)) part.code_versions.insert(s.text(14));
    if (!s.is_null(15)) {
      const std::string claimed = s.text(15);  // host:pid:worker (or the rank's host)
      part.hosts.insert(claimed.substr(0, claimed.find(':')));
    }
    part.unit_seconds += u.wall_s;
    p.done.push_back(u);
  }
  return part;
}

/// The spec's keys that say what a unit computes: everything but the slice of the grid, its
/// resolutions and its box size (numerical parameters a part chooses for its points, as d), as
/// JSON (section -> key -> value).
nlohmann::json unit_identity(const CampaignSpec& spec) {
  nlohmann::json j = nlohmann::json::parse(spec.to_json());
  j.erase("campaign");
  j.erase("dataset");
  for (const char* key : {"phi", "re", "realizations"}) j["grid"].erase(key);
  for (const char* key : {"spheres", "box_size"}) j["packing"].erase(key);
  for (const char* key : {"resolutions", "min_resolution", "max_resolution", "max_steps"}) {
    j["lbm"].erase(key);
  }
  return j;
}

/// Parts of one dataset: no point twice, the same unit identity, one code version (unless
/// allowed). Each refusal names the parts, and the point, key or versions.
void check_parts(const std::vector<Part>& parts, bool allow_mixed_code) {
  std::map<std::pair<double, double>, std::string> owner;
  for (const Part& part : parts) {
    for (const auto& [key, p] : part.points) {
      const auto [it, fresh] = owner.emplace(std::make_pair(p.phi, p.re_target), part.spec.name);
      if (!fresh) {
        bad("dataset: the point phi = " + format_g(p.phi) + ", Re = " + format_g(p.re_target) +
            " is in two parts, campaigns '" + it->second + "' and '" + part.spec.name +
            "': a dataset takes each point from one campaign");
      }
    }
  }
  const nlohmann::json reference = unit_identity(parts.front().spec);
  for (std::size_t k = 1; k < parts.size(); ++k) {
    const nlohmann::json other = unit_identity(parts[k].spec);
    for (const auto& [section, keys] : reference.items()) {
      for (const auto& [key, value] : keys.items()) {
        const nlohmann::json there = other.contains(section) && other[section].contains(key)
                                         ? other[section][key]
                                         : nlohmann::json();
        if (there != value) {
          bad("dataset: campaign '" + parts[k].spec.name + "' is not a part of the same grid as '" +
              parts.front().spec.name + "': [" + section + "] " + key + " is " + there.dump() +
              " there and " + value.dump() + " in '" + parts.front().spec.name + "'");
        }
      }
    }
    if (other.dump() != reference.dump()) {
      bad("dataset: campaign '" + parts[k].spec.name + "' is not a part of the same grid as '" +
          parts.front().spec.name + "': its spec has keys the other has not");
    }
  }
  std::set<std::string> versions;
  for (const Part& part : parts)
    versions.insert(part.code_versions.begin(), part.code_versions.end());
  if (versions.size() > 1 && !allow_mixed_code) {
    std::string which;
    for (const Part& part : parts) {
      which += (which.empty() ? "" : "; ") + std::string("'") + part.spec.name + "': ";
      std::string list;
      for (const std::string& v : part.code_versions) list += (list.empty() ? "" : ", ") + v;
      which += list.empty() ? "no finished unit" : list;
    }
    bad("dataset: the units were computed by " + std::to_string(versions.size()) +
        " code versions (" + which +
        "); rerun the odd ones with one version, or allow the mix (dataset build "
        "--allow-mixed-code), which the dataset then records");
  }
}

/// One point's dataset value from its units, or false (with the reason in notes.skipped).
bool reduce_point(const CampaignSpec& spec, const PointUnits& p, DatasetPoint* out,
                  BuildNotes* notes) {
  const std::string label = "phi = " + format_g(p.phi) + ", Re = " + format_g(p.re_target);
  // Resolutions with a converged unit, and realizations converged at all of them (paired, so
  // that the extrapolation compares the same packings). Dropping coarse resolutions can bring
  // back realizations that failed there: keep the finest-resolution suffix with the most paired
  // realizations (sampling error usually dominates), and of those the most resolutions.
  std::map<int, double> d_of;  // resolution index -> d
  for (const auto& u : p.done) d_of[u.resolution_index] = u.resolution;
  if (d_of.empty()) {
    notes->skipped.push_back(label + ": no converged unit (" + std::to_string(p.failed) +
                             " failed" + (p.diagnoses.empty() ? "" : ": " + p.diagnoses.front()) +
                             ")");
    return false;
  }
  std::vector<int> all_res;
  for (const auto& [index, d] : d_of) all_res.push_back(index);
  std::sort(all_res.begin(), all_res.end(), [&d_of](int a, int b) { return d_of[a] < d_of[b]; });
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
  const std::size_t point_resolutions = spec.point_resolutions(p.phi, p.re_target).size();
  if (res.size() < point_resolutions) {
    notes->notes.push_back(
        label + ": " + std::to_string(point_resolutions - res.size()) +
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
    d_values.push_back(d_of[res[k]]);
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
  if (!e.note.empty()) notes->notes.push_back(label + ": " + e.note);
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
    ++notes->single_realization_points;
  }
  dp.F_standard_error = std::fabs(relative_se * dp.F);
  dp.F_uncertainty = std::sqrt(dp.F_standard_error * dp.F_standard_error +
                               dp.F_discretisation_error * dp.F_discretisation_error);
  if (!(std::isfinite(dp.F) && dp.F > 0.0 && std::isfinite(dp.F_uncertainty))) {
    notes->skipped.push_back(label + ": extrapolated F = " + format_g(dp.F) +
                             " is not a finite positive value");
    return false;
  }
  if (dp.F_uncertainty <= 0.0) {
    // Exactly repeated values (one realization, zero spread): keep a floor of the engine's
    // own error so that the point carries a usable weight.
    dp.F_uncertainty = std::max(finest_engine_error, 1e-6) * dp.F;
  }
  *out = dp;
  return true;
}

/// What one part contributed, for the dataset's method.
nlohmann::json part_json(const Part& part) {
  return {{"campaign", part.spec.name},
          {"campaign_id", part.status.id},
          {"spec_hash", part.status.spec_hash},
          {"spheres",
           part.spec.box_size > 0.0 ? nlohmann::json(nullptr) : nlohmann::json(part.spec.spheres)},
          {"box_size",
           part.spec.box_size > 0.0 ? nlohmann::json(part.spec.box_size) : nlohmann::json(nullptr)},
          {"code_versions", part.code_versions},
          {"hosts", part.hosts},
          {"unit_seconds", part.unit_seconds},
          {"units_total", part.status.units_total},
          {"units_done", part.status.units_done},
          {"units_failed", part.status.units_failed},
          {"units_not_run", part.status.units_pending + part.status.units_running}};
}

}  // namespace

Dataset build_dataset(Database& db, std::int64_t campaign_id, std::vector<std::string>* skipped) {
  return build_dataset(db, std::vector<std::int64_t>{campaign_id}, BuildDatasetOptions(), skipped);
}

Dataset build_dataset(Database& db, const std::vector<std::int64_t>& campaign_ids,
                      const BuildDatasetOptions& options, std::vector<std::string>* skipped) {
  if (campaign_ids.empty()) bad("dataset: no campaign to build from");
  if (campaign_ids.size() > 1 && options.name.empty()) {
    bad("dataset: a dataset of several campaigns needs a name (dataset build --name)");
  }
  std::vector<Part> parts;
  for (std::int64_t id : campaign_ids) {
    for (const Part& seen : parts) {
      if (seen.status.id == id) bad("dataset: campaign '" + seen.spec.name + "' is named twice");
    }
    parts.push_back(read_part(db, id));
  }
  check_parts(parts, options.allow_mixed_code);

  Dataset dataset;
  dataset.campaign_id = parts.front().status.id;
  dataset.name = options.name.empty() ? parts.front().spec.name : options.name;
  BuildNotes notes;
  for (const Part& part : parts) {
    for (const auto& [key, p] : part.points) {
      DatasetPoint dp;
      if (reduce_point(part.spec, p, &dp, &notes)) dataset.points.push_back(dp);
    }
  }
  // Parts in any order give the same dataset: points by (phi, Re target), as one campaign's.
  std::sort(dataset.points.begin(), dataset.points.end(),
            [](const DatasetPoint& a, const DatasetPoint& b) {
              return std::make_pair(a.phi, a.re_target) < std::make_pair(b.phi, b.re_target);
            });
  std::int64_t done = 0, failed = 0, not_run = 0, total = 0;
  for (const Part& part : parts) {
    done += part.status.units_done;
    failed += part.status.units_failed;
    not_run += part.status.units_pending + part.status.units_running;
    total += part.status.units_total;
  }
  if (dataset.points.empty()) {
    bad("campaign '" + parts.front().spec.name + "'" +
        (parts.size() > 1 ? " and its other parts have" : " has") +
        " no (phi, Re) point with a converged unit (" + std::to_string(done) + " done, " +
        std::to_string(failed) + " failed, " + std::to_string(not_run) + " not run): no dataset");
  }
  const CampaignSpec& spec = parts.front().spec;
  nlohmann::json method = {
      {"source", "campaign"},
      {"campaign_id", parts.front().status.id},
      {"campaign", spec.name},
      {"spec_hash", parts.front().status.spec_hash},
      {"extrapolation", spec.extrapolation},
      {"resolutions",
       spec.resolution_rule ? nlohmann::json("rule") : nlohmann::json(spec.resolutions)},
      {"realizations", spec.realizations},
      {"units_total", total},
      {"units_done", done},
      {"units_failed", failed},
      {"units_not_run", not_run},
      {"points", dataset.points.size()},
      {"skipped", notes.skipped},
      {"notes", notes.notes},
      {"standard_error",
       notes.single_realization_points == 0
           ? "over realizations at the finest resolution, scaled to F_inf"
           : "over realizations at the finest resolution, scaled to F_inf; " +
                 std::to_string(notes.single_realization_points) +
                 " point(s) with a single converged realization use the engine's per-sphere "
                 "spread / sqrt(N) instead"},
      {"discretisation_error",
       spec.extrapolation == "finest" ? "engine error_estimate x F at the resolution"
       : spec.resolution_rule
           ? "|F_inf - F(finest resolution)| where a point has several resolutions, the engine "
             "error_estimate x F where it has one"
           : "|F_inf - F(finest resolution)|"},
  };
  if (parts.size() > 1) {
    // Each part's own spec, versions, machines and time: the provenance of a dataset computed
    // in pieces.
    nlohmann::json list = nlohmann::json::array();
    for (const Part& part : parts) list.push_back(part_json(part));
    method["parts"] = list;
  }
  std::set<std::string> versions;
  for (const Part& part : parts)
    versions.insert(part.code_versions.begin(), part.code_versions.end());
  if (versions.size() > 1) method["mixed_code_versions"] = versions;
  dataset.method = method.dump();
  dataset.code_version = kDragDbVersion;
  if (skipped) *skipped = notes.skipped;
  return store_dataset(db, dataset);
}

}  // namespace campaign
}  // namespace draglab
