// Bubble diameter per drag law with its numerical uncertainty, and the work-precision study
// (draglab/workflows/sensitivity.h, docs/scenes.md "Sensitivity and work-precision").
#include "draglab/workflows/sensitivity.h"

#include "draglab/consumers/bed_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "study_state.h"

namespace draglab {
namespace workflows {
using consumers::BedModel;
using consumers::BedProgress;
using consumers::BedRealization;
using consumers::BedResult;
using consumers::check_run_options;
using consumers::derive_scene;
using consumers::find_bed_model;
using consumers::run_bed_model;
using consumers::TimeResolution;
namespace {

using Clock = std::chrono::steady_clock;

[[noreturn]] void Fail(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

std::string Num(double x, int digits = 4) { return core::format_number(x, digits); }

std::string Cm(double metres) { return Num(100.0 * metres, 3); }

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

std::string GridText(int cells_x, int cells_y, int cells_z = 1) {
  return to_string(GridSize{cells_x, cells_y, cells_z});
}

/// "packing seed 5", "injection seed 1": a realization of a kind by its seed.
std::string RealizationText(const std::string& kind, std::uint64_t seed) {
  const bool named_seed = kind.size() >= 4 && kind.compare(kind.size() - 4, 4, "seed") == 0;
  return kind + (named_seed ? " " : " seed ") + std::to_string(seed);
}

/// The progress label of preparing a realization (a packing settles).
std::string PrepareText(const std::string& kind, std::uint64_t seed) {
  return (kind == "packing" ? "settle " : "prepare ") + RealizationText(kind, seed);
}

GridSize GridOf(const Scene& s) { return {s.grid.cells_x, s.grid.cells_y, s.grid.cells_z}; }

/// The bubble boundary bound of a grid (bubble.h): the traced boundary is misplaced by up to half
/// a cell along the perimeter; with non-square cells the larger side bounds it. On a 3-D grid
/// (cells_z > 1) the depth side counts too: it is the size the grid method refines.
double CellSize(const Scene& s) {
  double h = std::max(s.geometry.width_m / s.grid.cells_x, s.geometry.height_m / s.grid.cells_y);
  if (s.grid.cells_z > 1) h = std::max(h, s.geometry.depth_m / s.grid.cells_z);
  return h;
}

/// Mean and standard error of the mean s / sqrt(n) (s the sample standard deviation, n >= 2).
std::pair<double, double> MeanAndStandardError(const std::vector<double>& values) {
  const double n = static_cast<double>(values.size());
  double sum = 0.0;
  for (double v : values) sum += v;
  const double mean = sum / n;
  double squares = 0.0;
  for (double v : values) squares += (v - mean) * (v - mean);
  return {mean, std::sqrt(squares / (n - 1.0) / n)};  // n = 2: |x1 - x2| / 2
}

double Mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

/// The scene on another grid (and, if `time_resolution` is given, at that value of the model's
/// time resolution), checked; `what` names the configuration in the message of a scene that
/// cannot take it.
Scene SceneOnGrid(const Scene& scene, GridSize grid, const BedModel& model,
                  const double* time_resolution, const std::string& what) {
  Scene s = time_resolution ? model.WithTimeResolution(scene, *time_resolution) : scene;
  s.grid.cells_x = grid.cells_x;
  s.grid.cells_y = grid.cells_y;
  // "AxB" names no depth: a 3-D scene keeps its depth cells.
  if (grid.cells_z > 1) s.grid.cells_z = grid.cells_z;
  std::string why;
  if (!s.IsValid(&why)) Fail(what + ": " + why);
  return s;
}

/// Run controls for one run: the scene's file outputs, if it asks for any, go to a folder per
/// run instead of every run overwriting the same files.
BedRunOptions RunOptions(const BedRunOptions& base, const Scene& s, const std::string& law,
                         const std::string& tag) {
  BedRunOptions o = base;
  if (!(s.outputs.fields || s.outputs.particles)) return o;
  std::string dir = !base.output_directory.empty() ? base.output_directory
                    : !s.outputs.directory.empty() ? s.outputs.directory
                                                   : "out/" + s.name;
  std::string name = law;
  std::replace(name.begin(), name.end(), '@', '_');
  o.output_directory = dir + "/" + name + "_" + tag;
  return o;
}

std::shared_ptr<const Law> Load(const LawLoader& load_law, const std::string& reference) {
  std::shared_ptr<const Law> law = load_law(reference);
  if (!law) Fail("law loader returned no law for '" + reference + "'");
  return law;
}

/// The study's record of one run.
SensitivityRun MakeRun(const BedResult& r, const Scene& s, std::uint64_t seed) {
  SensitivityRun run;
  run.seed = seed;
  run.cells_x = s.grid.cells_x;
  run.cells_y = s.grid.cells_y;
  run.cells_z = s.grid.cells_z;
  run.cell_size_m = CellSize(s);
  run.bubble_found = r.metrics.bubble_present;
  run.reached_t_ref = r.has_snapshot;
  run.bubble_diameter_m = r.metrics.bubble_present ? r.metrics.bubble_diameter_m : 0.0;
  run.background_m_s = r.metrics.background_m_s;
  run.wall_s = r.wall_s;
  run.gas_steps = r.steps;
  run.gas_dt_s = r.mean_dt_s;
  run.dem_steps = r.inner_steps;
  run.dem_dt_s = r.inner_dt_s;
  run.series = r.series;
  run.momentum_mismatch = r.momentum_mismatch;
  run.max_relative_mass_imbalance = r.max_relative_mass_imbalance;
  run.void_fraction_clamps = r.void_fraction_clamps;
  run.drag_out_of_range = r.law_out_of_range;
  run.headline = r.headline;
  return run;
}

/// A work-precision row from one run of its configuration.
WorkPrecisionRow RowOf(const SensitivityRun& run, double time_resolution) {
  WorkPrecisionRow row;
  row.cells_x = run.cells_x;
  row.cells_y = run.cells_y;
  row.cells_z = run.cells_z;
  row.time_resolution = time_resolution;
  row.cell_size_m = run.cell_size_m;
  row.bubble_found = run.bubble_found;
  row.reached_t_ref = run.reached_t_ref;
  row.bubble_diameter_m = run.bubble_diameter_m;
  row.wall_s = run.wall_s;
  row.gas_steps = run.gas_steps;
  row.dem_steps = run.dem_steps;
  row.gas_dt_s = run.gas_dt_s;
  row.dem_dt_s = run.dem_dt_s;
  row.headline = run.headline;
  return row;
}

/// Prepares the realization of `scene` (its seed) for every law and grid of that seed.
std::shared_ptr<const BedRealization> Realize(const BedModel& model, const Scene& scene,
                                              std::shared_ptr<const Law> law,
                                              const BedProgress& progress, SensitivityPacking* info,
                                              const consumers::RealizeOptions& options = {}) {
  std::shared_ptr<const BedRealization> realization =
      model.Realize(scene, std::move(law), progress, options);
  info->seed = realization->seed;
  info->particles = realization->particles;
  info->settled_bed_height_m = realization->bed_height_m;
  info->settle_wall_s = realization->prepare_wall_s;
  return realization;
}

/// What the study keeps of a run (study_state.h).
detail::StoredRun Stored(const BedResult& r, const Scene& s, std::uint64_t seed,
                         const SensitivityPacking& packing) {
  detail::StoredRun stored;
  stored.run = MakeRun(r, s, seed);
  stored.packing = packing;
  stored.umf_m_s = r.metrics.umf_m_s;
  stored.background_m_s = r.metrics.background_m_s;
  stored.background_mode = r.background_mode;
  stored.has_snapshot = r.has_snapshot;
  if (r.has_snapshot) stored.snapshot = r.snapshot;
  return stored;
}

/// One run of a study: its scene (grid and seed), law, folder tag and key, and what the state
/// folder had of it.
struct StudyRunSlot {
  Scene scene;
  std::size_t law = 0;
  std::string tag;
  std::string key;
  detail::StoredRun stored;
  bool stored_found = false;
};

/// A unit the state folder had: done at once.
void ReportReused(const BedProgress& progress) {
  if (progress) progress(1.0, "kept");
}

/// Progress over `total` equal units (a settling or a run each). The stage text is the unit's
/// label, "LABEL (k of N)", constant over the unit, so that a caller can time and announce it.
class StudyProgress {
 public:
  StudyProgress(const SensitivityProgress& progress, int total)
      : progress_(progress), total_(std::max(1, total)) {}
  BedProgress Unit(const std::string& label) {
    const int unit = done_++;
    if (!progress_) return nullptr;
    const std::string stage =
        label + " (" + std::to_string(unit + 1) + " of " + std::to_string(total_) + ")";
    return [this, unit, stage](double f, const std::string&) {
      progress_((unit + std::clamp(f, 0.0, 1.0)) / total_, stage);
    };
  }

 private:
  SensitivityProgress progress_;
  int total_;
  int done_ = 0;
};

/// The realization of `seed` for the runs in `slots`: taken from the state folder or prepared
/// (and kept there), and only if one of the runs is still to be done; its record either way.
SensitivityPacking PrepareRealization(const BedModel& model, const Scene& scene, std::uint64_t seed,
                                      const std::string& law, const LawLoader& load_law,
                                      const detail::StudyState& state, double checkpoint_interval_s,
                                      const std::vector<StudyRunSlot>& slots, StudyProgress* study,
                                      std::shared_ptr<const BedRealization>* realization) {
  const std::string kind = model.realization_kind();
  const bool needed = std::any_of(slots.begin(), slots.end(),
                                  [](const StudyRunSlot& slot) { return !slot.stored_found; });
  if (!needed) {
    SensitivityPacking info = slots.front().stored.packing;
    info.reused = true;
    ReportReused(study->Unit(PrepareText(kind, seed) + ", kept"));
    return info;
  }
  Scene seeded = scene;
  seeded.seed = seed;
  const std::string label = kind + "_seed" + std::to_string(seed);
  const std::string key = detail::realization_key(model, seeded, law);
  *realization = state.LoadRealization(model, label, key);
  if (*realization && (*realization)->seed == seed) {
    SensitivityPacking info;
    info.seed = seed;
    info.particles = (*realization)->particles;
    info.settled_bed_height_m = (*realization)->bed_height_m;
    info.settle_wall_s = (*realization)->prepare_wall_s;
    info.reused = true;
    ReportReused(study->Unit(PrepareText(kind, seed) + ", kept"));
    return info;
  }
  SensitivityPacking info;
  consumers::RealizeOptions keep;
  keep.checkpoint_path = state.RealizationCheckpoint(label, key);
  keep.checkpoint_interval_s = checkpoint_interval_s;
  *realization = Realize(model, seeded, Load(load_law, law), study->Unit(PrepareText(kind, seed)),
                         &info, keep);
  state.SaveRealization(model, label, key, **realization);
  return info;
}

void CheckLawList(const std::vector<std::string>& laws, const std::string& field, std::string* why,
                  bool* ok) {
  std::set<std::string> seen;
  for (const auto& l : laws) {
    if (l.empty() || l.find_first_of(" \t,") != std::string::npos || l.find('@') == 0) {
      *why = field + ": '" + l + "' is not a law reference NAME@VERSION (e.g. ergun@1)";
      *ok = false;
      return;
    }
    if (!seen.insert(l).second) {
      *why = field + ": '" + l + "' is listed twice";
      *ok = false;
      return;
    }
  }
}

}  // namespace

const char* to_string(UncertaintyMethod method) {
  switch (method) {
    case UncertaintyMethod::kGrids:
      return "grids";
    case UncertaintyMethod::kRealizationsAndGrids:
      return "both";
    case UncertaintyMethod::kRealizations:
      break;
  }
  return "realizations";
}

UncertaintyMethod uncertainty_method_from_string(const std::string& text) {
  if (text == "realizations") return UncertaintyMethod::kRealizations;
  if (text == "grids") return UncertaintyMethod::kGrids;
  if (text == "both") return UncertaintyMethod::kRealizationsAndGrids;
  Fail("uncertainty: '" + text + "' is not a method (use realizations, grids or both)");
}

std::string to_string(const GridSize& grid) {
  std::string text = std::to_string(grid.cells_x) + "x" + std::to_string(grid.cells_y);
  if (grid.cells_z > 1) text += "x" + std::to_string(grid.cells_z);
  return text;
}

std::vector<GridSize> parse_grid_list(const std::string& text, const std::string& field) {
  const std::string form =
      " (expected CELLS_XxCELLS_Y or CELLS_XxCELLS_YxCELLS_Z[,...], e.g. 8x24,12x36 or "
      "4x10x4,6x15x6)";
  std::vector<GridSize> grids;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    // Two or three counts of 1 to 6 digits separated by 'x'.
    std::vector<std::string> parts(1);
    for (char c : item) {
      if (c == 'x')
        parts.emplace_back();
      else
        parts.back() += c;
    }
    bool ok = parts.size() == 2 || parts.size() == 3;
    for (const std::string& part : parts) {
      ok = ok && !part.empty() && part.size() <= 6 &&
           part.find_first_not_of("0123456789") == std::string::npos;
    }
    GridSize g;
    if (ok) {
      g.cells_x = std::stoi(parts[0]);
      g.cells_y = std::stoi(parts[1]);
      g.cells_z = parts.size() == 3 ? std::stoi(parts[2]) : 1;
    }
    if (!ok || g.cells_x < 1 || g.cells_y < 1 || g.cells_z < 1)
      Fail(field + ": '" + item + "' is not a grid of at least 1x1 (or 1x1x1) cells" + form);
    grids.push_back(g);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return grids;
}

bool SensitivityOptions::IsValid(std::string* error) const {
  std::string why;
  bool ok = true;
  CheckLawList(laws, "SensitivityOptions.laws", &why, &ok);
  if (ok && !(realizations >= 2 && realizations <= 32)) {
    why = "SensitivityOptions.realizations must be in [2, 32], got " + std::to_string(realizations);
    ok = false;
  }
  if (ok && !(grid_refinement > 1.0 && grid_refinement <= 4.0)) {
    why = "SensitivityOptions.grid_refinement must be in (1, 4], got " + Num(grid_refinement);
    ok = false;
  }
  if (ok && !run.IsValid(&why)) {
    why = "SensitivityOptions.run: " + why;
    ok = false;
  }
  if (ok && !(checkpoint_interval_s >= 0.0 && checkpoint_interval_s <= 1e6)) {
    why = "SensitivityOptions.checkpoint_interval_s must be in [0, 1e6] s, got " +
          Num(checkpoint_interval_s);
    ok = false;
  }
  if (!ok && error) *error = why;
  return ok;
}

bool WorkPrecisionOptions::IsValid(std::string* error) const {
  std::string why;
  bool ok = true;
  CheckLawList({law}, "WorkPrecisionOptions.law", &why, &ok);
  for (std::size_t a = 0; ok && a < grids.size(); ++a) {
    if (grids[a].cells_x < 1 || grids[a].cells_y < 1 || grids[a].cells_z < 1) {
      why = "WorkPrecisionOptions.grids: " + to_string(grids[a]) +
            (grids[a].cells_z < 1 ? " (cells_z " + std::to_string(grids[a].cells_z) + ")" : "") +
            " needs at least 1 cell each way";
      ok = false;
    }
    for (std::size_t b = 0; ok && b < a; ++b) {
      if (grids[a].cells_x == grids[b].cells_x && grids[a].cells_y == grids[b].cells_y &&
          grids[a].cells_z == grids[b].cells_z) {
        why = "WorkPrecisionOptions.grids: " + to_string(grids[a]) + " is listed twice";
        ok = false;
      }
    }
  }
  for (std::size_t a = 0; ok && a < time_resolutions.size(); ++a) {
    if (!std::isfinite(time_resolutions[a]) || time_resolutions[a] <= 0.0) {
      why = "WorkPrecisionOptions.time_resolutions: " + Num(time_resolutions[a]) +
            " is not a positive number";
      ok = false;
    }
    for (std::size_t b = 0; ok && b < a; ++b) {
      if (time_resolutions[a] == time_resolutions[b]) {
        why = "WorkPrecisionOptions.time_resolutions: " + Num(time_resolutions[a]) +
              " is listed twice";
        ok = false;
      }
    }
  }
  if (ok && !run.IsValid(&why)) {
    why = "WorkPrecisionOptions.run: " + why;
    ok = false;
  }
  if (!ok && error) *error = why;
  return ok;
}

DiameterUncertainty realization_uncertainty(const std::vector<double>& diameters_m,
                                            double cell_size_m) {
  const std::size_t n = diameters_m.size();
  if (n < 2)
    Fail("realization_uncertainty: needs at least two realizations, got " + std::to_string(n));
  if (!(cell_size_m > 0.0) || !std::isfinite(cell_size_m))
    Fail("realization_uncertainty: cell_size_m must be > 0, got " + Num(cell_size_m));
  double sum = 0.0;
  for (double d : diameters_m) {
    if (!std::isfinite(d)) Fail("realization_uncertainty: a diameter is not finite");
    sum += d;
  }
  DiameterUncertainty u;
  u.mean_m = sum / static_cast<double>(n);
  double squares = 0.0;
  for (double d : diameters_m) squares += (d - u.mean_m) * (d - u.mean_m);
  const double sample_variance = squares / static_cast<double>(n - 1);
  u.estimate_m = u.mean_m;
  u.spread_m = std::sqrt(sample_variance / static_cast<double>(n));  // n = 2: |D1 - D2| / 2
  u.boundary_m = cell_size_m;
  u.total_m = std::hypot(u.spread_m, u.boundary_m);
  return u;
}

DiameterUncertainty grid_uncertainty(double d_coarse_m, double h_coarse_m, double d_fine_m,
                                     double h_fine_m) {
  if (!std::isfinite(d_coarse_m) || !std::isfinite(d_fine_m))
    Fail("grid_uncertainty: a diameter is not finite");
  if (!(h_fine_m > 0.0 && h_fine_m < h_coarse_m) || !std::isfinite(h_coarse_m))
    Fail("grid_uncertainty: needs 0 < h_fine < h_coarse, got h_fine = " + Num(h_fine_m) +
         " m, h_coarse = " + Num(h_coarse_m) + " m");
  DiameterUncertainty u;
  u.mean_m = 0.5 * (d_coarse_m + d_fine_m);
  u.estimate_m = d_fine_m;
  // Richardson for order 1: D_fine - D_exact ~ (D_fine - D_coarse) / (r - 1).
  u.spread_m = std::abs(d_fine_m - d_coarse_m) / (h_coarse_m / h_fine_m - 1.0);
  u.boundary_m = h_fine_m;
  u.total_m = std::hypot(u.spread_m, u.boundary_m);
  return u;
}

DiameterUncertainty combined_uncertainty(const std::vector<double>& d_coarse_m, double h_coarse_m,
                                         const std::vector<double>& d_fine_m, double h_fine_m) {
  if (d_coarse_m.size() < 2 || d_fine_m.size() < 2)
    Fail("combined_uncertainty: needs at least two realizations on each grid, got " +
         std::to_string(d_coarse_m.size()) + " and " + std::to_string(d_fine_m.size()));
  for (double d : d_coarse_m)
    if (!std::isfinite(d)) Fail("combined_uncertainty: a diameter is not finite");
  if (!(h_fine_m > 0.0 && h_fine_m < h_coarse_m) || !std::isfinite(h_coarse_m))
    Fail("combined_uncertainty: needs 0 < h_fine < h_coarse, got h_fine = " + Num(h_fine_m) +
         " m, h_coarse = " + Num(h_coarse_m) + " m");
  DiameterUncertainty u = realization_uncertainty(d_fine_m, h_fine_m);
  // Richardson for order 1 on the means of the seeds.
  u.grid_m = std::abs(u.mean_m - Mean(d_coarse_m)) / (h_coarse_m / h_fine_m - 1.0);
  u.total_m =
      std::sqrt(u.spread_m * u.spread_m + u.grid_m * u.grid_m + u.boundary_m * u.boundary_m);
  return u;
}

HeadlineUncertainty headline_uncertainty(const std::string& name, const std::vector<double>& coarse,
                                         double h_coarse_m, const std::vector<double>& fine,
                                         double h_fine_m) {
  const std::string what = "headline_uncertainty (" + name + ")";
  for (const auto* values : {&coarse, &fine})
    for (double v : *values)
      if (!std::isfinite(v)) Fail(what + ": a value is not finite");
  HeadlineUncertainty u;
  u.name = name;
  if (coarse.empty()) {  // realizations
    if (fine.size() < 2)
      Fail(what + ": needs at least two realizations, got " + std::to_string(fine.size()));
    std::tie(u.estimate, u.spread) = MeanAndStandardError(fine);
  } else {
    if (!(h_fine_m > 0.0 && h_fine_m < h_coarse_m) || !std::isfinite(h_coarse_m))
      Fail(what + ": needs 0 < h_fine < h_coarse, got h_fine = " + Num(h_fine_m) +
           " m, h_coarse = " + Num(h_coarse_m) + " m");
    const double r = h_coarse_m / h_fine_m;
    if (coarse.size() == 1 && fine.size() == 1) {  // grids
      u.estimate = fine.front();
      u.grid = std::abs(fine.front() - coarse.front()) / (r - 1.0);
    } else {  // both
      if (coarse.size() < 2 || fine.size() < 2)
        Fail(what + ": needs one value per grid, or at least two realizations on each, got " +
             std::to_string(coarse.size()) + " and " + std::to_string(fine.size()));
      std::tie(u.estimate, u.spread) = MeanAndStandardError(fine);
      u.grid = std::abs(u.estimate - Mean(coarse)) / (r - 1.0);
    }
  }
  u.total = std::hypot(u.spread, u.grid);
  return u;
}

RichardsonEstimate richardson_extrapolate(const std::vector<double>& cell_sizes_m,
                                          const std::vector<double>& diameters_m) {
  RichardsonEstimate est;
  if (cell_sizes_m.size() != 3 || diameters_m.size() != 3) {
    est.reason = "needs exactly three grids";
    return est;
  }
  const double h1 = cell_sizes_m[0], h2 = cell_sizes_m[1], h3 = cell_sizes_m[2];
  if (!(h1 > h2 && h2 > h3 && h3 > 0.0)) {
    est.reason = "cell sizes must decrease (coarse to fine)";
    return est;
  }
  const double r = h1 / h2;
  if (std::abs(h2 / h3 / r - 1.0) > 0.02) {
    est.reason = "the three finest grids are not refined by one ratio (" + Num(h1 / h2) + " then " +
                 Num(h2 / h3) + ")";
    return est;
  }
  const double e21 = diameters_m[1] - diameters_m[0], e32 = diameters_m[2] - diameters_m[1];
  if (!(e21 * e32 > 0.0) || !(std::abs(e32) < std::abs(e21))) {
    est.reason = "D does not converge monotonically on the three finest grids (" +
                 Num(diameters_m[0]) + ", " + Num(diameters_m[1]) + ", " + Num(diameters_m[2]) +
                 " m)";
    return est;
  }
  const double p = std::log(e21 / e32) / std::log(r);
  if (!(p >= 0.5 && p <= 6.0)) {
    est.reason = "observed order " + Num(p) + " is outside [0.5, 6]";
    return est;
  }
  est.valid = true;
  est.order = p;
  est.extrapolated_m = diameters_m[2] + e32 / (std::pow(r, p) - 1.0);
  return est;
}

SensitivitySummary run_sensitivity(const Scene& scene, const LawLoader& load_law,
                                   const SensitivityOptions& options,
                                   const SensitivityProgress& progress) {
  const auto t0 = Clock::now();
  scene.Validate();
  std::string why;
  if (!options.IsValid(&why)) Fail(why);
  check_run_options(scene, options.run);  // before the realizations are prepared
  if (!load_law) Fail("run_sensitivity: no law loader given");
  const std::vector<std::string> laws = options.laws.empty() ? scene.laws : options.laws;
  const BedModel& model = find_bed_model(scene.solver);
  // A deterministic model has no realizations: its uncertainty comes from two grids.
  const bool realized = !model.realization_kind().empty();
  const UncertaintyMethod method = realized ? options.uncertainty : UncertaintyMethod::kGrids;
  const bool with_grids = method != UncertaintyMethod::kRealizations;

  // Grids and seeds of the study.
  std::vector<Scene> grid_scenes = {scene};
  if (with_grids) {
    const auto refine = [&](int cells) {
      return static_cast<int>(std::lround(options.grid_refinement * cells));
    };
    // The depth is refined with the rest on a 3-D grid; a pseudo-2D grid keeps its one cell.
    const GridSize fine{refine(scene.grid.cells_x), refine(scene.grid.cells_y),
                        scene.grid.cells_z > 1 ? refine(scene.grid.cells_z) : 1};
    grid_scenes.push_back(SceneOnGrid(scene, fine, model, nullptr,
                                      "the finer grid (" + Num(options.grid_refinement) +
                                          " x the scene's, " + to_string(fine) + " cells)"));
    if (!(CellSize(grid_scenes[1]) < CellSize(scene)))
      Fail("the finer grid " + to_string(fine) +
           " has no smaller cells than the scene's; raise grid_refinement");
  }
  std::vector<std::uint64_t> seeds;
  const int n_seeds = method == UncertaintyMethod::kGrids ? 1 : options.realizations;
  for (int k = 0; k < n_seeds; ++k) seeds.push_back(scene.seed + static_cast<std::uint64_t>(k));

  if (!options.state_directory.empty())
    core::check_output_directory(options.state_directory, "the study's state folder");
  // Fail fast: every law loads and has a U_mf and stable steps on every grid.
  for (const auto& ref : laws) {
    const auto law = Load(load_law, ref);
    for (const Scene& gs : grid_scenes) (void)derive_scene(gs, *law);
  }

  SensitivitySummary summary;
  summary.scene = scene.name;
  summary.scene_hash = scene.hash();
  summary.method = method;
  summary.t_ref_s = scene.time.t_ref_s;
  summary.eps_threshold = scene.bubble.eps_threshold;
  summary.realization_kind = model.realization_kind();
  for (const Scene& gs : grid_scenes) summary.grids.push_back(GridOf(gs));

  summary.laws.resize(laws.size());
  for (std::size_t i = 0; i < laws.size(); ++i) summary.laws[i].law = laws[i];
  StudyProgress study(
      progress,
      static_cast<int>(seeds.size() * ((realized ? 1 : 0) + grid_scenes.size() * laws.size())));
  const detail::StudyState state(options.state_directory);
  for (const std::uint64_t seed : seeds) {
    // The runs of this seed the state folder already has.
    std::vector<StudyRunSlot> slots;
    for (const Scene& grid_scene : grid_scenes) {
      Scene run_scene = grid_scene;
      run_scene.seed = seed;
      const std::string grid = to_string(GridOf(run_scene));
      const std::string tag = realized ? "seed" + std::to_string(seed) + "_" + grid : grid;
      for (std::size_t i = 0; i < laws.size(); ++i) {
        StudyRunSlot slot{
            run_scene, i, tag, detail::run_key(model, run_scene, laws[i], options.run), {}, false};
        slot.stored_found = state.LoadRun(laws[i] + "_" + tag, slot.key, &slot.stored);
        slots.push_back(std::move(slot));
      }
    }
    // Prepared (or taken from the state folder) once per seed, only if a run of it is to be
    // done; every law and grid of that seed starts from it.
    std::shared_ptr<const BedRealization> realization;
    if (realized) {
      summary.packings.push_back(PrepareRealization(model, scene, seed, laws.front(), load_law,
                                                    state, options.checkpoint_interval_s, slots,
                                                    &study, &realization));
    }
    for (StudyRunSlot& slot : slots) {
      const std::string& law = laws[slot.law];
      if (slot.stored_found) {
        ReportReused(study.Unit(law + " " + slot.tag + ", kept"));
      } else {
        const BedResult r = run_bed_model(slot.scene, Load(load_law, law),
                                          RunOptions(options.run, slot.scene, law, slot.tag),
                                          study.Unit(law + " " + slot.tag), realization.get());
        slot.stored = Stored(r, slot.scene, realized ? seed : 0,
                             realized ? summary.packings.back() : SensitivityPacking());
        state.SaveRun(law + "_" + slot.tag, slot.key, slot.stored);
      }
      SensitivityLawResult& lr = summary.laws[slot.law];
      lr.runs.push_back(slot.stored.run);
      lr.wall_s += slot.stored.run.wall_s;
      if (lr.runs.size() == 1) {
        lr.umf_m_s = slot.stored.umf_m_s;
        lr.background_m_s = slot.stored.background_m_s;
        lr.background_mode = slot.stored.background_mode;
        lr.has_snapshot = slot.stored.has_snapshot;
        if (slot.stored.has_snapshot) lr.snapshot = std::move(slot.stored.snapshot);
      }
    }
  }

  // Runs are seed-major, grid-minor: run k * G + g is seed k on grid g.
  const std::size_t n_grids = grid_scenes.size();
  const double h_coarse = CellSize(grid_scenes.front()), h_fine = CellSize(grid_scenes.back());
  for (SensitivityLawResult& lr : summary.laws) {
    // Per grid, the values of every seed: D, and each headline number.
    std::vector<std::vector<double>> d(n_grids);
    const HeadlineNumbers& names = lr.runs.front().headline;
    std::vector<std::vector<std::vector<double>>> head(names.size(),
                                                       std::vector<std::vector<double>>(n_grids));
    for (std::size_t k = 0; k < lr.runs.size(); ++k) {
      const SensitivityRun& run = lr.runs[k];
      d[k % n_grids].push_back(run.bubble_diameter_m);
      lr.bubbles_found += run.bubble_found ? 1 : 0;
      if (run.headline.size() != names.size())
        Fail(lr.law + ": the model's headline numbers differ between runs");
      for (std::size_t n = 0; n < names.size(); ++n) {
        if (run.headline[n].first != names[n].first)
          Fail(lr.law + ": the model's headline numbers differ between runs ('" +
               run.headline[n].first + "' against '" + names[n].first + "')");
        head[n][k % n_grids].push_back(run.headline[n].second);
      }
    }
    switch (method) {
      case UncertaintyMethod::kRealizations:
        lr.diameter = realization_uncertainty(d[0], h_coarse);
        break;
      case UncertaintyMethod::kGrids:
        lr.diameter = grid_uncertainty(d[0][0], h_coarse, d[1][0], h_fine);
        break;
      case UncertaintyMethod::kRealizationsAndGrids:
        lr.diameter = combined_uncertainty(d[0], h_coarse, d[1], h_fine);
        break;
    }
    for (std::size_t n = 0; n < names.size(); ++n) {
      lr.headline.push_back(
          with_grids
              ? headline_uncertainty(names[n].first, head[n][0], h_coarse, head[n][1], h_fine)
              : headline_uncertainty(names[n].first, {}, 0.0, head[n][0], h_coarse));
    }
  }

  // How the uncertainty was formed, in words (for D, or for the headline numbers).
  const bool headline = summary.has_headline();
  const std::string kind = model.realization_kind();
  const std::string seed_range =
      "seeds " + std::to_string(seeds.front()) + ".." + std::to_string(seeds.back());
  const std::string se_text = "SE = s/sqrt(n) the standard error of the mean (n = 2: |x1 - x2|/2)";
  if (method == UncertaintyMethod::kRealizations) {
    summary.method_description =
        std::to_string(n_seeds) + " " + kind + " realizations (" + seed_range + ") on the grid " +
        to_string(GridOf(scene)) + "; " +
        (headline ? "each number = the mean of the runs; uncertainty = " + se_text
                  : "D = mean of the runs; uncertainty = sqrt(SE^2 + h^2) with " + se_text +
                        " and h = max(dx, dy) = " + Cm(CellSize(scene)) +
                        " cm the bubble-boundary bound of the grid");
  } else {
    const double r = h_coarse / h_fine;
    const std::string grids = "the grids " + to_string(GridOf(grid_scenes[0])) + " and " +
                              to_string(GridOf(grid_scenes[1])) + " (r = " + Num(r) + ")";
    const std::string richardson_text =
        "the Richardson error of the finer value for first-order convergence";
    const std::string bound_text =
        " and h = max(dx, dy) = " + Cm(h_fine) + " cm the bubble-boundary bound of the finer grid";
    if (method == UncertaintyMethod::kGrids) {
      summary.method_description =
          (realized ? "one " + kind + " (seed " + std::to_string(scene.seed) + ")"
                    : "the " + scene.solver + " model (deterministic: no realizations)") +
          " on " + grids + "; " +
          (headline
               ? "each number = the finer grid's; uncertainty = E = |fine - coarse|/(r - 1), " +
                     richardson_text
               : "D = the finer grid's; uncertainty = sqrt(E^2 + h^2) with E = |D_fine - "
                 "D_coarse|/(r - 1) " +
                     richardson_text + bound_text);
    } else {
      summary.method_description =
          std::to_string(n_seeds) + " " + kind + " realizations (" + seed_range + "), each on " +
          grids + "; " + (headline ? "each number" : std::string("D")) +
          " = the mean over the seeds on the finer grid; uncertainty = sqrt(SE^2 + E^2" +
          (headline ? "" : " + h^2") +
          ") with SE = s/sqrt(n) on the finer grid, E = |mean_fine - "
          "mean_coarse|/(r - 1) " +
          richardson_text + (headline ? "" : bound_text);
    }
  }
  summary.wall_s = Seconds(t0);
  return summary;
}

namespace {

/// "name = value" for each headline number of a run or a row.
std::string HeadlineText(const HeadlineNumbers& numbers) {
  std::string text;
  for (const auto& [name, value] : numbers)
    text += (text.empty() ? "" : ", ") + name + " " + Num(value);
  return text;
}

/// A bed of several sizes: its segregation index at the sample nearest t_ref and its change over
/// the run (last sample minus first; BedSample::segregation_index). False for a bed of one size,
/// whose index is 0 throughout.
bool SegregationOf(const SensitivityRun& run, double t_ref_s, double* at_t_ref, double* change) {
  const std::vector<BedSample>& series = run.series;
  if (std::none_of(series.begin(), series.end(),
                   [](const BedSample& s) { return s.segregation_index != 0.0; })) {
    return false;
  }
  const auto nearest = std::min_element(
      series.begin(), series.end(), [t_ref_s](const BedSample& a, const BedSample& b) {
        return std::abs(a.t_s - t_ref_s) < std::abs(b.t_s - t_ref_s);
      });
  *at_t_ref = nearest->segregation_index;
  *change = series.back().segregation_index - series.front().segregation_index;
  return true;
}

/// "; segregation change over the run M +- SE" over a law's runs (SE over the runs), or "" for
/// beds of one size.
std::string SegregationChangeText(const SensitivityLawResult& law, double t_ref_s) {
  std::vector<double> changes;
  for (const SensitivityRun& r : law.runs) {
    double at_t_ref = 0.0, change = 0.0;
    if (SegregationOf(r, t_ref_s, &at_t_ref, &change)) changes.push_back(change);
  }
  if (changes.empty()) return "";
  const double n = static_cast<double>(changes.size());
  double mean = 0.0;
  for (double c : changes) mean += c / n;
  double var = 0.0;
  for (double c : changes) var += (c - mean) * (c - mean);
  const double se = changes.size() > 1 ? std::sqrt(var / (n - 1.0) / n) : 0.0;
  return "; segregation change over the run " + Num(mean, 3) + " +- " + Num(se, 2);
}

}  // namespace

std::string SensitivitySummary::BriefReport() const {
  std::ostringstream s;
  if (has_headline()) {
    s << "Headline numbers of scene " << scene << " (" << to_string(method) << "):\n";
    for (const SensitivityLawResult& lr : laws) {
      s << "  " << lr.law << ":";
      for (const HeadlineUncertainty& h : lr.headline)
        s << " " << h.name << " = " << Num(h.estimate) << " +- " << Num(h.total, 2) << ";";
      s << " U_mf " << Num(lr.umf_m_s) << " m/s\n";
    }
    return s.str();
  }
  s << "Bubble diameter at t_ref = " << Num(t_ref_s) << " s after injection, scene " << scene
    << " (" << to_string(method) << "):\n";
  for (const SensitivityLawResult& lr : laws) {
    s << "  " << lr.law << ": D = " << Cm(lr.diameter.estimate_m) << " +- "
      << Cm(lr.diameter.total_m) << " cm";
    if (lr.bubbles_found < static_cast<int>(lr.runs.size()))
      s << " (no bubble at t_ref in " << lr.runs.size() - lr.bubbles_found << " of "
        << lr.runs.size() << " runs: D = 0 there)";
    s << "; U_mf " << Num(lr.umf_m_s) << " m/s, background " << Num(lr.background_m_s) << " m/s"
      << SegregationChangeText(lr, t_ref_s) << "\n";
  }
  return s.str();
}

std::string SensitivitySummary::FullReport() const {
  std::ostringstream s;
  s << BriefReport() << "  uncertainty: " << method_description << "\n";
  const bool headline = has_headline();
  for (const SensitivityPacking& p : packings) {
    if (p.particles == 0) continue;  // a realization without particles (DBM: a seed) says nothing
    s << "  packing seed " << p.seed << ": " << p.particles << " particles, settled bed "
      << Cm(p.settled_bed_height_m) << " cm, settling " << Num(p.settle_wall_s, 3) << " s wall"
      << (p.reused ? " (kept from an earlier part of the study)" : "") << "\n";
  }
  for (const SensitivityLawResult& lr : laws) {
    if (headline) {
      s << "  " << lr.law << ":\n";
      for (const HeadlineUncertainty& h : lr.headline) {
        s << "    " << h.name << " = " << Num(h.estimate) << " +- " << Num(h.total, 3)
          << " (statistical " << Num(h.spread, 3) << ", grid " << Num(h.grid, 3) << ")\n";
      }
    } else {
      s << "  " << lr.law << " (mean " << Cm(lr.diameter.mean_m) << " cm, spread "
        << Cm(lr.diameter.spread_m) << " cm";
      if (method == UncertaintyMethod::kRealizationsAndGrids)
        s << ", grid " << Cm(lr.diameter.grid_m) << " cm";
      s << ", cell bound " << Cm(lr.diameter.boundary_m) << " cm):\n";
    }
    for (const SensitivityRun& r : lr.runs) {
      s << "    seed " << r.seed << ", grid " << GridText(r.cells_x, r.cells_y, r.cells_z) << ": ";
      if (headline) {
        s << HeadlineText(r.headline) << "; " << r.gas_steps << " steps, " << Num(r.wall_s, 3)
          << " s wall" << (r.reused ? " (kept)" : "") << "\n";
      } else {
        s << "D " << (r.bubble_found ? Cm(r.bubble_diameter_m) + " cm" : std::string("none"));
        double at_t_ref = 0.0, change = 0.0;
        if (SegregationOf(r, t_ref_s, &at_t_ref, &change)) {
          s << ", segregation index " << Num(at_t_ref, 3) << " at t_ref (change over the run "
            << Num(change, 3) << ")";
        }
        s << ", " << r.gas_steps << " gas / " << r.dem_steps << " DEM steps, " << Num(r.wall_s, 3)
          << " s wall, momentum mismatch " << Num(r.momentum_mismatch, 2)
          << (r.reused ? " (kept from an earlier part of the study)" : "") << "\n";
      }
    }
  }
  s << "  total wall " << Num(wall_s, 3) << " s\n";
  return s.str();
}

WorkPrecisionResult run_work_precision(const Scene& scene, const LawLoader& load_law,
                                       const WorkPrecisionOptions& options,
                                       const SensitivityProgress& progress) {
  const auto t0 = Clock::now();
  scene.Validate();
  std::string why;
  if (!options.IsValid(&why)) Fail(why);
  check_run_options(scene, options.run);
  if (!load_law) Fail("run_work_precision: no law loader given");
  const BedModel& model = find_bed_model(scene.solver);
  const TimeResolution resolution = model.time_resolution();
  for (double v : options.time_resolutions) {
    if (resolution.whole_number && v != std::floor(v))
      Fail("WorkPrecisionOptions.time_resolutions: " + resolution.name + " = " + Num(v) +
           " is not a whole number (" + resolution.description + ", " + resolution.range + ")");
  }
  const bool realized = !model.realization_kind().empty();
  const std::vector<GridSize> grids =
      options.grids.empty() ? std::vector<GridSize>{GridOf(scene)} : options.grids;
  // The scene's own value goes through WithTimeResolution too, so that it alone sets the step
  // (DPM: the scene's dem_dt_s is dropped for t_c / contact_steps) in every row alike.
  const std::vector<double> steps = options.time_resolutions.empty()
                                        ? std::vector<double>{model.time_resolution_of(scene)}
                                        : options.time_resolutions;

  // Every configuration is checked (and the law's U_mf and gas steps) before the first run.
  std::vector<Scene> configs;
  std::vector<double> config_steps;
  for (const GridSize& g : grids) {
    const std::string grid = "grid " + to_string(g);
    for (const double& v : steps) {
      configs.push_back(
          SceneOnGrid(scene, g, model, &v, grid + " with " + resolution.name + " " + Num(v)));
      config_steps.push_back(v);
    }
  }
  {
    const auto law = Load(load_law, options.law);
    for (const Scene& c : configs) (void)derive_scene(c, *law);
  }

  WorkPrecisionResult result;
  result.scene = scene.name;
  result.scene_hash = scene.hash();
  result.law = options.law;
  result.seed = realized ? scene.seed : 0;
  result.realization_kind = model.realization_kind();
  result.time_resolution_name = resolution.name;
  result.finer_time_is_larger = resolution.larger_is_finer;
  result.t_ref_s = scene.time.t_ref_s;
  StudyProgress study(progress, (realized ? 1 : 0) + static_cast<int>(configs.size()));
  std::shared_ptr<const BedRealization> realization;
  if (realized) {
    SensitivityPacking info;
    // One realization, prepared with the scene's own settings, for every configuration.
    realization = Realize(model, scene, Load(load_law, options.law),
                          study.Unit(PrepareText(model.realization_kind(), scene.seed)), &info);
    result.settle_wall_s = info.settle_wall_s;
  }
  for (std::size_t k = 0; k < configs.size(); ++k) {
    const Scene& c = configs[k];
    const std::string tag = to_string(GridOf(c)) + "_" + resolution.name + Num(config_steps[k]);
    const BedResult r =
        run_bed_model(c, Load(load_law, options.law), RunOptions(options.run, c, options.law, tag),
                      study.Unit(options.law + " " + tag), realization.get());
    result.rows.push_back(RowOf(MakeRun(r, c, result.seed), config_steps[k]));
    result.umf_m_s = r.metrics.umf_m_s;
    result.background_m_s = r.metrics.background_m_s;
  }

  // Reference: Richardson over the three finest grids at the finest time step, else the finest
  // configuration (most cells, then the finest time step).
  const auto finer_time = [&](double a, double b) {
    return resolution.larger_is_finer ? a > b : a < b;
  };
  double finest_steps = config_steps.front();
  for (double v : config_steps)
    if (finer_time(v, finest_steps)) finest_steps = v;
  std::vector<const WorkPrecisionRow*> at_finest_steps;
  for (const auto& row : result.rows)
    if (row.time_resolution == finest_steps) at_finest_steps.push_back(&row);
  std::sort(at_finest_steps.begin(), at_finest_steps.end(),
            [](const WorkPrecisionRow* a, const WorkPrecisionRow* b) {
              return a->cell_size_m > b->cell_size_m;  // coarse to fine
            });
  // A model with headline numbers is compared with its finest configuration: its D (DBM: the
  // mean bubble size) is no traced boundary whose O(h) error Richardson would extrapolate.
  const bool headline = !result.rows.front().headline.empty();
  RichardsonEstimate rich;
  if (headline) {
    rich.reason = "the model's headline numbers are compared with the finest configuration";
  } else if (at_finest_steps.size() >= 3) {
    const std::size_t n = at_finest_steps.size();
    std::vector<double> h, d;
    bool uniform = true;
    for (std::size_t k = n - 3; k < n; ++k) {
      h.push_back(at_finest_steps[k]->cell_size_m);
      d.push_back(at_finest_steps[k]->bubble_diameter_m);
      // Refinement must be the same in both directions for one cell size to describe a grid.
      const double rx = static_cast<double>(at_finest_steps[k]->cells_x) /
                        at_finest_steps[n - 3]->cells_x,
                   ry = static_cast<double>(at_finest_steps[k]->cells_y) /
                        at_finest_steps[n - 3]->cells_y;
      uniform = uniform && std::abs(rx / ry - 1.0) <= 0.02;
      uniform = uniform && at_finest_steps[k]->bubble_found;
    }
    rich = uniform ? richardson_extrapolate(h, d)
                   : RichardsonEstimate{false, 0.0, 0.0,
                                        "the three finest grids are not refined alike in x and "
                                        "y, or one of them has no bubble at t_ref"};
  } else {
    rich.reason = "fewer than three grids";
  }
  if (rich.valid) {
    result.reference_method = "richardson";
    result.observed_order = rich.order;
    result.reference_diameter_m = rich.extrapolated_m;
    for (auto& row : result.rows)
      row.error_m = std::abs(row.bubble_diameter_m - result.reference_diameter_m);
  } else {
    result.reference_method = "finest as reference";
    result.reference_note = headline ? "" : "Richardson not possible: " + rich.reason;
    std::size_t finest = 0;
    for (std::size_t k = 1; k < result.rows.size(); ++k) {
      const auto& a = result.rows[k];
      const auto& b = result.rows[finest];
      const long cells_a = static_cast<long>(a.cells_x) * a.cells_y * a.cells_z,
                 cells_b = static_cast<long>(b.cells_x) * b.cells_y * b.cells_z;
      if (cells_a > cells_b ||
          (cells_a == cells_b && finer_time(a.time_resolution, b.time_resolution)))
        finest = k;
    }
    result.rows[finest].is_reference = true;
    result.reference_diameter_m = result.rows[finest].bubble_diameter_m;
    for (auto& row : result.rows) {
      row.error_m = row.is_reference
                        ? std::numeric_limits<double>::quiet_NaN()
                        : std::abs(row.bubble_diameter_m - result.reference_diameter_m);
    }
    if (headline) {
      result.reference_headline = result.rows[finest].headline;
      const HeadlineNumbers& ref = result.reference_headline;
      for (auto& row : result.rows) {
        if (row.headline.size() != ref.size())
          Fail("run_work_precision: the model's headline numbers differ between configurations");
        for (std::size_t n = 0; n < ref.size(); ++n) {
          if (row.headline[n].first != ref[n].first)
            Fail(
                "run_work_precision: the model's headline numbers differ between configurations "
                "('" +
                row.headline[n].first + "' against '" + ref[n].first + "')");
          row.headline_difference.push_back(row.is_reference
                                                ? std::numeric_limits<double>::quiet_NaN()
                                                : row.headline[n].second - ref[n].second);
        }
      }
    }
  }
  result.wall_s = Seconds(t0);
  return result;
}

std::string WorkPrecisionResult::BriefReport() const {
  std::ostringstream s;
  s << "Work-precision of " << law << " on scene " << scene;
  if (!realization_kind.empty()) s << " (" << RealizationText(realization_kind, seed) << ")";
  if (has_headline()) {
    const WorkPrecisionRow* ref = nullptr;
    for (const WorkPrecisionRow& r : rows)
      if (r.is_reference) ref = &r;
    s << ": headline numbers against the finest configuration";
    if (ref)
      s << " (grid " << GridText(ref->cells_x, ref->cells_y, ref->cells_z) << ", "
        << time_resolution_name << " " << Num(ref->time_resolution) << ")";
    s << ": " << HeadlineText(reference_headline) << "; " << rows.size()
      << " configurations, total " << Num(wall_s, 3) << " s wall\n";
    return s.str();
  }
  s << ": D at t_ref = " << Num(t_ref_s) << " s; reference " << reference_method
    << " D = " << Cm(reference_diameter_m) << " cm";
  if (reference_method == "richardson") s << " (observed order " << Num(observed_order, 3) << ")";
  s << "; " << rows.size() << " configurations, ";
  if (!realization_kind.empty()) s << realization_kind << " " << Num(settle_wall_s, 3) << " s, ";
  s << "total " << Num(wall_s, 3) << " s wall\n";
  if (!reference_note.empty()) s << "  " << reference_note << "\n";
  return s.str();
}

std::string WorkPrecisionResult::FullReport() const {
  std::ostringstream s;
  s << BriefReport();
  for (const WorkPrecisionRow& r : rows) {
    if (has_headline()) {
      s << "  grid " << GridText(r.cells_x, r.cells_y, r.cells_z) << ", " << time_resolution_name
        << " " << Num(r.time_resolution) << ":";
      for (std::size_t n = 0; n < r.headline.size(); ++n) {
        const double diff = n < r.headline_difference.size() ? r.headline_difference[n] : 0.0;
        s << " " << r.headline[n].first << " " << Num(r.headline[n].second) << " ("
          << (std::isnan(diff) ? std::string("reference") : "diff " + Num(diff, 3)) << "),";
      }
      s << " " << r.gas_steps << " steps, " << Num(r.wall_s, 3) << " s wall\n";
      continue;
    }
    s << "  grid " << GridText(r.cells_x, r.cells_y) << ", " << time_resolution_name << " "
      << Num(r.time_resolution) << ": D "
      << (r.bubble_found ? Cm(r.bubble_diameter_m) + " cm" : std::string("none")) << ", error "
      << (std::isnan(r.error_m) ? std::string("(reference)") : Cm(r.error_m) + " cm")
      << ", cell bound " << Cm(r.cell_size_m) << " cm, " << r.gas_steps << " gas / " << r.dem_steps
      << " DEM steps, " << Num(r.wall_s, 3) << " s wall\n";
  }
  return s.str();
}

}  // namespace workflows
}  // namespace draglab
