// The DPM (CFD-DEM, dpm.h) as a bed model: one coupled run of the scene, its result in the
// family's neutral form, and its full DpmResult as the stored JSON.
#include <memory>
#include <string>

#include "bed/builtin_models.h"
#include "draglab/consumers/dpm.h"
#include "draglab/consumers/regress.h"

namespace draglab {
namespace consumers {
namespace {

class DpmBedModel : public BedModel {
 public:
  std::string key() const override { return "dpm"; }
  std::string description() const override {
    return "CFD-DEM: soft-sphere particles in a volume-averaged gas (dpm.h)";
  }
  BedResult Run(const Scene& scene, std::shared_ptr<const Law> law, const BedRunOptions& options,
                const BedProgress& progress) const override {
    // U_mf and the time steps first: a law whose validity box excludes the bed fails here, in
    // microseconds, rather than after the settling.
    derive_scene(scene, *law);
    DpmOptions dpm;
    dpm.duration_s = options.duration_s;
    dpm.output_directory = options.output_directory;
    DpmSimulation simulation(scene, law, dpm);
    const DpmResult r = simulation.Run(progress);
    BedResult out;
    out.model = key();
    out.law = r.law;
    out.scene = r.scene;
    out.scene_hash = r.scene_hash;
    out.metrics = consumer_metrics_of(r);
    out.background_mode = r.background_mode;
    out.eps_mf = r.eps_mf;
    out.series = r.series;
    out.max_relative_mass_imbalance = r.max_relative_mass_imbalance;
    out.momentum_mismatch = r.momentum_mismatch;
    out.law_out_of_range = r.law_out_of_range;
    out.wall_s = r.wall_s;
    out.threads = r.threads;
    out.output_files = r.output_files;
    out.steps = r.gas_steps;
    out.mean_dt_s = r.gas_dt_s;
    out.has_snapshot = r.has_snapshot;
    if (r.has_snapshot) {
      out.snapshot_t_s = r.snapshot.t_s;
      out.snapshot_void_fraction = r.snapshot.void_fraction;
      out.snapshot_bubble = r.snapshot.bubble;
    }
    out.result_json = dpm_result_json(r);
    out.brief = r.BriefReport();
    return out;
  }
};

}  // namespace

namespace internal {
std::unique_ptr<BedModel> make_dpm_bed_model() { return std::make_unique<DpmBedModel>(); }
}  // namespace internal

}  // namespace consumers
}  // namespace draglab
