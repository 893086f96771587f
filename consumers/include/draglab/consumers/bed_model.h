// draglab/consumers/bed_model.h: the bundled fluidized-bed solvers as one family.
//
// A bed model runs a scene (scene.h) with one loaded drag law and returns a solver-neutral
// BedResult: U_mf and the background flow, the bubble at t_ref and its time series, the
// balances, the law's out-of-range count, the cost, and the model's own full result as JSON (what
// consumer results store). Models are registered by key, the scene's `[scene] solver`; `scene
// run` and `regress` dispatch through run_bed_model, so a new model (TFM, DBM) plugs in by
// registering, and scene validation accepts exactly the registered keys.
//
// Built in: "dpm" (dpm.h, CFD-DEM) and "tfm" (tfm.h, two-fluid with KTGF). Units SI. Thread-safety:
// register before running.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "draglab/consumers/bubble.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/drag_db/law.h"

namespace draglab {
namespace consumers {

/// Run controls every model understands (tests and the CLI override a few scene values).
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
  long steps = 0;          ///< Gas (DPM) or coupled (TFM) time steps.
  double mean_dt_s = 0.0;  ///< Simulated time / steps.
  /// The state at the sample nearest to t_ref (false: the run ended before it): the gas
  /// fraction on the scene's grid and the bubble measured in it, for figures.
  bool has_snapshot = false;
  double snapshot_t_s = 0.0;  ///< After the jet start.
  GridField2D snapshot_void_fraction;
  BubbleMetrics snapshot_bubble;
  std::string result_json;  ///< The model's full result (a JSON object with "solver": key).
  std::string brief;        ///< One-line report.
};

/// Progress: fraction in [0, 1] and a stage text.
using BedProgress = std::function<void(double fraction, const std::string& stage)>;

/// A bed model. Run throws draglab::Error as the model documents (invalid scene: kInvalidArgument;
/// a bed outside the law's validity box: kOutOfValidity; instability: with a diagnosis).
class BedModel {
 public:
  virtual ~BedModel() = default;
  virtual std::string key() const = 0;          ///< The `[scene] solver` value.
  virtual std::string description() const = 0;  ///< One line.
  virtual BedResult Run(const Scene& scene, std::shared_ptr<const Law> law,
                        const BedRunOptions& options, const BedProgress& progress) const = 0;
};

/// Adds a model. Throws Error(kInvalidArgument) for an empty or already registered key.
void register_bed_model(std::unique_ptr<BedModel> model);
/// The registered keys, sorted.
std::vector<std::string> bed_model_keys();
/// Throws Error(kInvalidArgument) naming the registered keys when `key` is not one.
const BedModel& find_bed_model(const std::string& key);
/// Runs `scene` with the model its `solver` names.
BedResult run_bed_model(const Scene& scene, std::shared_ptr<const Law> law,
                        const BedRunOptions& options = BedRunOptions(),
                        const BedProgress& progress = nullptr);

}  // namespace consumers
}  // namespace draglab
