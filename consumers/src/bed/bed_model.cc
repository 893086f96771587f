// The bed-model registry and dispatch by the scene's solver.
#include "draglab/consumers/bed_model.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include "bed/bed_sampling.h"
#include "bed/builtin_models.h"
#include "draglab/core/files.h"
#include "draglab/core/machine.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, std::unique_ptr<BedModel>> models;
};

void add(Registry& r, std::unique_ptr<BedModel> model) {
  if (!model || model->key().empty()) {
    throw Error(ErrorCode::kInvalidArgument, "bed model: a model needs a non-empty key");
  }
  const std::string key = model->key();
  if (!r.models.emplace(key, std::move(model)).second) {
    throw Error(ErrorCode::kInvalidArgument, "bed model '" + key + "' is already registered");
  }
}

Registry& registry() {
  static Registry* r = [] {
    auto* made = new Registry;
    add(*made, internal::make_dpm_bed_model());
    add(*made, internal::make_tfm_bed_model());
    add(*made, internal::make_dbm_bed_model());
    return made;
  }();
  return *r;
}

std::string joined_keys(const Registry& r) {
  std::string out;
  for (const auto& [key, model] : r.models) out += (out.empty() ? "" : ", ") + key;
  return out;
}

/// Memory of a bed model's grid per cell, the largest measured (`/usr/bin/time -f %M` of
/// `scene run` on tfm_bubble.toml at 30 x 120 and 60 x 240 cells: 27.0 and 46.0 MB, 1.8 kB per
/// cell for the two-fluid model's fields and implicit systems; the DBM's emulsion measured below
/// 1 kB per cell), rounded up.
constexpr double kGridBytesPerCell = 2048.0;
/// Share of the machine's memory a run may plan to take.
constexpr double kMemoryShare = 0.8;

/// The grid's memory against the machine, before any work: a grid that cannot fit is bad input
/// naming [grid] (it would otherwise allocate for a while and die in std::bad_alloc).
void check_grid_memory(const Scene& scene) {
  const double cells = static_cast<double>(scene.grid.cells_x) * scene.grid.cells_y *
                       scene.grid.cells_z;  // 1 for the pseudo-2D models
  const double bytes = kGridBytesPerCell * cells;
  const double memory = core::physical_memory_bytes();
  if (memory <= 0.0 || bytes <= kMemoryShare * memory) return;
  throw Error(ErrorCode::kInvalidArgument,
              "[grid] " + core::format_number(cells) + " cells (cells_x x cells_y" +
                  (scene.grid.cells_z > 1 ? " x cells_z" : "") + ") need about " +
                  core::format_number(bytes / 1073741824.0, 3) + " GiB, more than " +
                  core::format_number(100.0 * kMemoryShare, 2) + " % of this machine's " +
                  core::format_number(memory / 1073741824.0, 3) +
                  " GiB: use fewer cells (at most about " +
                  core::format_number(kMemoryShare * memory / kGridBytesPerCell, 3) + ")");
}

}  // namespace

bool BedRunOptions::IsValid(std::string* error) const {
  if (!std::isfinite(duration_s) || duration_s < 0.0) {
    if (error) *error = "duration_s must be finite and >= 0 (0: the scene's duration)";
    return false;
  }
  return true;
}

RegressionTolerances BedModel::default_tolerances(const Scene& scene) const {
  RegressionTolerances t;
  // Bubble diameter: bubble.h measures D from the cells above the threshold, so each run's D is
  // off by up to one cell size h (the boundary of the region is resolved to a cell); two runs
  // can differ by 2 h with no change in the physics. On top, 10 % of D: a single run of a DPM
  // bubble scatters with the packing and the chaotic particle motion (several % between
  // realizations of the same bed), and a drag law change smaller than that is not a change a
  // bubble prediction can show.
  const double dx = scene.geometry.width_m / std::max(scene.grid.cells_x, 1);
  const double dy = scene.geometry.height_m / std::max(scene.grid.cells_y, 1);
  t.diameter_abs_m = 2.0 * std::max(dx, dy);
  t.diameter_rel = 0.10;
  // U_mf comes from the law's force balance at eps_mf solved to 1e-12 (scene.h), with no
  // run-to-run scatter: 1 % is a real change of the law at incipient fluidization (the five
  // literature laws differ by 10-25 % there), small enough to catch a coefficient change that a
  // noisy bubble metric would hide.
  t.umf_rel = 0.01;
  return t;
}

void register_bed_model(std::unique_ptr<BedModel> model) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  add(r, std::move(model));
}

std::string time_resolution_flag(const TimeResolution& t) {
  if (!t.flag.empty()) return t.flag;
  std::string flag = "--" + t.name;
  for (char& c : flag) c = c == '_' ? '-' : c;
  return flag;
}

std::vector<std::string> bed_model_keys() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> keys;
  for (const auto& [key, model] : r.models) keys.push_back(key);
  return keys;
}

const BedModel& find_bed_model(const std::string& key) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.models.find(key);
  if (it == r.models.end()) {
    throw Error(ErrorCode::kInvalidArgument,
                "[scene] solver = '" + key +
                    "' is not a registered bed model (registered: " + joined_keys(r) + ")");
  }
  return *it->second;
}

std::shared_ptr<const BedRealization> BedModel::Realize(const Scene&, std::shared_ptr<const Law>,
                                                        const BedProgress&,
                                                        const RealizeOptions&) const {
  throw Error(ErrorCode::kInvalidArgument,
              "bed model '" + key() + "' is deterministic: it has no realizations to prepare");
}

bool BedModel::SaveRealization(const BedRealization&, const std::string&) const { return false; }

std::shared_ptr<const BedRealization> BedModel::LoadRealization(const std::string&) const {
  return nullptr;
}

ConsumerResult consumer_result(const Scene& scene, const Law& law, const BedResult& result) {
  ConsumerResult stored;
  stored.scene_name = scene.name;
  stored.scene_hash = scene.hash();
  stored.law_name = law.record().name;
  stored.law_version = law.record().version;
  stored.law_content_hash = law.record().content_hash;
  stored.metrics = result.metrics;
  stored.result_json = result.result_json;
  return stored;
}

void check_run_options(const Scene& scene, const BedRunOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, "bed run options: " + why);
  if (options.duration_s > 0.0) {
    // A duration given in place of the scene's obeys the scene's rules (its range, t_ref and
    // every averaging window inside it), checked here before any work rather than found at the
    // end of the run.
    Scene with_duration = scene;
    with_duration.time.duration_s = options.duration_s;
    if (!with_duration.IsValid(&why)) {
      throw Error(ErrorCode::kInvalidArgument,
                  "the duration " + core::format_number(options.duration_s) +
                      " s given for the run (--duration, in place of [time] duration_s): " + why);
    }
  }
}

BedResult run_bed_model(const Scene& scene, std::shared_ptr<const Law> law,
                        const BedRunOptions& options, const BedProgress& progress,
                        const BedRealization* start) {
  check_run_options(scene, options);
  check_grid_memory(scene);
  if (scene.outputs.fields || scene.outputs.particles) {
    // Before the settling or the first step, not when the first file is due.
    core::check_output_directory(
        internal::scene_output_directory(scene, options.output_directory),
        options.output_directory.empty() ? "[outputs] directory" : "the output directory");
  }
  return find_bed_model(scene.solver).Run(scene, std::move(law), options, progress, start);
}

}  // namespace consumers
}  // namespace draglab
