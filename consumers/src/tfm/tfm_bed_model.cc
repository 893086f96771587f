// The two-fluid model (tfm.h) as a bed model: the scene's bed, uniform at eps_mf up to its
// minimum-fluidization height, fluidized at the law's U_mf (or the scene's fixed velocity), one
// bubble injected by the jet; bubble metrics sampled like every bed model (bed_sampling.h).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bed/bed_sampling.h"
#include "bed/builtin_models.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "io/bed_output.h"
#include "tfm/tfm.h"
#include "tfm/tfm_scene.h"

namespace draglab {
namespace consumers {
namespace {

std::string Num(double x) { return core::format_number(x, 4); }

/// The two-fluid model's options for a scene whose background is `background_m_s`.
TfmOptions SceneTfmOptions(const Scene& s, double background_m_s) {
  TfmOptions o;
  o.gas = internal::scene_gas_options(s, background_m_s, /*with_jet=*/true);
  o.particle_diameter_m = s.particles.diameter_m;
  o.particle_density_kg_m3 = s.particles.density_kg_m3;
  o.ktgf = internal::scene_ktgf_options(s);
  o.initial_solids = 1.0 - s.eps_mf;
  const SceneTfm& t = tfm_section(s);
  o.initial_bed_height_m = s.bed_height_mf_m();
  o.initial_theta_m2_s2 = t.theta_initial_m2_s2;
  o.residual_solids = t.residual_solids;
  o.cfl = t.cfl;
  o.dt_max_s = t.dt_max_s;
  o.fixed_dt_s = s.time.gas_dt_s;
  o.solids_walls = t.solids_walls == "no_slip" ? WallSlip::kNoSlip : WallSlip::kFreeSlip;
  o.fraction_scheme =
      t.fraction_scheme == "van_leer" ? FractionScheme::kVanLeer : FractionScheme::kUpwind;
  o.solids_viscosity = t.solids_viscosity == "point_implicit" ? SolidsViscosity::kPointImplicit
                                                              : SolidsViscosity::kExplicit;
  o.solids_pressure =
      t.solids_pressure == "implicit" ? SolidsPressure::kImplicit : SolidsPressure::kExplicit;
  o.granular_temperature = t.granular_temperature == "algebraic" ? GranularTemperature::kAlgebraic
                                                                 : GranularTemperature::kTransport;
  return o;
}

/// The two-fluid model's cell fields for the output files (bed_output.h layout).
CellFields TfmCellFields(const TfmSimulation& tfm) {
  const TfmOptions& o = tfm.options();
  CellFields c;
  c.nx = o.gas.nx;
  c.nz = o.gas.nz;
  c.dx = tfm.dx();
  c.dz = tfm.dz();
  c.depth = o.gas.depth_m;
  Eigen::ArrayXXd ux(c.nx, c.nz), uz(c.nx, c.nz), vx(c.nx, c.nz), vz(c.nx, c.nz);
  for (int j = 0; j < c.nz; ++j) {
    for (int i = 0; i < c.nx; ++i) {
      ux(i, j) = 0.5 * (tfm.gas_u()(i, j) + tfm.gas_u()(i + 1, j));
      uz(i, j) = 0.5 * (tfm.gas_w()(i, j) + tfm.gas_w()(i, j + 1));
      vx(i, j) = 0.5 * (tfm.solids_u()(i, j) + tfm.solids_u()(i + 1, j));
      vz(i, j) = 0.5 * (tfm.solids_w()(i, j) + tfm.solids_w()(i, j + 1));
    }
  }
  c.arrays = {{"eps", tfm.gas_fraction()},
              {"phi", tfm.solids_fraction()},
              {"p", tfm.pressure()},
              {"u_x", ux},
              {"u_z", uz},
              {"v_x", vx},
              {"v_z", vz},
              {"theta", tfm.theta()},
              {"beta", tfm.beta()}};
  return c;
}

/// What the two-fluid model refuses before any work: a realization, an off-centre jet,
/// particle output.
void CheckScene(const Scene& scene, const BedRealization* start) {
  if (start)
    throw Error(ErrorCode::kInvalidArgument,
                "tfm: the two-fluid model is deterministic and starts from no realization");
  if (std::abs(scene.jet_center_m() - 0.5 * scene.geometry.width_m) > 1e-9 * scene.geometry.width_m)
    throw Error(ErrorCode::kInvalidArgument,
                "[jet] center_m: the gas inflow supports only a central slot (width / 2 = " +
                    Num(0.5 * scene.geometry.width_m) + " m), got " + Num(scene.jet_center_m()));
  if (scene.outputs.particles)
    throw Error(ErrorCode::kInvalidArgument,
                "[outputs] particles = true: the two-fluid model has no particles (its solids "
                "fraction, velocities and theta are cell fields: [outputs] fields = true)");
}

/// Where the run stops: every sample, and every field output (each outputs.interval_s, or once
/// at t_ref when it is 0) when fields are written, in time order: (time, is a field output).
std::vector<std::pair<double, bool>> StopsOf(const Scene& scene, double duration) {
  std::vector<std::pair<double, bool>> stops;
  for (const double t : internal::sample_times(duration, scene.bubble.sample_interval_s))
    stops.push_back({t, false});
  if (scene.outputs.fields) {
    const double t_ref_abs = scene.jet.start_s + scene.time.t_ref_s;
    if (scene.outputs.interval_s > 0.0) {
      for (int k = 1; k * scene.outputs.interval_s <= duration * (1.0 + 1e-12); ++k)
        stops.push_back({k * scene.outputs.interval_s, true});
    } else if (t_ref_abs <= duration) {
      stops.push_back({t_ref_abs, true});
    }
  }
  std::stable_sort(stops.begin(), stops.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  return stops;
}

/// What the sampling loop records besides the bed series: the JSON series and the sample
/// nearest t_ref with its bubble.
struct TfmSeries {
  nlohmann::json series = nlohmann::json::array();
  BedSample at_ref;
  bool have_ref = false;
  BubbleMetrics ref_bubble;
};

/// Runs the model to `duration` through `stops`, sampling the bed (into out: series, snapshot
/// field, largest bed height) and writing the fields at the output stops.
TfmSeries SampleRun(TfmSimulation& tfm, const Scene& scene, double duration,
                    const std::vector<std::pair<double, bool>>& stops, BedOutputWriter* writer,
                    const BedProgress& progress, BedResult* out) {
  internal::BedSampler sampler(scene, scene.bed_height_mf_m());
  const double dz = tfm.dz();
  TfmSeries s;
  for (const auto& [t, is_output] : stops) {
    tfm.AdvanceTo(t);
    if (is_output) {
      writer->WriteFields(tfm.time(), TfmCellFields(tfm));
      continue;
    }
    const internal::BedSampler::Taken taken = sampler.Take(
        tfm.time(), tfm.gas_fraction(), tfm.PressureDrop(0.5 * dz, scene.geometry.height_m));
    const BedSample& smp = taken.sample;
    out->series.push_back(smp);
    out->metrics.max_bed_height_m = std::max(out->metrics.max_bed_height_m, smp.bed_height_m);
    if (taken.nearest_to_ref) {
      s.at_ref = smp;
      s.have_ref = true;
      s.ref_bubble = taken.bubble;
      out->snapshot.void_fraction = internal::scene_grid_field(scene, tfm.gas_fraction());
    }
    s.series.push_back({{"t_s", smp.t_s},
                        {"bubble_diameter_m", smp.bubble_diameter_m},
                        {"bubble_centroid_m", smp.bubble_centroid_m},
                        {"bed_height_m", smp.bed_height_m},
                        {"pressure_drop_pa", smp.pressure_drop_pa},
                        {"dt_s", tfm.diagnostics().last_dt_s}});
    if (progress) {
      progress(t / duration, "two-fluid run, dt " + Num(tfm.diagnostics().last_dt_s) + " s (" +
                                 to_string(tfm.diagnostics().last_limit) + ")");
    }
  }
  if (tfm.time() < duration) tfm.AdvanceTo(duration);
  return s;
}

double SolidsMassChange(const TfmDiagnostics& dg) {
  return dg.initial_solids_mass_kg > 0.0
             ? (dg.solids_mass_kg - dg.initial_solids_mass_kg) / dg.initial_solids_mass_kg
             : 0.0;
}

nlohmann::json ResultJson(const TfmSimulation& tfm, const Scene& scene, const BedResult& out,
                          const TfmSeries& s) {
  const TfmDiagnostics& dg = tfm.diagnostics();
  const ConsumerMetrics& m = out.metrics;
  nlohmann::json limits = nlohmann::json::object();
  for (int k = 0; k < 7; ++k) {
    if (dg.steps_by_limit[k] > 0)
      limits[to_string(static_cast<TfmStepLimit>(k))] = dg.steps_by_limit[k];
  }
  const TfmOptions& o = tfm.options();
  nlohmann::json j = {
      {"solver", "tfm"},
      {"scene", out.scene},
      {"scene_hash", out.scene_hash},
      {"law", out.law},
      {"umf_m_s", m.umf_m_s},
      {"background_m_s", m.background_m_s},
      {"background", out.background_mode},
      {"eps_mf", scene.eps_mf},
      {"t_ref_s", m.t_ref_s},
      {"bubble_at_t_ref", m.bubble_present},
      {"bubble_diameter_m",
       m.bubble_present ? nlohmann::json(m.bubble_diameter_m) : nlohmann::json(nullptr)},
      {"series", s.series},
      {"grid", {{"cells_x", o.gas.nx}, {"cells_y", o.gas.nz}}},
      {"closures",
       {{"set", to_string(o.ktgf.closures)},
        {"radial_distribution", to_string(o.ktgf.radial)},
        {"restitution", o.ktgf.restitution},
        {"packing_limit", o.ktgf.packing_limit},
        {"friction", to_string(o.ktgf.friction)},
        {"friction_min_solids", o.ktgf.friction_min_solids},
        {"friction_angle_deg", o.ktgf.friction_angle_deg},
        {"friction_delta", o.ktgf.friction_delta},
        {"friction_max_viscosity_pa_s", o.ktgf.friction_max_viscosity_pa_s},
        {"knudsen_length_m", o.ktgf.knudsen_length_m},
        {"granular_temperature",
         o.granular_temperature == GranularTemperature::kAlgebraic ? "algebraic" : "transport"}}},
      {"numerics",
       {{"fraction_scheme", o.fraction_scheme == FractionScheme::kVanLeer ? "van_leer" : "upwind"},
        {"solids_viscosity",
         o.solids_viscosity == SolidsViscosity::kPointImplicit ? "point_implicit" : "explicit"},
        {"solids_pressure",
         o.solids_pressure == SolidsPressure::kImplicit ? "implicit" : "explicit"},
        {"solids_walls", o.solids_walls == WallSlip::kNoSlip ? "no_slip" : "free_slip"},
        {"cfl", o.cfl},
        {"dt_max_s", o.dt_max_s}}},
      {"steps", dg.steps},
      {"dt_min_s", dg.min_dt_s},
      {"dt_mean_s", dg.steps > 0 ? tfm.time() / static_cast<double>(dg.steps) : 0.0},
      {"steps_by_limit", limits},
      {"max_wave_speed_m_s", dg.max_wave_speed_m_s},
      {"max_solids_fraction", dg.max_solids_fraction},
      {"max_theta_m2_s2", dg.max_theta_m2_s2},
      {"flux_limited_faces", dg.flux_limited_faces},
      {"implicit_viscosity_faces", dg.implicit_viscosity_faces},
      {"max_pressure_correction", dg.max_pressure_correction},
      {"positivity_limited_cells", dg.positivity_limited_cells},
      {"packing_limited_cells", dg.packing_limited_cells},
      {"relative_solids_mass_change", SolidsMassChange(dg)},
      {"max_relative_gas_mass_imbalance", out.max_relative_mass_imbalance},
      {"momentum_mismatch", nullptr},
      {"drag_out_of_range", out.law_out_of_range},
      {"threads", out.threads},
      {"wall_s", out.wall_s},
      {"output_files", out.output_files}};
  if (s.have_ref) j["snapshot"] = internal::snapshot_json(s.at_ref.t_s, s.ref_bubble);
  return j;
}

std::string BriefReport(const TfmSimulation& tfm, const Scene& scene, const BedResult& out) {
  const TfmDiagnostics& dg = tfm.diagnostics();
  const ConsumerMetrics& m = out.metrics;
  const TfmOptions& o = tfm.options();
  std::ostringstream brief;
  brief << "TFM " << scene.name << " with " << out.law << ": U_mf = " << Num(m.umf_m_s)
        << " m/s, background = " << Num(m.background_m_s) << " m/s (" << out.background_mode
        << "), eps_mf = " << scene.eps_mf << "; " << o.gas.nx << " x " << o.gas.nz << " cells, "
        << dg.steps << " steps (dt min " << Num(dg.min_dt_s) << " s, mean "
        << Num(dg.steps > 0 ? tfm.time() / dg.steps : 0.0) << " s); wall " << Num(out.wall_s)
        << " s\n  bubble D at t_ref = " << Num(scene.time.t_ref_s)
        << " s: " << (m.bubble_present ? Num(m.bubble_diameter_m) + " m" : std::string("none"))
        << "\n  solids mass change " << Num(SolidsMassChange(dg)) << " (rel.), gas mass imbalance "
        << Num(out.max_relative_mass_imbalance) << " (rel.), max phi "
        << Num(dg.max_solids_fraction) << ", flux-limited faces " << dg.flux_limited_faces
        << ", drag out of range " << out.law_out_of_range;
  return brief.str();
}

class TfmBedModel : public BedModel {
 public:
  std::string key() const override { return "tfm"; }
  const SceneTable* scene_table() const override { return &tfm_scene_table(); }
  std::string description() const override {
    return "two-fluid model with the kinetic theory of granular flow (tfm.h)";
  }
  BedModelSettings Settings(const Scene& scene) const override {
    const KtgfOptions k = internal::scene_ktgf_options(scene);
    const SceneTfm& t = tfm_section(scene);
    BedModelSettings s;
    s.line = "two-fluid: " + t.closures + " closures, g0 " + t.radial_distribution +
             ", e = " + Num(k.restitution) + ", packing limit " + Num(k.packing_limit) +
             ", friction " + t.friction + "; solids pressure " + t.solids_pressure +
             ", viscosity " + t.solids_viscosity + "; adaptive step (CFL " + Num(t.cfl) +
             ", at most " + Num(t.dt_max_s) + " s)";
    s.numbers = {{"cfl", t.cfl},
                 {"dt_max_s", t.dt_max_s},
                 {"packing_limit", k.packing_limit},
                 {"restitution", k.restitution}};
    return s;
  }

  TimeResolution time_resolution() const override {
    return {"cfl",
            "Courant number of the coupled step (the step is also bounded by [tfm] dt_max_s and "
            "the granular pressure wave)",
            "(0, 0.5]",
            /*whole_number=*/false,
            /*larger_is_finer=*/false,
            "--cfl",
            "0.3,0.15"};
  }
  double time_resolution_of(const Scene& scene) const override { return tfm_section(scene).cfl; }
  Scene WithTimeResolution(const Scene& scene, double value) const override {
    Scene s = scene;
    tfm_section(s).cfl = value;
    return s;
  }

  BedResult Run(const Scene& scene, std::shared_ptr<const Law> law, const BedRunOptions& options,
                const BedProgress& progress, const BedRealization* start) const override {
    const auto t0 = std::chrono::steady_clock::now();
    scene.Validate();
    if (!law) throw Error(ErrorCode::kInvalidArgument, "tfm: law is null");
    CheckScene(scene, start);
    // U_mf first: a law whose validity box excludes the bed fails here, before any step.
    const SceneDerived derived = derive_scene(scene, *law);
    // The TFM bed starts uniform at eps_mf, so its packing is the eps_mf state: "umf_packing"
    // is "umf" here.
    const double background = derived.background_m_s;
    TfmSimulation tfm(SceneTfmOptions(scene, background), law);
    const double duration = options.duration_s > 0.0 ? options.duration_s : scene.time.duration_s;

    BedResult out = internal::result_header(key(), scene, law->record().reference(),
                                            to_string(scene.distributor.mode));
    ConsumerMetrics& m = out.metrics;
    m.umf_m_s = derived.umf.umf_m_s;
    m.background_m_s = background;
    m.t_ref_s = scene.time.t_ref_s;
    std::unique_ptr<BedOutputWriter> writer;
    if (scene.outputs.fields) {
      const std::string dir = internal::scene_output_directory(scene, options.output_directory);
      writer = std::make_unique<BedOutputWriter>(scene, out.law, dir, true, false);
    }
    TfmSeries s;
    try {
      s = SampleRun(tfm, scene, duration, StopsOf(scene, duration), writer.get(), progress, &out);
      if (writer) {
        writer->Finish();
        out.output_files = writer->files();
      }
    } catch (const Error& e) {
      throw Error(e.code(), "tfm " + scene.name + " with " + out.law + ": " + e.what());
    }
    const TfmDiagnostics& dg = tfm.diagnostics();
    m.bubble_present = s.have_ref && s.ref_bubble.found;
    m.bubble_diameter_m = m.bubble_present ? s.at_ref.bubble_diameter_m : 0.0;
    m.bubble_centroid_m = m.bubble_present ? s.at_ref.bubble_centroid_m : 0.0;
    out.max_relative_mass_imbalance =
        dg.gas_mass_in_kg > 0.0 ? std::abs(dg.gas_mass_imbalance_kg) / dg.gas_mass_in_kg : 0.0;
    out.momentum_mismatch = 0.0;
    out.law_out_of_range = law->out_of_range_count();
    out.threads = 1;
    out.steps = dg.steps;
    out.mean_dt_s = dg.steps > 0 ? tfm.time() / static_cast<double>(dg.steps) : 0.0;
    out.has_snapshot = s.have_ref;
    out.snapshot.t_s = s.at_ref.t_s;
    out.snapshot.bubble = s.ref_bubble;
    out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m.wall_s = out.wall_s;
    out.result_json = ResultJson(tfm, scene, out, s).dump();
    out.brief = BriefReport(tfm, scene, out);
    return out;
  }
};

}  // namespace

namespace internal {
std::unique_ptr<BedModel> make_tfm_bed_model() { return std::make_unique<TfmBedModel>(); }
}  // namespace internal

}  // namespace consumers
}  // namespace draglab
