// The DPM (CFD-DEM, dpm.h) as a bed model: one coupled run of the scene, its result in the
// family's neutral form, and its full DpmResult as the stored JSON. Its realization is a packing
// settled with the scene's seed; its time resolution the DEM steps per contact time.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "bed/bed_sampling.h"
#include "bed/builtin_models.h"
#include "dpm/dpm_scene.h"
#include "draglab/consumers/dpm.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

std::string Num(double x) { return core::format_number(x, 3); }

/// A settled packing of one seed.
class DpmPacking : public BedRealization {
 public:
  Particles settled;
};

// A packing's file (SaveRealization): this magic line, then seed, particle count, settled bed
// height and preparation time, then the particle arrays, each whole, in native byte order (the
// file serves a study resumed on the machine that stopped it).
constexpr char kPackingMagic[] = "draglab dpm packing 1\n";
constexpr std::size_t kPackingMagicSize = sizeof(kPackingMagic) - 1;

/// The particle arrays of a packing file, in their order.
std::vector<std::vector<double>*> PackingArrays(Particles& p) {
  return {&p.x,  &p.y,  &p.z,      &p.vx,     &p.vy,     &p.vz,       &p.wx,
          &p.wy, &p.wz, &p.fx_ext, &p.fy_ext, &p.fz_ext, &p.diameter, &p.density};
}

struct PackingHeader {
  std::uint64_t seed = 0;
  std::int64_t particles = 0;
  double bed_height_m = 0.0;
  double prepare_wall_s = 0.0;
};

void SavePacking(const DpmPacking& packing, const std::string& path) {
  Particles copy = packing.settled;  // PackingArrays takes mutable arrays
  const PackingHeader header{packing.seed, static_cast<std::int64_t>(copy.size()),
                             packing.bed_height_m, packing.prepare_wall_s};
  std::vector<core::FilePiece> pieces = {{kPackingMagic, kPackingMagicSize},
                                         {&header, sizeof(header)}};
  for (std::vector<double>* a : PackingArrays(copy))
    pieces.push_back({a->data(), a->size() * sizeof(double)});
  pieces.push_back({copy.id.data(), copy.id.size() * sizeof(std::int64_t)});
  core::write_file_atomically(path, pieces, "packing state file");
}

std::shared_ptr<const BedRealization> LoadPacking(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return nullptr;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  PackingHeader header;
  if (bytes.size() < kPackingMagicSize + sizeof(header) ||
      bytes.compare(0, kPackingMagicSize, kPackingMagic) != 0)
    return nullptr;
  std::memcpy(&header, bytes.data() + kPackingMagicSize, sizeof(header));
  auto packing = std::make_shared<DpmPacking>();
  const auto n = static_cast<std::size_t>(header.particles);
  const std::size_t arrays = PackingArrays(packing->settled).size();
  if (header.particles < 0 ||
      bytes.size() !=
          kPackingMagicSize + sizeof(header) + n * (arrays * sizeof(double) + sizeof(std::int64_t)))
    return nullptr;
  const char* at = bytes.data() + kPackingMagicSize + sizeof(header);
  for (std::vector<double>* a : PackingArrays(packing->settled)) {
    a->resize(n);
    std::memcpy(a->data(), at, n * sizeof(double));
    at += n * sizeof(double);
  }
  packing->settled.id.resize(n);
  std::memcpy(packing->settled.id.data(), at, n * sizeof(std::int64_t));
  std::string why;
  if (!packing->settled.IsValid(&why)) return nullptr;
  packing->seed = header.seed;
  packing->particles = header.particles;
  packing->bed_height_m = header.bed_height_m;
  packing->prepare_wall_s = header.prepare_wall_s;
  return packing;
}

class DpmBedModel : public BedModel {
 public:
  std::string key() const override { return "dpm"; }
  std::string description() const override {
    return "CFD-DEM: soft-sphere particles in a volume-averaged gas (dpm.h)";
  }

  const SceneTable* scene_table() const override { return &dem_scene_table(); }
  bool polydisperse() const override { return true; }

  BedModelSettings Settings(const Scene& scene) const override {
    // The contact model matters to the DEM only.
    const double t_c = contact_time_s(scene);
    const int contact_steps = dem_section(scene).contact_steps;
    const double dem_dt = t_c / contact_steps;
    BedModelSettings s;
    s.line = "contact time t_c = " + Num(t_c) + " s -> DEM step " + Num(dem_dt) + " s (t_c/" +
             std::to_string(contact_steps) + ")";
    s.numbers = {{"contact_time_s", t_c}, {"recommended_dem_dt_s", dem_dt}};
    return s;
  }

  std::string realization_kind() const override { return "packing"; }

  std::shared_ptr<const BedRealization> Realize(const Scene& scene, std::shared_ptr<const Law> law,
                                                const BedProgress& progress,
                                                const RealizeOptions& options) const override {
    const auto t0 = std::chrono::steady_clock::now();
    DpmOptions settle;
    settle.settle_checkpoint_path = options.checkpoint_path;
    settle.settle_checkpoint_interval_s = options.checkpoint_interval_s;
    DpmSimulation settler(scene, std::move(law), settle);  // settling has no gas
    settler.Settle(progress);
    auto packing = std::make_shared<DpmPacking>();
    packing->settled = settler.dem().particles();
    packing->seed = scene.seed;
    packing->particles = static_cast<std::int64_t>(packing->settled.size());
    packing->bed_height_m = settler.settled_bed_height_m();
    packing->prepare_wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return packing;
  }

  bool SaveRealization(const BedRealization& realization, const std::string& path) const override {
    const auto* packing = dynamic_cast<const DpmPacking*>(&realization);
    if (!packing)
      throw Error(ErrorCode::kInvalidArgument,
                  "dpm: the given realization was not made by the dpm model");
    SavePacking(*packing, path);
    return true;
  }
  std::shared_ptr<const BedRealization> LoadRealization(const std::string& path) const override {
    return LoadPacking(path);
  }

  TimeResolution time_resolution() const override {
    return {"contact_steps",
            "DEM steps per contact time (the DEM step is t_c / contact_steps)",
            "[20, 1000]",
            /*whole_number=*/true,
            /*larger_is_finer=*/true,
            "--contact-steps",
            "20,40"};
  }
  double time_resolution_of(const Scene& scene) const override {
    return dem_section(scene).contact_steps;
  }
  Scene WithTimeResolution(const Scene& scene, double value) const override {
    // The scene's own check names the range; a value beyond int must not wrap on the way there.
    if (!(std::abs(value) < 1e9)) {
      throw Error(ErrorCode::kInvalidArgument,
                  "[dem] contact_steps = " + core::format_number(value) + " is outside [20, 1000]");
    }
    Scene s = scene;
    dem_section(s).contact_steps = static_cast<int>(value);
    dem_section(s).dem_dt_s = 0.0;  // the DEM step follows contact_steps
    return s;
  }

  BedResult Run(const Scene& scene, std::shared_ptr<const Law> law, const BedRunOptions& options,
                const BedProgress& progress, const BedRealization* start) const override {
    const DpmPacking* packing = nullptr;
    if (start) {
      packing = dynamic_cast<const DpmPacking*>(start);
      if (!packing)
        throw Error(ErrorCode::kInvalidArgument,
                    "dpm: the given realization was not made by the dpm model");
      if (packing->seed != scene.seed)
        throw Error(ErrorCode::kInvalidArgument,
                    "dpm: the packing was settled with seed " + std::to_string(packing->seed) +
                        ", the scene asks for seed " + std::to_string(scene.seed));
    }
    // U_mf and the time steps first: a law whose validity box excludes the bed fails here, in
    // microseconds, rather than after the settling.
    derive_scene(scene, *law);
    DpmOptions dpm;
    dpm.duration_s = options.duration_s;
    dpm.output_directory = options.output_directory;
    DpmSimulation simulation(scene, law, dpm);
    if (packing) simulation.Start(packing->settled);
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
    out.inner_steps = r.dem_steps;
    out.inner_dt_s = r.dem_dt_s;
    out.void_fraction_clamps = r.void_fraction_clamps;
    out.has_snapshot = r.has_snapshot;
    if (r.has_snapshot) out.snapshot = r.snapshot;
    out.result_json = dpm_result_json(r);
    out.brief = r.BriefReport();
    return out;
  }
};

}  // namespace

ConsumerMetrics consumer_metrics_of(const DpmResult& r) {
  ConsumerMetrics m;
  m.umf_m_s = r.umf_m_s;
  m.background_m_s = r.background_m_s;
  m.t_ref_s = r.t_ref_s;
  m.bubble_present = r.bubble_at_t_ref;
  m.bubble_diameter_m = r.bubble_at_t_ref ? r.bubble_diameter_m : 0.0;
  // The centroid of the same sample as the diameter (nearest to t_ref).
  const DpmSample* at_ref = nullptr;
  for (const DpmSample& s : r.series) {
    if (!at_ref || std::abs(s.t_s - r.t_ref_s) < std::abs(at_ref->t_s - r.t_ref_s)) at_ref = &s;
    m.max_bed_height_m = std::max(m.max_bed_height_m, s.bed_height_m);
  }
  m.bubble_centroid_m = r.bubble_at_t_ref && at_ref ? at_ref->bubble_centroid_m : 0.0;
  m.wall_s = r.wall_s;
  return m;
}

std::string dpm_result_json(const DpmResult& r) {
  nlohmann::json series = nlohmann::json::array();
  for (const DpmSample& s : r.series) {
    series.push_back({{"t_s", s.t_s},
                      {"bubble_diameter_m", s.bubble_diameter_m},
                      {"bubble_centroid_m", s.bubble_centroid_m},
                      {"bed_height_m", s.bed_height_m},
                      {"pressure_drop_pa", s.pressure_drop_pa},
                      {"segregation_index", s.segregation_index}});
  }
  nlohmann::json j = {
      {"solver", "dpm"},
      {"scene", r.scene},
      {"scene_hash", r.scene_hash},
      {"law", r.law},
      {"umf_m_s", r.umf_m_s},
      {"background_m_s", r.background_m_s},
      {"background", r.background_mode},
      {"eps_mf", r.eps_mf},
      {"t_ref_s", r.t_ref_s},
      {"bubble_at_t_ref", r.bubble_at_t_ref},
      {"bubble_diameter_m",
       r.bubble_at_t_ref ? nlohmann::json(r.bubble_diameter_m) : nlohmann::json(nullptr)},
      {"series", series},
      {"particles", r.particles},
      {"settled_bed_height_m", r.settled_bed_height_m},
      {"gas_dt_s", r.gas_dt_s},
      {"dem_dt_s", r.dem_dt_s},
      {"threads", r.threads},
      {"gas_steps", r.gas_steps},
      {"dem_steps", r.dem_steps},
      {"settle_wall_s", r.settle_wall_s},
      {"wall_s", r.wall_s},
      {"max_relative_gas_mass_imbalance", r.max_relative_mass_imbalance},
      {"momentum_mismatch", r.momentum_mismatch},
      {"max_action_reaction_mismatch_n", r.max_action_reaction_mismatch_n},
      {"void_fraction_clamps", r.void_fraction_clamps},
      {"drag_out_of_range", r.law_out_of_range},
      {"eps_packing", r.eps_packing},
      {"umf_packing_m_s", r.umf_packing_m_s},
      {"umf_extrapolation",
       r.umf_extrapolation.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.umf_extrapolation)},
      {"output_files", r.output_files}};
  if (r.has_snapshot) j["snapshot"] = internal::snapshot_json(r.snapshot.t_s, r.snapshot.bubble);
  return j.dump();
}

namespace internal {
std::unique_ptr<BedModel> make_dpm_bed_model() { return std::make_unique<DpmBedModel>(); }
}  // namespace internal

}  // namespace consumers
}  // namespace draglab
