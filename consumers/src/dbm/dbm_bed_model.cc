// The discrete bubble model (dbm.h) as a bed model. Where the drag law enters: the emulsion is
// at minimum fluidization of the loaded law, so U_mf (at the scene's eps_mf) sets the bubble gas
// flow (u0 - U_mf) A of two-phase theory and, with bubble_diameter_m = 0, the injected size
// (Davidson-Harrison from each nozzle's flow). A realization is an injection seed (the nozzles'
// phases). Results: hold-up (global, against height, against two-phase theory), bubble sizes
// against height (with Darton and Mori-Wen beside them), the time-averaged emulsion circulation,
// and, with [outputs] fields = true, a figure-data file for scripts/draglab_fig6.py.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bed/bed_sampling.h"
#include "bed/builtin_models.h"
#include "dbm/dbm.h"
#include "dbm/dbm_scene.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

std::string Num(double x) { return core::format_number(x, 4); }

[[noreturn]] void Bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

/// The DBM's options for a scene, given the law's U_mf.
DbmOptions SceneDbmOptions(const Scene& s, double umf_m_s, std::uint64_t seed) {
  const SceneDbm& d = dbm_section(s);
  DbmOptions o;
  o.width_m = s.geometry.width_m;
  o.depth_m = s.geometry.depth_m;
  o.height_m = s.geometry.height_m;
  o.nx = s.grid.cells_x;
  o.nz = s.grid.cells_y;
  o.ny = s.grid.cells_z;
  o.emulsion_density_kg_m3 = d.emulsion_density_kg_m3;
  o.emulsion_viscosity_pa_s = d.emulsion_viscosity_pa_s;
  o.gravity_m_s2 = s.gas.gravity_m_s2;
  o.walls = d.walls == "free_slip" ? WallSlip::kFreeSlip : WallSlip::kNoSlip;
  // One cell across the depth is the 2-D column: its depth walls must not brake the emulsion.
  o.depth_walls = s.grid.cells_z == 1 ? WallSlip::kFreeSlip : o.walls;
  o.bubble_density_kg_m3 = d.bubble_density_kg_m3;
  o.virtual_mass_coefficient = d.virtual_mass_coefficient;
  o.lift = d.lift;
  o.lift_coefficient = d.lift_coefficient;
  o.nozzles = square_nozzle_array(d.nozzles_per_side, d.nozzle_pitch_m, o.width_m, o.depth_m);
  o.bubble_gas_flow_m3_s =
      std::max(d.superficial_velocity_m_s - umf_m_s, 0.0) * o.width_m * o.depth_m;
  const double per_nozzle = o.bubble_gas_flow_m3_s / static_cast<double>(o.nozzles.size());
  o.bubble_diameter_m =
      d.bubble_diameter_m > 0.0
          ? d.bubble_diameter_m
          : (per_nozzle > 0.0 ? davidson_harrison_bubble_diameter(per_nozzle, s.gas.gravity_m_s2)
                              : 0.0);
  o.seed = seed;
  o.coupling_width_m = d.coupling_width_m;
  o.coalescence = d.coalescence;
  o.film_drainage_s = d.film_drainage_s;
  o.collisions = d.collisions;
  o.injection_ramp_s = d.injection_ramp_s;
  o.cfl = d.cfl;
  o.dt_s = d.dt_s;
  o.average_from_s = d.average_from_s;
  o.sample_interval_s = d.sample_interval_s;
  return o;
}

/// The batch-means standard error of the mean of a correlated series.
struct BatchMeans {
  double standard_error = 0.0;
  int batches = 0;
};
constexpr int kBatches = 10;
BatchMeans batch_means(const std::vector<double>& samples) {
  BatchMeans out;
  const int per_batch = static_cast<int>(samples.size()) / kBatches;
  if (per_batch < 1) return out;  // too few samples: no estimate (0 batches)
  std::vector<double> means(kBatches, 0.0);
  for (int b = 0; b < kBatches; ++b) {
    for (int s = 0; s < per_batch; ++s) means[b] += samples[b * per_batch + s];
    means[b] /= per_batch;
  }
  double mean = 0.0, var = 0.0;
  for (double m : means) mean += m / kBatches;
  for (double m : means) var += (m - mean) * (m - mean) / (kBatches - 1);
  out.standard_error = std::sqrt(var / kBatches);
  out.batches = kBatches;
  return out;
}

/// The injection seed a run starts from.
class DbmInjectionSeed : public BedRealization {};

/// Mean of a cell field over the cells whose centres satisfy `keep` [x, y, z].
template <typename Keep>
double MeanOver(const Eigen::VectorXd& field, const DbmOptions& o, Keep keep) {
  const double hx = o.width_m / o.nx, hy = o.depth_m / o.ny, hz = o.height_m / o.nz;
  double sum = 0.0;
  int count = 0;
  for (int k = 0; k < o.ny; ++k)
    for (int j = 0; j < o.nz; ++j)
      for (int i = 0; i < o.nx; ++i) {
        if (!keep((i + 0.5) * hx, (k + 0.5) * hy, (j + 0.5) * hz)) continue;
        sum += field(i + o.nx * (j + o.nz * k));
        ++count;
      }
  return count > 0 ? sum / count : 0.0;
}

/// The realization a run starts from (an injection seed of the scene's) and the outputs.
void CheckRealization(const Scene& scene, const BedRealization* start) {
  if (start) {
    if (!dynamic_cast<const DbmInjectionSeed*>(start))
      Bad("dbm: the realization was not made by the DBM (an injection seed is expected)");
    if (start->seed != scene.seed)
      Bad("dbm: the injection seed " + std::to_string(start->seed) + " is not the scene's seed " +
          std::to_string(scene.seed));
  }
  if (scene.outputs.particles)
    Bad("[outputs] particles = true: the DBM has no particles (its bubbles go to the figure "
        "data with [outputs] fields = true)");
}

/// The DBM's options for a scene and a law, checked: the gas flow above U_mf, the injected bubble
/// against the column and the nozzle pitch, the stable step.
DbmOptions CheckedOptions(const Scene& scene, const Law& law, const MinFluidizationResult& umf) {
  const SceneDbm& sd = dbm_section(scene);
  const std::string law_ref = law.record().reference();
  if (!(sd.superficial_velocity_m_s > umf.umf_m_s))
    Bad("[dbm] superficial_velocity_m_s = " + Num(sd.superficial_velocity_m_s) +
        " m/s is not above U_mf = " + Num(umf.umf_m_s) + " m/s of " + law_ref +
        ": by two-phase theory the bed carries no bubbles (raise u0 above U_mf)");
  const DbmOptions o = SceneDbmOptions(scene, umf.umf_m_s, scene.seed);
  const double column = std::min(o.width_m, o.depth_m);
  if (!(o.bubble_diameter_m < column))
    Bad("[dbm] bubble_diameter_m = 0: the Davidson-Harrison bubble of each nozzle's flow is " +
        Num(o.bubble_diameter_m) + " m, not smaller than the column (" + Num(column) +
        " m): more nozzles, or a fixed bubble_diameter_m");
  if (sd.nozzles_per_side > 1 && sd.nozzle_pitch_m < o.bubble_diameter_m)
    Bad("[dbm] nozzle_pitch_m = " + Num(sd.nozzle_pitch_m) + " m is below the injected bubble " +
        Num(o.bubble_diameter_m) + " m (Davidson-Harrison with " + law_ref +
        "): the bubbles of neighbouring nozzles would overlap");
  std::string why;
  if (!o.IsValid(&why)) Bad("[dbm] " + why);
  const double stable = o.StableTimeStep();
  if (o.dt_s > stable)
    Bad("[dbm] dt_s = " + Num(o.dt_s) + " s is above the stability limit " + Num(stable) +
        " s (the emulsion's explicit viscous limit and the bubbles' slip relaxation time at "
        "d_b = " +
        Num(o.bubble_diameter_m) + " m); remedy: dt_s <= " + Num(stable));
  return o;
}

/// What the sampling loop records: the bed series (into the result), the JSON series and the
/// hold-up samples after average_from_s (for the batch means).
struct DbmSeries {
  nlohmann::json series = nlohmann::json::array();
  std::vector<double> holdup_samples;
};

/// Runs the simulation to `duration`, sampling at the scene's interval.
DbmSeries SampleRun(DbmSimulation& dbm, const Scene& scene, const DbmOptions& o, double duration,
                    const std::string& law_ref, const BedProgress& progress, BedResult* out) {
  const SceneDbm& sd = dbm_section(scene);
  const double column_volume = o.width_m * o.depth_m * o.height_m;
  DbmSeries s;
  try {
    for (const double t : internal::sample_times(duration, sd.sample_interval_s)) {
      dbm.AdvanceTo(t);
      const auto& bubbles = dbm.bubbles();
      double d_sum = 0.0, z_sum = 0.0;
      for (const DbmBubble& b : bubbles) {
        d_sum += b.diameter_m;
        z_sum += b.x(2);
      }
      const double count = static_cast<double>(bubbles.size());
      const double holdup = dbm.gas_in_bubbles_m3() / column_volume;
      BedSample smp;
      smp.t_s = dbm.time();
      smp.bubble_diameter_m = count > 0 ? d_sum / count : 0.0;
      smp.bubble_centroid_m = count > 0 ? z_sum / count : 0.0;
      smp.bed_height_m = o.height_m;
      out->series.push_back(smp);
      if (smp.t_s > sd.average_from_s + 1e-12) s.holdup_samples.push_back(holdup);
      s.series.push_back({{"t_s", smp.t_s},
                          {"bubbles", bubbles.size()},
                          {"holdup", holdup},
                          {"mean_diameter_m", smp.bubble_diameter_m},
                          {"mean_height_m", smp.bubble_centroid_m}});
      if (progress)
        progress(dbm.time() / duration,
                 "DBM: " + std::to_string(bubbles.size()) + " bubbles, hold-up " + Num(holdup));
    }
    if (dbm.time() < duration - 1e-9 * o.dt_s) dbm.AdvanceTo(duration);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("dbm " + scene.name + " with " + law_ref + ": " + e.what());
  }
  return s;
}

/// Hold-up against height and overall; sizes against height.
struct HeightProfiles {
  nlohmann::json holdup = nlohmann::json::array(), size = nlohmann::json::array();
  double holdup_mean = 0.0, d_sum = 0.0, d_count = 0.0;
};

HeightProfiles ProfilesOf(const DbmAverages& av, const DbmOptions& o) {
  const double hz = o.height_m / o.nz;
  HeightProfiles p;
  for (int j = 0; j < o.nz; ++j) {
    const double h = av.holdup_by_height(j) / av.samples;
    p.holdup_mean += h / o.nz;
    p.holdup.push_back({{"z_m", (j + 0.5) * hz}, {"holdup", h}});
    const double c = av.count_by_height(j);
    p.d_sum += av.diameter_sum_by_height(j);
    p.d_count += c;
    p.size.push_back({{"z_m", (j + 0.5) * hz},
                      {"mean_diameter_m", c > 0 ? av.diameter_sum_by_height(j) / c : 0.0},
                      {"bubbles_per_sample", c / av.samples}});
  }
  return p;
}

/// The mean bubble at each of the scene's size heights beside Darton's and Mori-Wen's
/// correlations; appends each to the headline.
nlohmann::json SizesAgainstCorrelations(const DbmAverages& av, const DbmOptions& o,
                                        const SceneDbm& sd, double umf_m_s,
                                        std::vector<std::pair<std::string, double>>* headline) {
  const double hz = o.height_m / o.nz;
  const double excess = sd.superficial_velocity_m_s - umf_m_s;
  const double area_per_orifice = o.width_m * o.depth_m / static_cast<double>(o.nozzles.size());
  const double bed_area = o.width_m * o.depth_m;
  const double bed_diameter = std::sqrt(4.0 * bed_area / 3.14159265358979323846);
  nlohmann::json sizes = nlohmann::json::array();
  for (double h : sd.size_heights_m) {
    const int j = std::clamp(static_cast<int>(h / hz), 0, o.nz - 1);
    const double c = av.count_by_height(j);
    const double mean = c > 0 ? av.diameter_sum_by_height(j) / c : 0.0;
    const double darton = darton_bubble_diameter(excess, h, area_per_orifice, o.gravity_m_s2);
    const double mori_wen = mori_wen_bubble_diameter(excess, h, bed_area, bed_diameter);
    sizes.push_back({{"height_m", h},
                     {"row_z_m", {j * hz, (j + 1) * hz}},
                     {"mean_diameter_m", c > 0 ? nlohmann::json(mean) : nlohmann::json(nullptr)},
                     {"bubbles_sampled", c},
                     {"darton_m", darton},
                     {"mori_wen_m", mori_wen},
                     {"ratio_to_darton", c > 0 ? nlohmann::json(mean / darton) : nullptr},
                     {"ratio_to_mori_wen", c > 0 ? nlohmann::json(mean / mori_wen) : nullptr}});
    headline->push_back({"mean_diameter_at_" + Num(h) + "_m", mean});
  }
  return sizes;
}

/// Circulation: the time-averaged vertical emulsion velocity in the core (the central quarter
/// of the cross-section) and near the walls (the rest), over the middle third of the height,
/// and the upflow through the mid-height plane per unit column area.
struct Circulation {
  double w_core = 0.0, w_wall = 0.0, upflow = 0.0;
};

Circulation CirculationOf(const DbmAverages& av, const DbmOptions& o) {
  const Eigen::VectorXd w_mean = av.w_cell / av.time_s;
  const double W = o.width_m, D = o.depth_m, H = o.height_m, hz = o.height_m / o.nz;
  auto core = [&](double x, double y) {
    return std::abs(x - 0.5 * W) <= 0.25 * W && (o.ny == 1 || std::abs(y - 0.5 * D) <= 0.25 * D);
  };
  auto middle = [&](double z) { return z >= H / 3.0 && z <= 2.0 * H / 3.0; };
  Circulation c;
  c.w_core =
      MeanOver(w_mean, o, [&](double x, double y, double z) { return core(x, y) && middle(z); });
  c.w_wall =
      MeanOver(w_mean, o, [&](double x, double y, double z) { return !core(x, y) && middle(z); });
  const int j_mid = std::clamp(static_cast<int>(0.5 * H / hz), 0, o.nz - 1);
  const Eigen::VectorXd w_up = w_mean.cwiseMax(0.0);
  c.upflow = MeanOver(w_up, o,
                      [&](double, double, double z) { return static_cast<int>(z / hz) == j_mid; });
  return c;
}

/// Figure data ([outputs] fields = true): the mid-plane averaged field, profiles, size
/// histograms, the last bubbles; returns the file written.
std::string WriteFigureData(const DbmSimulation& dbm, const Scene& scene, const Law& law,
                            const DbmOptions& o, double umf_m_s, const HeightProfiles& profiles,
                            const std::string& output_directory) {
  const SceneDbm& sd = dbm_section(scene);
  const DbmAverages& av = dbm.averages();
  const Eigen::VectorXd w_mean = av.w_cell / av.time_s;
  const Eigen::VectorXd u_mean = av.u_cell / av.time_s;
  const std::string dir = internal::scene_output_directory(scene, output_directory);
  std::filesystem::create_directories(dir);
  const int k0 = (o.ny - 1) / 2, k1 = o.ny / 2;  // the vertical mid-plane (y = D/2)
  nlohmann::json ux = nlohmann::json::array(), uz = nlohmann::json::array(),
                 eb = nlohmann::json::array();
  const Eigen::VectorXd eb_mean = av.bubble_fraction / av.time_s;
  for (int j = 0; j < o.nz; ++j) {
    nlohmann::json rx = nlohmann::json::array(), rz = nlohmann::json::array(),
                   re = nlohmann::json::array();
    for (int i = 0; i < o.nx; ++i) {
      const int a = i + o.nx * (j + o.nz * k0), b = i + o.nx * (j + o.nz * k1);
      rx.push_back(0.5 * (u_mean(a) + u_mean(b)));
      rz.push_back(0.5 * (w_mean(a) + w_mean(b)));
      re.push_back(0.5 * (eb_mean(a) + eb_mean(b)));
    }
    ux.push_back(rx);
    uz.push_back(rz);
    eb.push_back(re);
  }
  nlohmann::json bx = nlohmann::json::array(), by = nlohmann::json::array(),
                 bz = nlohmann::json::array(), bd = nlohmann::json::array();
  for (const DbmBubble& b : dbm.bubbles()) {
    bx.push_back(b.x(0));
    by.push_back(b.x(1));
    bz.push_back(b.x(2));
    bd.push_back(b.diameter_m);
  }
  nlohmann::json hist = nlohmann::json::array();
  for (int j = 0; j < o.nz; ++j) {
    nlohmann::json row = nlohmann::json::array();
    for (int s = 0; s < av.size_histogram.cols(); ++s) row.push_back(av.size_histogram(j, s));
    hist.push_back(row);
  }
  const double area_per_orifice = o.width_m * o.depth_m / static_cast<double>(o.nozzles.size());
  const nlohmann::json fig = {
      {"scene", scene.name},
      {"law", law.record().reference()},
      {"superficial_velocity_m_s", sd.superficial_velocity_m_s},
      {"umf_m_s", umf_m_s},
      {"area_per_orifice_m2", area_per_orifice},
      {"gravity_m_s2", o.gravity_m_s2},
      {"coalescence", sd.coalescence},
      {"width_m", o.width_m},
      {"depth_m", o.depth_m},
      {"height_m", o.height_m},
      {"cells", {o.nx, o.ny, o.nz}},
      {"t_s", dbm.time()},
      {"average_from_s", sd.average_from_s},
      {"midplane_u_x", ux},
      {"midplane_u_z", uz},
      {"midplane_bubble_fraction", eb},
      {"holdup_profile", profiles.holdup},
      {"size_profile", profiles.size},
      {"size_bin_m", av.size_bin_m},
      {"size_histogram_by_row", hist},
      {"bubbles", {{"x_m", bx}, {"y_m", by}, {"z_m", bz}, {"diameter_m", bd}}}};
  const std::string path = dir + "/" + scene.name + "_" + law.record().name + "_dbm.json";
  core::write_file_atomically(path, fig.dump(), "DBM figure data");
  return path;
}

/// What the result JSON and the brief report share.
struct DbmSummary {
  double umf_m_s = 0.0, u_br = 0.0, holdup_theory = 0.0, gas_balance = 0.0;
  double wall_s = 0.0, cells_steps = 0.0;
  HeightProfiles profiles;
  Circulation circulation;
  BatchMeans holdup_error;
  nlohmann::json sizes;
  std::vector<std::pair<std::string, double>> headline;
};

nlohmann::json ResultJson(const DbmSimulation& dbm, const Scene& scene, const DbmOptions& o,
                          const BedResult& out, const DbmSummary& s, const nlohmann::json& series) {
  const SceneDbm& sd = dbm_section(scene);
  const DbmDiagnostics& dg = dbm.diagnostics();
  const DbmAverages& av = dbm.averages();
  const double holdup_mean = s.profiles.holdup_mean;
  nlohmann::json head = nlohmann::json::object();
  for (const auto& [name, value] : s.headline) head[name] = value;
  return {
      {"solver", "dbm"},
      {"scene", out.scene},
      {"scene_hash", out.scene_hash},
      {"law", out.law},
      {"umf_m_s", s.umf_m_s},
      {"eps_mf", scene.eps_mf},
      {"superficial_velocity_m_s", sd.superficial_velocity_m_s},
      {"bubble_gas_flow_m3_s", o.bubble_gas_flow_m3_s},
      {"injected_diameter_m", o.bubble_diameter_m},
      {"injected_diameter_from",
       sd.bubble_diameter_m > 0.0 ? "scene" : "davidson_harrison_per_nozzle"},
      {"nozzles", o.nozzles.size()},
      {"coupling_width_m", o.CouplingWidth()},
      {"coalescence", sd.coalescence},
      {"film_drainage_s", sd.film_drainage_s},
      {"collisions", sd.collisions && !sd.coalescence},
      {"grid", {{"cells_x", o.nx}, {"cells_y", o.nz}, {"cells_z", o.ny}}},
      {"dt_s", o.dt_s},
      {"stable_dt_s", o.StableTimeStep()},
      {"cfl", o.cfl},
      {"min_dt_s", dg.min_dt_s},
      {"headline", head},
      {"holdup",
       {{"mean", holdup_mean},
        {"two_phase_theory", s.holdup_theory},
        {"ratio_to_theory", s.holdup_theory > 0 ? holdup_mean / s.holdup_theory : 0.0},
        {"standard_error", s.holdup_error.standard_error},
        {"batches", s.holdup_error.batches},
        {"rise_velocity_davies_taylor_m_s", s.u_br}}},
      {"sizes", s.sizes},
      {"circulation",
       {{"core_mean_w_m_s", s.circulation.w_core},
        {"wall_mean_w_m_s", s.circulation.w_wall},
        {"upflow_mid_height_m_s", s.circulation.upflow},
        {"up_in_core_down_at_walls", s.circulation.w_core > 0.0 && s.circulation.w_wall < 0.0}}},
      {"holdup_profile", s.profiles.holdup},
      {"size_profile", s.profiles.size},
      {"series", series},
      {"averaged_s", av.time_s},
      {"samples", av.samples},
      {"gas",
       {{"injected_m3", dg.gas_injected_m3},
        {"left_at_surface_m3", dg.gas_left_m3},
        {"in_bubbles_m3", dbm.gas_in_bubbles_m3()},
        {"forming_at_nozzles_m3", dbm.gas_forming_m3()},
        {"relative_imbalance", s.gas_balance}}},
      {"bubbles_injected", dg.bubbles_injected},
      {"bubbles_left", dg.bubbles_left},
      {"coalescences", dg.coalescences},
      {"max_bubble_diameter_m", dg.max_bubble_diameter_m},
      {"max_cfl", dg.max_cfl},
      {"retaken_steps", dg.retaken_steps},
      {"max_bubble_fraction", dg.max_bubble_fraction},
      {"fraction_clamps", dg.fraction_clamps},
      {"max_pressure_residual", dg.max_continuity_residual},
      {"max_cg_iterations", dg.max_cg_iterations},
      {"steps", dg.steps},
      {"bubble_steps", dg.bubble_steps},
      {"bubble_steps_per_s", dg.bubble_steps / s.wall_s},
      {"cell_steps_per_s", s.cells_steps / s.wall_s},
      {"emulsion_wall_s", dg.emulsion_wall_s},
      {"bubble_wall_s", dg.bubble_wall_s},
      {"drag_out_of_range", out.law_out_of_range},
      {"wall_s", s.wall_s},
      {"output_files", out.output_files}};
}

std::string BriefReport(const DbmSimulation& dbm, const Scene& scene, const DbmOptions& o,
                        const BedResult& out, const DbmSummary& s) {
  const DbmDiagnostics& dg = dbm.diagnostics();
  std::ostringstream brief;
  brief << "DBM " << scene.name << " with " << out.law << ": U_mf = " << Num(s.umf_m_s)
        << " m/s, u0 = " << Num(dbm_section(scene).superficial_velocity_m_s) << " m/s, bubble gas "
        << Num(o.bubble_gas_flow_m3_s) << " m^3/s as " << Num(o.bubble_diameter_m)
        << " m bubbles from " << o.nozzles.size() << " nozzles; " << o.nx << " x " << o.ny << " x "
        << o.nz << " cells, " << dg.steps << " steps of " << Num(o.dt_s) << " s; wall "
        << Num(s.wall_s) << " s (" << Num(dg.bubble_steps / s.wall_s) << " bubble-steps/s, "
        << Num(s.cells_steps / s.wall_s) << " cell-steps/s)\n  hold-up "
        << Num(s.profiles.holdup_mean) << " +- " << Num(s.holdup_error.standard_error)
        << " (batch means)"
        << " (two-phase theory " << Num(s.holdup_theory) << "), mean bubble "
        << Num(out.metrics.bubble_diameter_m) << " m, circulation: core "
        << Num(s.circulation.w_core) << " m/s, walls " << Num(s.circulation.w_wall)
        << " m/s, upflow " << Num(s.circulation.upflow) << " m/s\n  gas balance "
        << Num(s.gas_balance) << " (rel.), " << dg.coalescences << " coalescences, max bubble "
        << Num(dg.max_bubble_diameter_m) << " m, max CFL " << Num(dg.max_cfl);
  return brief.str();
}

class DbmBedModel : public BedModel {
 public:
  std::string key() const override { return "dbm"; }
  const SceneTable* scene_table() const override { return &dbm_scene_table(); }
  /// The emulsion fills the column: no particle inventory.
  bool particle_bed() const override { return false; }
  std::string description() const override {
    return "discrete bubble model: Lagrangian bubbles in a continuous emulsion (dbm.h)";
  }
  BedModelSettings Settings(const Scene& scene) const override {
    const SceneDbm& d = dbm_section(scene);
    BedModelSettings s;
    s.line = "discrete bubbles: u0 = " + Num(d.superficial_velocity_m_s) + " m/s, emulsion " +
             Num(d.emulsion_density_kg_m3) + " kg/m^3 and " + Num(d.emulsion_viscosity_pa_s) +
             " Pa s, bubbles " + Num(d.bubble_density_kg_m3) + " kg/m^3 of " +
             (d.bubble_diameter_m > 0.0 ? Num(d.bubble_diameter_m) + " m"
                                        : std::string("Davidson-Harrison size")) +
             " from " + std::to_string(d.nozzles_per_side * d.nozzles_per_side) +
             " nozzles (pitch " + Num(d.nozzle_pitch_m) + " m); coalescence " +
             (d.coalescence ? "on (film drainage " + Num(d.film_drainage_s) + " s)" : "off") +
             "; coupling width " +
             (d.coupling_width_m > 0.0 ? Num(d.coupling_width_m) + " m"
                                       : std::string("5 bubble diameters")) +
             "; " + std::to_string(scene.grid.cells_x) + " x " +
             std::to_string(scene.grid.cells_z) + " x " + std::to_string(scene.grid.cells_y) +
             " cells, dt " + Num(d.dt_s) + " s";
    s.numbers = {{"superficial_velocity_m_s", d.superficial_velocity_m_s},
                 {"bubble_diameter_m", d.bubble_diameter_m},
                 {"nozzles", static_cast<double>(d.nozzles_per_side * d.nozzles_per_side)},
                 {"dt_s", d.dt_s}};
    return s;
  }

  RegressionTolerances default_tolerances(const Scene&) const override {
    // The DBM's "bubble diameter" is the mean size of its Lagrangian bubbles over the run: each
    // bubble carries its volume exactly, none is traced on the grid, so there is no cell part.
    // The 10 % covers the run-to-run scatter that coalescence brings (which bubbles meet
    // depends on the injection phases and the flow: docs/scenes.md), and like the DPM's it is the
    // smallest change of a bubble size a reactor prediction can use. Without coalescence every
    // bubble keeps its injected size, so D moves only when that size does.
    RegressionTolerances t;
    t.diameter_abs_m = 0.0;
    t.diameter_rel = 0.10;
    t.umf_rel = 0.01;  // as every model's (BedModel::default_tolerances)
    return t;
  }

  std::string realization_kind() const override { return "injection seed"; }
  std::shared_ptr<const BedRealization> Realize(const Scene& scene, std::shared_ptr<const Law>,
                                                const BedProgress&,
                                                const RealizeOptions&) const override {
    auto seed = std::make_shared<DbmInjectionSeed>();
    seed->seed = scene.seed;
    return seed;
  }

  TimeResolution time_resolution() const override {
    return {"dt_s",
            "the fixed DBM step [s] (bounded by DbmOptions::StableTimeStep)",
            "(0, the stability limit]",
            /*whole_number=*/false,
            /*larger_is_finer=*/false,
            "--dt",
            "5e-3,2.5e-3"};
  }
  double time_resolution_of(const Scene& scene) const override { return dbm_section(scene).dt_s; }
  Scene WithTimeResolution(const Scene& scene, double value) const override {
    Scene s = scene;
    dbm_section(s).dt_s = value;
    return s;
  }

  BedResult Run(const Scene& scene, std::shared_ptr<const Law> law, const BedRunOptions& options,
                const BedProgress& progress, const BedRealization* start) const override {
    const auto t0 = std::chrono::steady_clock::now();
    scene.Validate();
    if (!law) Bad("dbm: law is null");
    CheckRealization(scene, start);
    const SceneDbm& sd = dbm_section(scene);
    MinFluidizationOptions mo;
    mo.eps_mf = scene.eps_mf;
    const MinFluidizationResult umf =
        minimum_fluidization(*law, scene.particles, scene.gas, mo);  // kOutOfValidity: stop here
    const std::string law_ref = law->record().reference();
    const DbmOptions o = CheckedOptions(scene, *law, umf);
    DbmSimulation dbm(o);
    const double duration = options.duration_s > 0.0 ? options.duration_s : scene.time.duration_s;

    BedResult out = internal::result_header(key(), scene, law_ref, "two_phase");
    const DbmSeries series = SampleRun(dbm, scene, o, duration, law_ref, progress, &out);
    const DbmDiagnostics& dg = dbm.diagnostics();
    const DbmAverages& av = dbm.averages();
    if (av.samples == 0 || av.time_s <= 0.0)
      Bad("[dbm] average_from_s = " + Num(sd.average_from_s) + " s leaves no averaging time in " +
          Num(duration) + " s (lower it or run longer)");

    DbmSummary s;
    s.umf_m_s = umf.umf_m_s;
    s.u_br = davies_taylor_rise_velocity(o.bubble_diameter_m, o.gravity_m_s2);
    s.profiles = ProfilesOf(av, o);
    s.holdup_theory = two_phase_holdup(sd.superficial_velocity_m_s, umf.umf_m_s, s.u_br);
    s.headline = {{"holdup", s.profiles.holdup_mean}};
    s.sizes = SizesAgainstCorrelations(av, o, sd, umf.umf_m_s, &s.headline);
    s.circulation = CirculationOf(av, o);
    s.headline.push_back({"circulation_upflow_m_s", s.circulation.upflow});
    s.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    s.cells_steps = static_cast<double>(o.nx) * o.ny * o.nz * dg.steps;
    if (scene.outputs.fields) {
      out.output_files.push_back(
          WriteFigureData(dbm, scene, *law, o, umf.umf_m_s, s.profiles, options.output_directory));
    }

    ConsumerMetrics& m = out.metrics;
    m.umf_m_s = umf.umf_m_s;
    m.background_m_s = sd.superficial_velocity_m_s;
    m.t_ref_s = 0.0;
    m.bubble_present = s.profiles.d_count > 0;
    m.bubble_diameter_m = s.profiles.d_count > 0 ? s.profiles.d_sum / s.profiles.d_count : 0.0;
    m.bubble_centroid_m = 0.0;
    m.max_bed_height_m = o.height_m;
    const double left_and_in = dg.gas_left_m3 + dbm.gas_in_bubbles_m3() + dbm.gas_forming_m3();
    s.gas_balance =
        dg.gas_injected_m3 > 0.0 ? (dg.gas_injected_m3 - left_and_in) / dg.gas_injected_m3 : 0.0;
    out.max_relative_mass_imbalance = std::abs(s.gas_balance);
    out.law_out_of_range = law->out_of_range_count();
    out.threads = 1;
    out.steps = dg.steps;
    out.mean_dt_s = dg.steps > 0 ? dbm.time() / static_cast<double>(dg.steps) : o.dt_s;
    out.inner_steps = dg.bubble_steps;
    out.wall_s = s.wall_s;
    m.wall_s = s.wall_s;
    out.headline = s.headline;
    // The hold-up's statistical error: the samples are correlated over a bubble's rise, so their
    // standard error understates it; the means of kBatches consecutive batches, each far longer
    // than a rise through the column, are close to independent.
    s.holdup_error = batch_means(series.holdup_samples);
    out.headline_uncertainty = s.holdup_error.standard_error;
    out.headline_uncertainty_method =
        "hold-up: standard error of the means of " + std::to_string(s.holdup_error.batches) +
        " consecutive batches of the samples after average_from_s (statistical; the grid's and "
        "step's errors are measured by draglab sensitivity --work-precision)";
    out.result_json = ResultJson(dbm, scene, o, out, s, series.series).dump();
    out.brief = BriefReport(dbm, scene, o, out, s);
    return out;
  }
};

}  // namespace

namespace internal {
std::unique_ptr<BedModel> make_dbm_bed_model() { return std::make_unique<DbmBedModel>(); }
}  // namespace internal

}  // namespace consumers
}  // namespace draglab
