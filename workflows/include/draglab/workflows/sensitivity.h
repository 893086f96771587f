// draglab/workflows/sensitivity.h: how much a bed model's bubble depends on the drag law, each
// law's bubble diameter with its numerical uncertainty (the seed's Fig. 4 and 5 studies), and the
// work-precision study of one law (bubble diameter against grid size and time step, with run
// times). Every registered bed model (bed_model.h) runs through the same code: its realization
// and time-resolution hooks say what the studies vary.
//
// run_sensitivity runs one scene (scene.h, docs/scenes.md) per law and reports the bubble
// diameter D at t_ref with an uncertainty from one of two sources:
//  - realizations (default, for a model that has them, e.g. the DPM's packings): the
//    realization is prepared once per seed (scene.seed, scene.seed + 1, ...) and every law
//    starts from it; the statistical part is the standard error of the mean over the n
//    realizations, s / sqrt(n) with s the sample standard deviation (for n = 2: |D1 - D2| / 2);
//  - grids (always, for a deterministic model): one realization, the scene's grid and a grid
//    refined by grid_refinement (1.5); the value is the finer grid's D and the statistical part
//    the Richardson error estimate of the finer value for first-order convergence (the traced
//    boundary of a bubble is O(h)): |D_fine - D_coarse| / (r - 1), r = h_coarse / h_fine.
//  - both (realizations and grids): every seed on the scene's grid and on the refined one; the
//    value is the mean over the seeds on the finer grid, the statistical part s / sqrt(n) on the
//    finer grid, the grid part |mean_fine - mean_coarse| / (r - 1), added in quadrature (a
//    deterministic model runs one "seed", so this is the grid method for it).
// Either part is combined in quadrature with the discretisation bound of the bubble boundary,
// h = max(dx, dy) of the (finest) grid used (bubble.h: |D - D_true| <~ one cell), which also
// guards against two runs that agree by chance. The figures of draglab_fig4.py read the
// snapshots (the particles coloured by their initial layer, or the solids fraction; the void
// fraction; the bubble metrics) of the first run of each law.
//
// A model with headline numbers (BedResult::headline; the DBM: hold-up, mean bubble diameter at
// the report heights, circulation) has no jet bubble at t_ref: the study reports each headline
// number per law with the same sources of uncertainty but no cell bound (the numbers are time
// averages, not traced boundaries): realizations: the mean and s / sqrt(n); grids: the finer
// grid's value and the first-order Richardson part |fine - coarse| / (r - 1); both: as above.
// The D fields are still filled (the DBM's D is its mean bubble diameter) but the reports show
// the headline numbers instead. A grid's cell size is max(dx, dy) for the pseudo-2D models and
// max(dx, dy, dz) for a 3-D grid (cells_z > 1); the refinement scales cells_z too then.
//
// run_work_precision runs one law on a list of grids x values of the model's time resolution
// (DPM: DEM contact steps; TFM: CFL number; DBM: dt_s) from one realization, and reports per
// configuration D at t_ref, wall time, steps and the error against a reference: the Richardson
// extrapolation of the three finest grids when they are refined by one common ratio and converge
// monotonically, else the finest configuration itself ("finest as reference", whose own error is
// then unknown). A model with headline numbers always takes the finest configuration as the
// reference, and each row carries its headline numbers and their differences to the reference's.
//
// Units SI. Limits: what the models say (dpm.h, tfm.h, dbm.h); two realizations give a rough
// standard error (a t-interval with one degree of freedom would be 12.7 times wider at 95 %); the
// grid estimate assumes first-order convergence.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/law.h"

namespace draglab {
namespace workflows {
using consumers::BedRunOptions;
using consumers::BedSample;
using consumers::BedSnapshot;
using consumers::Scene;

/// Loads a law by "name@version" (the CLI passes Database::load with the scene's range policy,
/// so consumers need not know the database). Called once per run, so each run gets a fresh
/// out-of-range counter. Throws as Database::load does (unknown law: Error(kNotFound)).
using LawLoader = std::function<std::shared_ptr<const Law>(const std::string& reference)>;

/// Where the numerical uncertainty of a law's bubble diameter comes from.
enum class UncertaintyMethod {
  kRealizations,  ///< Several realizations (seeds), same grid; grids for a deterministic model.
  kGrids,         ///< One realization, the scene's grid and a finer one.
  /// Several realizations, each on the scene's grid and a finer one (grids only for a
  /// deterministic model).
  kRealizationsAndGrids,
};
/// "realizations", "grids" or "both".
const char* to_string(UncertaintyMethod method);
/// "realizations", "grids" or "both"; anything else is Error(kInvalidArgument) naming the choices.
UncertaintyMethod uncertainty_method_from_string(const std::string& text);

/// Gas cells across the width and the height, and across the depth (1: the pseudo-2D models;
/// the DBM's grid is 3-D).
struct GridSize {
  int cells_x = 0;
  int cells_y = 0;
  int cells_z = 1;
};
/// "AxB", or "AxBxC" when cells_z > 1.
std::string to_string(const GridSize& grid);
/// Parses "8x24,12x36" or "4x10x4,6x15x6" (AxB or AxBxC, C the depth cells; at least one grid,
/// each count >= 1); throws Error(kInvalidArgument) naming `field` and the expected form. A grid
/// "AxB" (cells_z = 1) run on a scene with cells_z > 1 keeps the scene's depth cells (so "AxBx1"
/// cannot turn a 3-D scene into a 2-D column: set [grid] cells_z = 1 in the scene for that).
std::vector<GridSize> parse_grid_list(const std::string& text, const std::string& field);

/// Controls of run_sensitivity.
struct SensitivityOptions {
  std::vector<std::string> laws;  ///< "name@version", no duplicates; empty: the scene's [drag].
  UncertaintyMethod uncertainty = UncertaintyMethod::kRealizations;
  /// kRealizations, kRealizationsAndGrids: seeds scene.seed, scene.seed + 1, ...; [2, 32].
  int realizations = 2;
  /// kGrids, kRealizationsAndGrids: the finer grid has round(factor x cells) cells each way
  /// (across the depth too when the scene has cells_z > 1); (1, 4].
  double grid_refinement = 1.5;
  /// Run controls every model takes (the simulated time, the output folder); each run writes
  /// the files its scene asks for into a subfolder per law and grid.
  BedRunOptions run;
  /// Not empty: the study keeps each finished run, and each realization its model can keep
  /// (BedModel::SaveRealization: the DPM's settled packings), in this folder as it goes, and
  /// takes from it what the same study (the same scene text, seed, grid, law, time step,
  /// duration and t_ref) already finished, so that a study stopped part-way goes on where it
  /// was when run again; the results are those of an uninterrupted study, bit for bit. Created
  /// when the first file is written.
  std::string state_directory;
  /// With state_directory: wall seconds between the checkpoints of a realization still being
  /// prepared (the DPM's settling, RealizeOptions), so that one longer than a sitting goes on from
  /// where it stopped; [0, 1e6].
  double checkpoint_interval_s = 600.0;
  bool IsValid(std::string* error) const;
};

/// A model's headline numbers (BedResult::headline), in its order.
using HeadlineNumbers = std::vector<std::pair<std::string, double>>;

/// One run of one law.
struct SensitivityRun {
  std::uint64_t seed = 0;  ///< Realization (0 for a deterministic model).
  int cells_x = 0, cells_y = 0, cells_z = 1;
  /// max(dx, dy) (max(dx, dy, dz) on a 3-D grid): the boundary bound of this grid.
  double cell_size_m = 0.0;
  double bubble_diameter_m = 0.0;  ///< D at t_ref; 0 when no bubble was found there.
  bool bubble_found = false;
  /// A sample lay within half a sample interval of t_ref; false: the run (its duration rounded
  /// to whole gas steps) ended before t_ref, so "no bubble" means "not measured".
  bool reached_t_ref = false;
  double background_m_s = 0.0;  ///< Background used (umf_packing: depends on the packing).
  double wall_s = 0.0;          ///< The run only (preparing its realization is reported apart).
  long gas_steps = 0;           ///< BedResult::steps.
  std::int64_t dem_steps = 0;   ///< BedResult::inner_steps (DEM steps; 0 without particles).
  double gas_dt_s = 0.0, dem_dt_s = 0.0;
  double momentum_mismatch = 0.0;            ///< BedResult::momentum_mismatch.
  double max_relative_mass_imbalance = 0.0;  ///< Gas mass balance.
  std::int64_t void_fraction_clamps = 0;
  std::uint64_t drag_out_of_range = 0;  ///< Clamped/extrapolated drag evaluations.
  /// The bubble time series of the run: shows whether t_ref falls while the bubble grows,
  /// holds or rains out.
  std::vector<BedSample> series;
  HeadlineNumbers headline;  ///< BedResult::headline (empty for dpm and tfm).
  bool reused = false;       ///< Taken from the state folder (SensitivityOptions::state_directory).
};

/// D with its numerical uncertainty [m] (see the file comment for the methods).
struct DiameterUncertainty {
  double mean_m = 0.0;  ///< Arithmetic mean of the runs (both: of the finer grid's runs).
  /// Reported value: the mean (realizations), the finer grid's D (grids), the mean of the finer
  /// grid's runs (both).
  double estimate_m = 0.0;
  /// Standard error of the mean (realizations, both: on the finer grid), or the Richardson grid
  /// estimate (grids).
  double spread_m = 0.0;
  double grid_m = 0.0;      ///< both: |mean_fine - mean_coarse| / (r - 1); 0 otherwise.
  double boundary_m = 0.0;  ///< Cell-size bound h of the (finest) grid.
  double total_m = 0.0;     ///< sqrt(spread^2 + grid^2 + boundary^2).
};
/// Realizations: mean, s / sqrt(n) (s the sample standard deviation; n >= 2), the bound h.
/// Throws Error(kInvalidArgument) for fewer than two values, non-finite values or h <= 0.
DiameterUncertainty realization_uncertainty(const std::vector<double>& diameters_m,
                                            double cell_size_m);
/// Grids: the finer value and |D_fine - D_coarse| / (h_coarse / h_fine - 1) with the bound
/// h_fine. Throws Error(kInvalidArgument) unless 0 < h_fine < h_coarse and the values are finite.
DiameterUncertainty grid_uncertainty(double d_coarse_m, double h_coarse_m, double d_fine_m,
                                     double h_fine_m);
/// Both: the realizations on the coarse and the fine grid (the same seeds; at least two each):
/// the fine mean, s / sqrt(n) of the fine runs, |mean_fine - mean_coarse| / (r - 1), the bound
/// h_fine. Throws Error(kInvalidArgument) as the two above.
DiameterUncertainty combined_uncertainty(const std::vector<double>& d_coarse_m, double h_coarse_m,
                                         const std::vector<double>& d_fine_m, double h_fine_m);

/// One headline number of a law with its numerical uncertainty (in the number's unit). Formed
/// as D's without a cell bound: realizations: the mean and s / sqrt(n); grids: the finer grid's
/// value and |fine - coarse| / (r - 1); both: the finer grid's mean, s / sqrt(n) there and
/// |mean_fine - mean_coarse| / (r - 1).
struct HeadlineUncertainty {
  std::string name;       ///< As the model names it ("holdup", "circulation_upflow_m_s").
  double estimate = 0.0;  ///< Reported value.
  double spread = 0.0;    ///< Statistical part (realizations, both); 0 for grids.
  double grid = 0.0;      ///< Grid part (grids, both); 0 for realizations.
  double total = 0.0;     ///< sqrt(spread^2 + grid^2).
};
/// The headline uncertainty from the values of the runs on the coarse grid (empty for the
/// realization method) and on the finer (or only) grid with their cell sizes: realizations when
/// `coarse` is empty (fine: >= 2 values), grids when each has one value, both otherwise (>= 2
/// values each). Throws Error(kInvalidArgument) naming `name` for fewer values, non-finite
/// values or cell sizes that are not 0 < h_fine < h_coarse.
HeadlineUncertainty headline_uncertainty(const std::string& name, const std::vector<double>& coarse,
                                         double h_coarse_m, const std::vector<double>& fine,
                                         double h_fine_m);

/// One law's runs and its D with uncertainty.
struct SensitivityLawResult {
  std::string law;              ///< name@version.
  double umf_m_s = 0.0;         ///< The law's U_mf at the scene's eps_mf.
  double background_m_s = 0.0;  ///< Background superficial velocity used.
  std::string background_mode;  ///< "umf", "fixed" or "override".
  /// Realizations in seed order, or coarse then fine grid; both: per seed, coarse then fine.
  std::vector<SensitivityRun> runs;
  DiameterUncertainty diameter;
  /// Each headline number of the model with its uncertainty (empty for dpm and tfm).
  std::vector<HeadlineUncertainty> headline;
  int bubbles_found = 0;  ///< Runs that found a bubble at t_ref.
  double wall_s = 0.0;    ///< Sum of the runs' wall times.
  /// The first run's state at t_ref (particles and their initial layers for a particle model,
  /// void fraction, bubble), for the figure; has_snapshot is false if the run ended before t_ref.
  bool has_snapshot = false;
  BedSnapshot snapshot;
};

/// One realization (DPM: a settled packing), shared by every law and grid of its seed.
struct SensitivityPacking {
  std::uint64_t seed = 0;
  std::int64_t particles = 0;
  double settled_bed_height_m = 0.0;
  double settle_wall_s = 0.0;  ///< What preparing it cost (when it was prepared).
  bool reused = false;         ///< Taken from the state folder, or not needed: every run was.
};

/// Result of run_sensitivity.
struct SensitivitySummary {
  std::string scene;
  std::string scene_hash;
  UncertaintyMethod method = UncertaintyMethod::kRealizations;
  std::string method_description;            ///< How the uncertainty was formed, in words.
  double t_ref_s = 0.0;                      ///< After jet start.
  double eps_threshold = 0.0;                ///< Bubble criterion.
  std::vector<GridSize> grids;               ///< Grids run (one, or coarse and fine).
  std::vector<SensitivityPacking> packings;  ///< Realizations prepared (none: deterministic).
  std::vector<SensitivityLawResult> laws;    ///< In the order asked.
  std::string realization_kind;              ///< The model's ("packing"); empty: deterministic.
  double wall_s = 0.0;                       ///< Everything, settling included.
  /// Whether the model reports headline numbers (then the reports show them instead of D).
  bool has_headline() const { return !laws.empty() && !laws.front().headline.empty(); }
  /// One line per law: D = mean +- uncertainty; with headline numbers, each of them +- its
  /// uncertainty.
  std::string BriefReport() const;
  /// BriefReport plus the method, every run's D (or headline numbers), steps and wall time, the
  /// packings (realizations), and the parts of each headline uncertainty.
  std::string FullReport() const;
};

/// Progress: fraction of the whole study in [0, 1] and the current unit (a realization or a run),
/// "LABEL (k of N)", constant while that unit runs.
using SensitivityProgress = std::function<void(double fraction, const std::string& stage)>;

/// Runs every law of the scene (or options.laws) as described in the file comment. All laws are
/// loaded and every grid and law checked (U_mf, time steps) before the first run, so bad input
/// fails fast. Throws Error(kInvalidArgument) for invalid options or a finer grid the scene
/// cannot take, the loader's errors (unknown law), and the model's diagnoses.
SensitivitySummary run_sensitivity(const Scene& scene, const LawLoader& load_law,
                                   const SensitivityOptions& options,
                                   const SensitivityProgress& progress = nullptr);

/// Controls of run_work_precision.
struct WorkPrecisionOptions {
  std::string law;              ///< One "name@version"; required.
  std::vector<GridSize> grids;  ///< Empty: the scene's grid. No duplicates.
  /// Values of the model's time resolution (BedModel::time_resolution: DPM contact_steps, TFM
  /// cfl, DBM dt_s), each within the range the scene allows; no duplicates; empty: the scene's.
  std::vector<double> time_resolutions;
  BedRunOptions run;  ///< Run controls every model takes.
  bool IsValid(std::string* error) const;
};

/// One configuration of the work-precision study.
struct WorkPrecisionRow {
  int cells_x = 0, cells_y = 0, cells_z = 1;
  double time_resolution = 0.0;  ///< Value of WorkPrecisionResult::time_resolution_name.
  double cell_size_m = 0.0;      ///< max(dx, dy): the bubble boundary bound of this grid.
  double bubble_diameter_m = 0.0;
  bool bubble_found = false;
  bool reached_t_ref = false;  ///< As SensitivityRun::reached_t_ref.
  /// |D - D_reference|; NaN for the reference configuration itself under "finest as
  /// reference" (its error is not known).
  double error_m = 0.0;
  bool is_reference = false;
  double wall_s = 0.0;  ///< The run (its realization excluded: one for all rows).
  long gas_steps = 0;
  std::int64_t dem_steps = 0;
  double gas_dt_s = 0.0, dem_dt_s = 0.0;
  HeadlineNumbers headline;  ///< The run's headline numbers (empty for dpm and tfm).
  /// Per headline number, value - the reference configuration's; NaN for the reference itself.
  std::vector<double> headline_difference;
};

/// Richardson extrapolation of D from the three finest grids (cell sizes h1 > h2 > h3).
struct RichardsonEstimate {
  bool valid = false;
  double order = 0.0;           ///< Observed order p = ln((D2 - D1)/(D3 - D2)) / ln r.
  double extrapolated_m = 0.0;  ///< D3 + (D3 - D2) / (r^p - 1).
  std::string reason;           ///< Why it is not valid (ratios differ, not monotone, ...).
};
/// Needs the three cell sizes refined by one ratio r (within 2 %) and monotone convergence
/// (D2 - D1 and D3 - D2 of the same sign, shrinking), with 0.5 <= p <= 6; otherwise valid is
/// false with the reason.
RichardsonEstimate richardson_extrapolate(const std::vector<double>& cell_sizes_m,
                                          const std::vector<double>& diameters_m);

/// Result of run_work_precision.
struct WorkPrecisionResult {
  std::string scene;
  std::string scene_hash;
  std::string law;
  std::uint64_t seed = 0;            ///< The realization's (0: a deterministic model).
  std::string realization_kind;      ///< The model's ("packing"); empty: deterministic.
  std::string time_resolution_name;  ///< The model's ("contact_steps", "cfl").
  bool finer_time_is_larger = true;  ///< Whether a larger value is the finer step.
  double umf_m_s = 0.0, background_m_s = 0.0;
  double t_ref_s = 0.0;
  /// "richardson" (observed order and extrapolated D below) or "finest as reference".
  std::string reference_method;
  double reference_diameter_m = 0.0;
  double observed_order = 0.0;         ///< Richardson only; 0 otherwise.
  std::string reference_note;          ///< Why Richardson was not possible, when it was not.
  double settle_wall_s = 0.0;          ///< Preparing the realization.
  std::vector<WorkPrecisionRow> rows;  ///< Grids in the order given, time resolutions inside.
  /// The reference configuration's headline numbers (a headline model; empty otherwise).
  HeadlineNumbers reference_headline;
  double wall_s = 0.0;
  bool has_headline() const { return !reference_headline.empty(); }
  std::string BriefReport() const;  ///< The reference and the range of errors and times.
  std::string FullReport() const;   ///< BriefReport plus the table.
};

/// Runs the study (every grid with every time-resolution value, set by the model's
/// WithTimeResolution). Throws Error(kInvalidArgument) for invalid options or a configuration the
/// scene cannot take (grid finer than a particle, gas step, a time resolution out of range), the
/// loader's errors, and the model's diagnoses.
WorkPrecisionResult run_work_precision(const Scene& scene, const LawLoader& load_law,
                                       const WorkPrecisionOptions& options,
                                       const SensitivityProgress& progress = nullptr);

}  // namespace workflows
}  // namespace draglab
