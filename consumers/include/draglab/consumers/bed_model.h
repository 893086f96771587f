// draglab/consumers/bed_model.h: the bundled fluidized-bed solvers as one family.
//
// A bed model runs a scene (scene.h) with one loaded drag law and returns a solver-neutral
// BedResult: U_mf and the background flow, the bubble at t_ref and its time series, the
// balances, the law's out-of-range count, the cost, and the model's own full result as JSON (what
// consumer results store). Models are registered by key, the scene's `[scene] solver`; `scene
// run`, `sensitivity`, work-precision and `regress` dispatch through the registry, so a new model
// (DBM) plugs in by registering, and scene validation accepts exactly the registered keys.
//
// Two hooks say what the studies (workflows/sensitivity.h) vary for a model:
//  - a realization is the random state every law and grid of one seed starts from, prepared once
//    per seed (DPM: a packing settled with scene.seed). A deterministic model has none
//    (realization_kind() empty) and its uncertainty comes from grids only;
//  - the time resolution is the one scene value that sets the model's time step, swept by the
//    work-precision study beside the grid (DPM: DEM steps per contact time; TFM: the CFL number).
//
// Built in: "dpm" (dpm.h, CFD-DEM), "tfm" (tfm.h, two-fluid with KTGF) and "dbm" (dbm.h, discrete
// bubbles in an emulsion; its realization is an injection seed, its time resolution dt_s). Units
// SI. Thread-safety: register before running; a registered model is immutable and may run on
// several threads.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "draglab/consumers/bubble.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/drag_db/law.h"

namespace draglab {
namespace consumers {

/// Run controls every model understands (tests and the CLI override a few scene values).
/// How Realize keeps a long preparation's work (BedModel::Realize).
struct RealizeOptions {
  /// A checkpoint file, written as the preparation goes and read when it starts; removed when it
  /// has finished. Empty: none. Models whose preparation is quick ignore it.
  std::string checkpoint_path;
  double checkpoint_interval_s = 600.0;  ///< Wall seconds between checkpoints, [0, 1e6].
};

struct BedRunOptions {
  double duration_s = 0.0;       ///< Simulated time; 0: the scene's, else > 0.
  std::string output_directory;  ///< For the files the scene asks for; empty: the model's default.
  bool IsValid(std::string* error) const;
};

/// What every model reports.
struct BedResult {
  std::string model;  ///< Registry key ("dpm").
  std::string law;    ///< name@version.
  std::string scene, scene_hash;
  ConsumerMetrics metrics;  ///< U_mf, background, bubble at t_ref, bed height, wall time.
  std::string background_mode;
  double eps_mf = 0.0;
  std::vector<BedSample> series;
  double max_relative_mass_imbalance = 0.0;  ///< Gas mass balance, max over steps.
  double momentum_mismatch = 0.0;            ///< Vertical momentum balance (model-defined).
  std::uint64_t law_out_of_range = 0;        ///< Clamped/extrapolated drag evaluations.
  double wall_s = 0.0;
  int threads = 1;
  std::vector<std::string> output_files;
  long steps = 0;                ///< Gas (DPM) or coupled (TFM) time steps.
  double mean_dt_s = 0.0;        ///< Simulated time / steps.
  std::int64_t inner_steps = 0;  ///< Steps inside the time steps (DPM: DEM steps); 0: none.
  double inner_dt_s = 0.0;       ///< Their step (DPM: the DEM step).
  std::int64_t void_fraction_clamps = 0;  ///< Cells whose gas fraction was clamped (DPM).
  /// The state at the sample nearest to t_ref (false: the run ended before it), for figures.
  bool has_snapshot = false;
  BedSnapshot snapshot;
  /// The model's headline numbers, named with their unit, for the studies (DBM: hold-up, mean
  /// bubble sizes at the report heights, circulation); empty for the jet-bubble models, whose
  /// headline is the bubble in `metrics`.
  std::vector<std::pair<std::string, double>> headline;
  /// The model's own error estimate of its first headline number, in its unit, and how it was
  /// made (DBM: the batch-means standard error of the time-averaged hold-up); negative: none
  /// (the jet-bubble models, whose estimate is the grid's cell).
  double headline_uncertainty = -1.0;
  std::string headline_uncertainty_method;
  std::string result_json;  ///< The model's full result (a JSON object with "solver": key).
  std::string brief;        ///< One-line report.
};

/// Progress: fraction in [0, 1] and a stage text.
using BedProgress = std::function<void(double fraction, const std::string& stage)>;

/// The random state a model's runs of one seed start from (see the file comment). Models derive
/// from it to hold their state (the DPM: the settled particles); callers see what it reports.
class BedRealization {
 public:
  virtual ~BedRealization() = default;
  std::uint64_t seed = 0;       ///< The scene seed it was prepared with.
  std::int64_t particles = 0;   ///< Particles in it (0 for a model without particles).
  double bed_height_m = 0.0;    ///< Its bed height (DPM: the settled bed).
  double prepare_wall_s = 0.0;  ///< What preparing it cost.
};

/// The scene value that sets a model's time step (see the file comment).
struct TimeResolution {
  std::string name;             ///< Its scene key and study column ("contact_steps", "cfl").
  std::string description;      ///< What it is, one phrase.
  std::string range;            ///< Allowed values, as the scene checks them ("[20, 1000]").
  bool whole_number = false;    ///< Only integers are allowed.
  bool larger_is_finer = true;  ///< Direction of refinement (CFL: smaller is finer).
  /// The command line's option for a list of values (`sensitivity --work-precision`); empty:
  /// "--" and the name with '-' for '_'.
  std::string flag;
  std::string example;  ///< A list of values for the option's help ("20,40").
};

/// TimeResolution::flag, or the one made from the name.
std::string time_resolution_flag(const TimeResolution& t);

/// What `scene check` reports of a model's own settings: one line for people and named numbers
/// for the JSON output.
struct BedModelSettings {
  std::string line;
  std::vector<std::pair<std::string, double>> numbers;
};

/// A key of a model's scene table and how it is read into the model's section.
using SceneKey = std::pair<std::string, std::function<void(SceneSection&, const SceneValue&)>>;

/// A key read into a member of the model's section type T: a number, a text or a flag.
template <typename T>
SceneKey scene_key(const std::string& name, double T::*member) {
  return {name, [member](SceneSection& s, const SceneValue& v) {
            static_cast<T&>(s).*member = v.number();
          }};
}
/// A whole number in [lo, hi], refused as the file is read (`what` names what it counts).
template <typename T>
SceneKey scene_key(const std::string& name, int T::*member, int lo, int hi,
                   const std::string& what = "") {
  return {name, [member, lo, hi, what](SceneSection& s, const SceneValue& v) {
            static_cast<T&>(s).*member = v.integer_in(lo, hi, what);
          }};
}
template <typename T>
SceneKey scene_key(const std::string& name, std::string T::*member) {
  return {name, [member](SceneSection& s, const SceneValue& v) {
            static_cast<T&>(s).*member = v.text();
          }};
}
template <typename T>
SceneKey scene_key(const std::string& name, bool T::*member) {
  return {name, [member](SceneSection& s, const SceneValue& v) {
            static_cast<T&>(s).*member = v.boolean();
          }};
}

/// A model's own table of scene files ([tfm], [dbm]): its keys, each read into the model's
/// SceneSection, and its checks of a scene. Scene files accept the tables of every registered
/// model; the checks run for every scene (a model refuses its table in another model's scene).
struct SceneTable {
  std::string name;  ///< The table's name, e.g. "tfm".
  /// A section holding the defaults.
  std::function<std::unique_ptr<SceneSection>()> make;
  /// The keys, in documentation order, and how each is read into the section.
  std::vector<SceneKey> keys;
  /// Keys that older scene files give in a shared table, as {key, that table} (the DPM's
  /// contact keys in [particles]): read into the section from there too. A key may stand in one
  /// place only; a shared table's own key of that name is read as well.
  std::vector<std::pair<std::string, std::string>> older_places;
  /// On failure *error names the field and the allowed range.
  std::function<bool(const Scene&, std::string*)> is_valid;
};

/// A bed model. Run throws draglab::Error as the model documents (invalid scene: kInvalidArgument;
/// a bed outside the law's validity box: kOutOfValidity; instability: with a diagnosis).
class BedModel {
 public:
  virtual ~BedModel() = default;
  virtual std::string key() const = 0;          ///< The `[scene] solver` value.
  virtual std::string description() const = 0;  ///< One line.
  /// The scene's settings that only this model reads (DPM: the contact time and DEM step; TFM:
  /// closures and step control), for `scene check`.
  virtual BedModelSettings Settings(const Scene& scene) const = 0;
  /// The model's own scene table; null: it has none (it reads only the shared tables).
  virtual const SceneTable* scene_table() const { return nullptr; }
  /// Whether the bed is a particle inventory ([particles] count or bed_height_mf_m, checked
  /// and turned into a bed height by the scene); false: the model's bed fills the column (the
  /// DBM's emulsion).
  virtual bool particle_bed() const { return true; }
  /// Whether the model runs beds of several particle sizes ([particles] diameters_m); a scene
  /// with size classes is refused for a model that does not.
  virtual bool polydisperse() const { return false; }

  /// What a realization is ("packing"); empty: the model is deterministic and has none.
  virtual std::string realization_kind() const { return ""; }
  /// Prepares the realization of scene.seed, to be passed to Run for every law and grid of that
  /// seed (`law` only for models whose preparation needs one). A preparation of hours (the DPM's
  /// settling) keeps a checkpoint at options.checkpoint_path and goes on from it when run again.
  /// Throws Error(kInvalidArgument) for a model without realizations.
  virtual std::shared_ptr<const BedRealization> Realize(const Scene& scene,
                                                        std::shared_ptr<const Law> law,
                                                        const BedProgress& progress,
                                                        const RealizeOptions& options) const;
  /// Writes a realization made by this model's Realize to `path` (atomically), so that a long
  /// study stopped part-way goes on without preparing it again; false: this model does not keep
  /// its realizations (the default). Throws Error(kIo) when the file cannot be written.
  virtual bool SaveRealization(const BedRealization& realization, const std::string& path) const;
  /// The realization SaveRealization wrote to `path`, bit for bit; null when the file is missing,
  /// is not such a file, or the model does not keep realizations.
  virtual std::shared_ptr<const BedRealization> LoadRealization(const std::string& path) const;

  virtual TimeResolution time_resolution() const = 0;
  /// The scene's value of time_resolution().name.
  virtual double time_resolution_of(const Scene& scene) const = 0;
  /// The scene with that value set (and whatever else must follow it); the caller validates.
  virtual Scene WithTimeResolution(const Scene& scene, double value) const = 0;

  /// The tolerances a regression baseline of `scene` gets unless given (`draglab regress`):
  /// how far a later law version may move this model's predictions before it counts as a
  /// change. Default: the bubble diameter within 2 gas cells (the larger cell side) + 10 % of
  /// the baseline's, U_mf within 1 % (bed_model.cc says why).
  virtual RegressionTolerances default_tolerances(const Scene& scene) const;

  /// One run. `start`: a realization of this model made by Realize with scene.seed (reused
  /// across laws and grids); null: the run prepares its own. Throws Error(kInvalidArgument) for
  /// a realization of another model or seed.
  virtual BedResult Run(const Scene& scene, std::shared_ptr<const Law> law,
                        const BedRunOptions& options, const BedProgress& progress,
                        const BedRealization* start = nullptr) const = 0;
};

/// Adds a model. Throws Error(kInvalidArgument) for an empty or already registered key.
void register_bed_model(std::unique_ptr<BedModel> model);
/// The registered keys, sorted.
std::vector<std::string> bed_model_keys();
/// Throws Error(kInvalidArgument) naming the registered keys when `key` is not one.
const BedModel& find_bed_model(const std::string& key);
/// Checks run controls against the scene before any work (a duration in place of the scene's
/// obeys the scene's rules: its range, t_ref and averaging windows inside it). Throws
/// Error(kInvalidArgument) naming the option.
void check_run_options(const Scene& scene, const BedRunOptions& options);
/// Runs `scene` with the model its `solver` names (from `start`, if given: see BedModel::Run),
/// after checking the options (check_run_options).
BedResult run_bed_model(const Scene& scene, std::shared_ptr<const Law> law,
                        const BedRunOptions& options = BedRunOptions(),
                        const BedProgress& progress = nullptr,
                        const BedRealization* start = nullptr);

/// The stored form of a run (provenance like laws and datasets: the scene's hash, the law's
/// name, version and content hash, the metrics and the model's full result JSON), as
/// `draglab scene run` and the regression checks store it.
ConsumerResult consumer_result(const Scene& scene, const Law& law, const BedResult& result);

}  // namespace consumers
}  // namespace draglab
