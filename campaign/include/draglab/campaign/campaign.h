// draglab/campaign/campaign.h: drag data campaigns with the LBM engine.
//
// A campaign is a grid of units, one per (phi, Re, realization, resolution): generate the
// realization's random packing (deterministic seed from the spec's seed, phi index and
// realization), run the LBM engine at the resolution and target Re, and commit the measurement
// (F, beta, achieved Re, error estimate, steps, wall time, convergence status and diagnosis,
// packing hash, code version) in its own transaction. The spec is TOML (docs/campaigns.md,
// examples in data/campaigns/). State lives in the drag-law database (schema version 4 tables
// campaigns and campaign_units), so a campaign killed at any moment (SIGKILL included) resumes
// with --resume: finished units are kept, units that were in flight are re-run, none is
// duplicated (a unit row is claimed and completed by single UPDATE transactions). A unit that
// diverges or does not converge is recorded as failed with the engine's diagnosis and does not
// stop the others. Units run in parallel across the cores (`jobs` workers, each with its own
// database connection; the LBM runs of a worker use threads = max(1, cores / jobs)).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "draglab/drag_db/dataset.h"
#include "draglab/lbm/lbm.h"

namespace draglab {
class Database;

namespace campaign {

/// A campaign spec (TOML). Every field is validated by IsValid and by parse_campaign_spec, which
/// names the field and the allowed range in its Error(kInvalidArgument).
constexpr int kMaxRanksPerUnit = 4096;

struct CampaignSpec {
  std::string name;                   ///< [campaign] name, non-empty.
  std::string description;            ///< [campaign] description (optional).
  std::vector<double> phi;            ///< [grid] phi: solids fractions, each in [0.05, 0.6].
  std::vector<double> re;             ///< [grid] re: target Re (superficial), each in [0, 1000].
  int realizations = 1;               ///< [grid] realizations per (phi, Re), [1, 100].
  std::uint64_t seed = 1;             ///< [grid] seed: base seed of the packings.
  int spheres = 16;                   ///< [packing] spheres per box, [1, 100000] (or box_size).
  double box_size = 0.0;              ///< [packing] box edge in diameters (> 0 overrides spheres).
  std::string distribution = "mono";  ///< [packing] mono, bi or lognormal.
  double size_ratio = 2.0;            ///< [packing] bidisperse d_large/d_small.
  double large_fraction = 0.5;        ///< [packing] bidisperse volume share of the large spheres.
  double sigma = 0.2;                 ///< [packing] lognormal sigma of ln d.
  double min_gap =
      0.0;  ///< [packing] forced min surface gap in d; 0 = none (hard-sphere structure).
  std::vector<double> resolutions;  ///< [lbm] resolutions d (lattice units per diameter), >= 4.
  /// [lbm] resolutions = "rule": each (phi, Re) point gets its own d from the engine's
  /// resolution rule (lbm::resolution_needed for the spec's collision), rounded up to an even
  /// number and held within [min_resolution, max_resolution]. Where the rule asks for more than
  /// max_resolution it cannot promise its accuracy: the point then runs at two resolutions,
  /// max_resolution and about max_resolution / 1.5, extrapolated in d (point_resolutions).
  /// `resolutions` is empty then.
  bool resolution_rule = false;
  double min_resolution = 12.0;  ///< [lbm] min_resolution, with "rule" only.
  double max_resolution = 32.0;  ///< [lbm] max_resolution, with "rule" only.
  /// [lbm] target_error, with "rule" only: the largest a-priori discretisation error
  /// (lbm::planned_discretisation_error) a point may have at one resolution; a point whose rule
  /// d leaves more runs at the smallest d up to max_resolution that meets it, or, if none does,
  /// at two resolutions. 0 = the accuracy rules alone decide.
  double target_error = 0.0;
  std::string collision = "auto";   ///< [lbm] auto (per unit: lbm::choose_collision), trt, bgk, rr.
  std::string boundary = "ibb";     ///< [lbm] ibb or bb.
  double tolerance = 1e-5;          ///< [lbm] convergence tolerance (relative change per T).
  std::int64_t max_steps = 200000;  ///< [lbm] step limit of one unit.
  /// [lbm] population storage, "double" or "float" (lbm::RunOptions::precision). Part of the
  /// spec's identity only when "float", so specs written before the key keep their hash.
  std::string precision = "double";
  /// [lbm] MPI ranks that share each unit's box (slabs of z-planes, lbm::RunOptions::ranks), [1,
  /// kMaxRanksPerUnit]; > 1 needs a job of at least 1 + ranks_per_unit ranks. How a unit is
  /// computed, not what: it is not part of the spec's identity (to_json), so a campaign may be
  /// resumed with another value (the drag agrees to round-off).
  int ranks_per_unit = 1;
  std::string extrapolation = "richardson";  ///< [dataset] richardson, inverse_d or finest.
  /// [dataset] extend_with: a dataset CSV (read_dataset_csv) whose points outside this grid's
  /// (phi, Re) box join the campaign's dataset when the pipeline builds it (extend_dataset): the
  /// points a quick campaign cannot compute in its time, from data measured elsewhere. A relative
  /// path is taken from the spec file's folder. It changes no unit, so it is not part of the
  /// spec's identity (to_json); the dataset's method records it.
  std::string extend_with;
  /// [dataset] extend_with_id: the dataset id (12 hex digits) the file must have; "" = any. Pins
  /// the data a preset publishes from, so an edited file is named rather than fitted.
  std::string extend_with_id;
  bool IsValid(std::string* error) const;
  /// The resolutions the point (phi, Re) runs at, ascending: `resolutions`, or the rule's.
  std::vector<double> point_resolutions(double phi, double re) const;
  /// The largest resolution of any point.
  double largest_resolution() const;
  /// Units of the whole grid (realizations x each point's resolutions).
  std::int64_t unit_count() const;
  /// Canonical JSON text (stored with the campaign; its hash identifies the spec).
  std::string to_json() const;
};

/// Parses and validates a TOML spec file: unknown keys, missing or empty grids, values out of
/// range and contradictions (e.g. spheres and box_size both set) are Error(kInvalidArgument).
CampaignSpec parse_campaign_spec(const std::string& path);
CampaignSpec parse_campaign_spec_text(const std::string& toml_text, const std::string& origin);

/// One unit's stored state.
struct UnitRecord {
  std::int64_t id = 0;
  std::int64_t campaign_id = 0;
  double phi = 0.0;
  double re_target = 0.0;
  int realization = 0;
  double resolution = 0.0;
  std::string status;  ///< "pending", "running", "done" or "failed".
  // Measurement (status "done"):
  double F = 0.0, beta_d2_over_mu = 0.0, re = 0.0, error_estimate = 0.0;
  std::int64_t steps = 0;
  double wall_s = 0.0;
  double mflups = 0.0;
  std::string diagnosis;  ///< Why a failed unit failed (the engine's diagnosis).
  std::string packing_hash;
  std::string code_version;
  std::string finished_at;
};

/// What one worker of a run did: a thread of the single-process runner, or an MPI rank.
struct WorkerReport {
  std::string name;     ///< "worker 0" (a thread) or "rank 3".
  std::string host;     ///< The node it ran on.
  int units = 0;        ///< Units it ran (failed ones included).
  double busy_s = 0.0;  ///< Sum of its units' run times.
};

/// The run that just ended (left empty by status queries).
struct SessionReport {
  std::string mode;          ///< "threads" (one process) or "mpi" (ranks); "" if no run.
  double wall_s = 0.0;       ///< Wall time of the run, from the first claim to the last commit.
  int threads_per_unit = 0;  ///< OpenMP threads of each unit's LBM run.
  std::vector<WorkerReport> workers;
  /// Busy time over (workers x wall time): the share of the workers' time spent in units. Low
  /// when a long unit leaves the others idle at the end, or when a rank waited on rank 0.
  double parallel_efficiency = 0.0;
  std::vector<std::string> notes;  ///< E.g. ranks presumed dead and the units handed on.
  /// A table: per worker its units and busy time, then the efficiency and the notes.
  std::string FullReport() const;
  std::string ToJson() const;  ///< The same as a JSON object.
};

/// A unit not yet finished whose checkpoint lies beside the database: where its run stood when
/// the checkpoint was last written.
struct UnitInProgress {
  std::int64_t unit_id = 0;
  double phi = 0.0, re_target = 0.0, resolution = 0.0;
  int realization = 0;
  std::string status;  ///< "running", or "pending" (a stopped campaign that will resume it).
  double checkpoint_age_s = 0.0;  ///< Since the checkpoint was written.
  lbm::CheckpointProgress progress;
  std::string unreadable;  ///< Why the checkpoint could not be read ("" if it could).
};

struct CampaignStatus {
  std::int64_t id = 0;
  std::string name;
  std::string spec_hash;
  std::string created_at;
  std::int64_t units_total = 0, units_done = 0, units_failed = 0, units_pending = 0,
               units_running = 0;
  double wall_s = 0.0;                      ///< Sum of the finished units' run times.
  std::vector<UnitInProgress> in_progress;  ///< Units with a checkpoint, in unit order.
  SessionReport session;                    ///< Filled by run_campaign for the run it made.
  std::string BriefReport() const;
  std::string FullReport() const;
};

struct RunCampaignOptions {
  int jobs = 0;         ///< Parallel units of one process; 0 = number of cores. Unused under MPI.
  bool resume = false;  ///< Continue the campaign of the same name (same spec hash required).
  /// OpenMP threads of each unit's LBM run, [0, 1024]; 0 = the cores of the node shared among the
  /// workers on it. The thread count changes the rounding of the engine's sums: runs that must
  /// agree bit for bit (the same dataset id) use the same value.
  int threads_per_unit = 0;
  /// MPI: a worker rank silent this long (no heartbeat) is presumed dead, and its unit goes back
  /// to the queue for another rank; [1, 86400] s.
  double worker_timeout_s = 30.0;
  /// One process (not MPI): each unit's LBM run keeps a checkpoint beside the database
  /// ("<db_path>.campaign-<id>-unit-<unit>.checkpoint", lbm::RunOptions::checkpoint), rewritten
  /// every this many seconds, [0, 1e6]; a unit taken over after a kill goes on from it.
  double checkpoint_interval = 600.0;
  /// Progress: units finished (done + failed), total, and a status line (ETA included).
  std::function<void(std::int64_t finished, std::int64_t total, const std::string& line)> progress;
};

/// Creates the campaign (or, with resume, finds it; resume also creates a missing one) and runs
/// its pending units; units left 'running' by a dead process run again. Started by an MPI
/// launcher with several ranks (draglab/mpi/world.h), rank 0 alone opens the database, claims
/// units, hands them to ranks 1..N-1 (most expensive first) and commits each result in its own
/// transaction, exactly as one process does; a rank silent for worker_timeout_s is presumed dead
/// and its unit handed to another. Every rank must call it; ranks other than 0 return an empty
/// status (their work is in rank 0's session report). One process at a time
/// runs a campaign: it holds an exclusive flock on "<db_path>.campaign-<id>.lock" (released by
/// the kernel when the process dies). Returns the final status. Errors: Error(kInvalidArgument)
/// for a spec that fails IsValid, jobs outside [0, 1024], units too large for the memory, a new
/// campaign whose name exists (use resume) or a resume whose spec differs from the stored one;
/// Error(kDatabase) if another live process holds the campaign's lock or the schema is < 4.
CampaignStatus run_campaign(const std::string& db_path, const CampaignSpec& spec,
                            const RunCampaignOptions& options);

/// Rank 0 of a multi-rank job that fails before calling run_campaign (its spec file does not
/// parse, say) calls this so that the worker ranks, already waiting in run_campaign, end with
/// `exit_code` instead of waiting forever. Does nothing in a one-rank world.
void cancel_distributed_run(int exit_code);

/// Predicted cost of one (phi, Re, resolution) point of a spec (all its realizations).
struct PlannedPoint {
  double phi = 0.0, re = 0.0, resolution = 0.0;
  int units = 0;              ///< Realizations.
  double fluid_nodes = 0.0;   ///< Per unit.
  double steps = 0.0;         ///< Per unit: lbm::predicted_steps.
  double unit_seconds = 0.0;  ///< Predicted run time of one unit on one core.
  double memory_bytes = 0.0;  ///< Per unit (populations, flags, links: generous).
  /// The resolution rule at (phi, Re) for the spec's collision (lbm/resolution.h) and what it
  /// says of this d: "ok", "under-resolved" (below the gap or boundary-layer bound: the error
  /// grows; extrapolate in d), "may diverge" (below the stability bound: beyond the cell
  /// Reynolds number where the operator has held in every measured packing) or "refused" (the
  /// engine will refuse the unit: beyond the operator's cell Reynolds number).
  double d_needed = 0.0;
  std::string resolution_verdict;
  std::string resolution_detail;  ///< lbm::ResolutionNeed::Summary().
  std::string collision;          ///< The operator the units run ("auto" resolved per point).
  /// The flow is expected to turn unsteady (lbm::expects_unsteady_flow): `steps` then include
  /// the time average.
  bool unsteady = false;
};

/// What `draglab campaign plan` predicts before any work: units, memory and run time, from the
/// engine's step model (lbm::predicted_steps) and this machine's measured time per fluid-node
/// update (a short timed run, or the given value). Limits: the step model is within a factor
/// ~2.6 per unit (median 1.2) where it was calibrated (phi <= 0.4, Re <= 25, d = 10) and within 3
/// on the dense sweeps at Re 100 and 300 (docs/campaigns.md); elsewhere it is an extrapolation,
/// and units that fail (Mach limit, tau near 1/2) are not predicted.
struct CampaignPlan {
  std::vector<PlannedPoint> points;
  std::int64_t units = 0;
  int jobs = 1;
  double node_update_seconds = 0.0;  ///< Seconds per fluid-node update, one core (TRT, BGK).
  /// The same for the regularized operator (its wall correction costs per boundary link).
  double rr_node_update_seconds = 0.0;
  double core_seconds = 0.0;  ///< Sum over units.
  /// Longest-first schedule of the units on `jobs` workers (as the runner orders them).
  double wall_seconds = 0.0;
  double largest_unit_memory_bytes = 0.0;
  double machine_memory_bytes = 0.0;  ///< 0 if unknown.
  bool fits_in_memory = true;         ///< largest_unit_memory_bytes x jobs <= 80 % of the machine.
  std::int64_t refused_units = 0;     ///< Units the engine will refuse (cell Reynolds number).
  std::int64_t under_resolved_units = 0;  ///< Units below the accuracy rules.
  std::int64_t unstable_units = 0;        ///< Units below the stability bound ("may diverge").
  /// Units whose packing the generator cannot make (each packing is generated by the plan), and
  /// per phi the realizations that fail with the generator's first reason.
  std::int64_t unpackable_units = 0;
  std::vector<std::string> packing_failures;
  /// False where the packings hold too many spheres in all to be generated quickly (> 20 000):
  /// then none was checked.
  bool packings_checked = false;
  std::string BriefReport() const;
  std::string FullReport() const;
};

/// Plans `spec` (which must be valid) for `jobs` workers (>= 1). node_update_seconds > 0 uses
/// that value for every operator; 0 measures TRT's and rr's with short runs (about two seconds,
/// one thread). Throws
/// Error(kInvalidArgument) for an invalid spec or jobs outside [1, 1024].
CampaignPlan plan_campaign(const CampaignSpec& spec, int jobs, double node_update_seconds = 0.0);

/// Status by id (decimal) or name; throws Error(kNotFound).
CampaignStatus campaign_status(const Database& db, const std::string& id_or_name);
std::vector<CampaignStatus> list_campaigns(const Database& db);
std::vector<UnitRecord> list_units(const Database& db, std::int64_t campaign_id);
CampaignSpec stored_spec(const Database& db, std::int64_t campaign_id);

/// Every column of every unit of a campaign, straight from the table, ordered by phi, Re,
/// realization and resolution (for archives and other tools; the columns are those of the
/// schema, docs/campaigns.md).
struct UnitsExport {
  std::size_t count = 0;
  std::string csv;   ///< A header of column names, then one row per unit (numbers as %.17g).
  std::string json;  ///< A JSON array of objects, one per unit (result_json parsed).
};
UnitsExport export_units(const Database& db, std::int64_t campaign_id);
/// '#' comment lines to put above a units CSV that is shipped: the campaign, its spec hash (the
/// line campaign import checks), the code versions and hosts of its finished units, their run
/// time in core-seconds with the first start and last finish, the unit counts, this machine, and
/// `notes` (one line each: the command, a predicted cost).
std::string units_provenance(const Database& db, std::int64_t campaign_id,
                             const std::vector<std::string>& notes);
/// A campaign restored from its spec and the CSV of its units (`campaign export --csv`): the
/// way a dataset computed in parts keeps its units in the repository rather than in a database a
/// machine may lose. Finished units come back as the file has them (their values to the bit, so
/// a dataset built from them has the same id); the others come back pending, for `campaign run
/// --resume` (their checkpoints do not travel with the file). Refused (Error(kInvalidArgument),
/// naming the file, line and column; nothing is stored): a header without exactly the columns
/// of the export, a row whose field count differs, a cell that is not a finite number where the
/// schema has a number, a done unit without its drag, error estimate, code version or record, a
/// failed unit without its diagnosis, a row that is not a unit of this spec (its phi, Re, d or
/// seed differ, or its indices lie outside the grid), a unit twice or missing, a spec-hash
/// comment ("# Spec hash (SHA-256 of the canonical spec): ...") that is not this spec's, and a
/// campaign of the same name already in the database.
struct ImportSummary {
  std::int64_t campaign_id = 0;
  std::string name, spec_hash;
  std::int64_t units = 0, done = 0, failed = 0, pending = 0;
  std::set<std::string> code_versions;  ///< Of the finished units.
  std::string BriefReport() const;
  std::string ToJson() const;
};
ImportSummary import_campaign(Database& db, const CampaignSpec& spec,
                              const std::string& units_path);
/// The checks of import_campaign that need no database (all but the name already in one): for a
/// command line that must refuse bad input before it opens, or creates, a database.
void check_units_file(const CampaignSpec& spec, const std::string& units_path);
/// The columns a units file has ("name TYPE", the schema's order and declared types).
std::vector<std::string> units_file_columns();

/// The drag of each size class of each finished unit of a campaign over polydisperse packings
/// (lbm::SpeciesDrag, from the unit's record): CSV with a header, one row per unit and class:
/// unit id, phi, re_target, re (achieved, on the Sauter mean), resolution, realization, the class's
/// y = d_i/<d> and x (solids volume share), its spheres, F_i (own diameter) and its standard error
/// over those spheres, and the unit's mixture F (van der Hoef et al. 2005). Units without classes
/// (one size, failed) give no rows; *rows (optional) receives the row count.
std::string export_species_csv(const Database& db, std::int64_t campaign_id,
                               std::size_t* rows = nullptr);

/// Builds the dataset of a campaign from its finished units (per (phi, Re): realization mean and
/// standard error at each resolution, then the spec's resolution extrapolation), stores it
/// (store_dataset) and returns it. Points whose units all failed are left out and listed in
/// *skipped (if given). Throws Error(kInvalidArgument) if no point has a finished unit.
Dataset build_dataset(Database& db, std::int64_t campaign_id,
                      std::vector<std::string>* skipped = nullptr);

/// A dataset computed in parts: several campaigns, each a slice of one grid (its own points,
/// realizations and resolutions; the same packings, operator, tolerance and precision). Refused
/// (Error(kInvalidArgument), naming the parts): a point in two parts, parts whose units would
/// compute differently (the spec key is named), and units of more than one code version unless
/// allow_mixed_code (the dataset's method then lists the versions). The method records each part
/// (campaign, spec hash, code versions, hosts, unit seconds, units).
struct BuildDatasetOptions {
  std::string name;               ///< Required for several campaigns; else the campaign's name.
  bool allow_mixed_code = false;  ///< Accept units of several code versions (recorded).
};
Dataset build_dataset(Database& db, const std::vector<std::int64_t>& campaign_ids,
                      const BuildDatasetOptions& options,
                      std::vector<std::string>* skipped = nullptr);

}  // namespace campaign
}  // namespace draglab
