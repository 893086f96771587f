// DpmSimulation: the coupled CFD-DEM run (draglab/consumers/dpm.h, docs/dpm.md).
#include "draglab/consumers/dpm.h"

#include "io/bed_output.h"

#include "bed/bed_sampling.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "dpm/dpm_scene.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "gas/particle_kernel.h"

namespace draglab {
namespace consumers {
namespace {

[[noreturn]] void Fail(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

std::string Num(double x) { return core::format_number(x, 4); }

using internal::Deposit;
using internal::Interpolate;
using internal::Tent;
using internal::TentAt;

}  // namespace

bool DpmOptions::IsValid(std::string* error) const {
  auto bad = [&](const std::string& m) {
    if (error) *error = "DpmOptions." + m;
    return false;
  };
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s))
    return bad("duration_s must be >= 0 (0: the scene's), got " + Num(duration_s));
  if (!std::isfinite(background_override_m_s))
    return bad("background_override_m_s must be finite (< 0: from the scene)");
  if (!(min_void_fraction > 0.0 && min_void_fraction < 0.5))
    return bad("min_void_fraction must be in (0, 0.5), got " + Num(min_void_fraction));
  if (!(settle_kinetic_tolerance > 0.0 && settle_kinetic_tolerance <= 1e-2))
    return bad("settle_kinetic_tolerance must be in (0, 1e-2], got " +
               Num(settle_kinetic_tolerance));
  if (!(settle_max_time_s > 0.0) || !std::isfinite(settle_max_time_s))
    return bad("settle_max_time_s must be > 0, got " + Num(settle_max_time_s));
  if (!(gas_dt_s >= 0.0) || !std::isfinite(gas_dt_s))
    return bad("gas_dt_s must be >= 0 (0: from the scene), got " + Num(gas_dt_s));
  if (!(settle_checkpoint_interval_s >= 0.0 && settle_checkpoint_interval_s <= 1e6))
    return bad("settle_checkpoint_interval_s must be in [0, 1e6], got " +
               Num(settle_checkpoint_interval_s));
  return true;
}

std::string DpmResult::BriefReport() const {
  std::ostringstream s;
  s << "DPM " << scene << " with " << law << ": U_mf = " << Num(umf_m_s)
    << " m/s, background = " << Num(background_m_s) << " m/s (" << background_mode
    << "), eps_mf = " << eps_mf << "; settled packing eps = " << Num(eps_packing)
    << ", its U_mf = " << Num(umf_packing_m_s) << " m/s\n  " << particles
    << " particles, settled bed " << Num(settled_bed_height_m) << " m; " << gas_steps
    << " gas steps of " << Num(gas_dt_s) << " s, " << dem_steps << " DEM steps of " << Num(dem_dt_s)
    << " s; wall " << Num(wall_s) << " s on " << threads << (threads == 1 ? " thread" : " threads")
    << " (settling " << Num(settle_wall_s) << " s)\n  bubble D at t_ref = " << Num(t_ref_s)
    << " s: " << (bubble_at_t_ref ? Num(bubble_diameter_m) + " m" : std::string("none"))
    << "\n  gas mass imbalance (max rel.) " << Num(max_relative_mass_imbalance)
    << ", momentum mismatch " << Num(momentum_mismatch) << ", action-reaction max "
    << Num(max_action_reaction_mismatch_n) << " N, eps clamps " << void_fraction_clamps
    << ", drag out of range " << law_out_of_range;
  if (!umf_extrapolation.empty()) s << "\n  U_mf EXTRAPOLATED: " << umf_extrapolation;
  return s.str();
}

struct DpmSimulation::Impl {
  std::unique_ptr<DemSystem> dem;
  std::unique_ptr<GasPhase> gas;
  Eigen::ArrayXXd eps, beta, upx, upz;
  std::vector<double> c;  // per-particle drag coefficient c_p [kg/s]
  DpmStepDiagnostics diag;
  double time = 0.0;
  // Vertical momentum bookkeeping (gas + particles).
  double impulse_z = 0.0;
  double wall_impulse_step = 0.0;
};

DpmSimulation::DpmSimulation(const Scene& scene, std::shared_ptr<const Law> law,
                             const DpmOptions& options)
    : scene_(scene), law_(std::move(law)), opt_(options), impl_(std::make_unique<Impl>()) {
  scene_.Validate();
  std::string why;
  if (!opt_.IsValid(&why)) Fail(why);
  if (!law_) Fail("DpmSimulation: law is null (load it with Database::load)");
  if (std::abs(scene_.jet_center_m() - 0.5 * scene_.geometry.width_m) >
      1e-9 * scene_.geometry.width_m)
    Fail("jet.center_m: the DPM gas solver supports only a central slot (width / 2 = " +
         Num(0.5 * scene_.geometry.width_m) + " m), got " + Num(scene_.jet_center_m()));
}

DpmSimulation::~DpmSimulation() = default;

const GasPhase& DpmSimulation::gas() const {
  if (!impl_->gas) Fail("DpmSimulation::gas: call Settle() first");
  return *impl_->gas;
}
const DemSystem& DpmSimulation::dem() const {
  if (!impl_->dem) Fail("DpmSimulation::dem: call Settle() first");
  return *impl_->dem;
}
double DpmSimulation::time() const { return impl_->time; }
const std::vector<double>& DpmSimulation::drag_coefficients() const { return impl_->c; }

namespace internal {

std::vector<double> class_diameters(const Scene& scene, int n) {
  // Whole particles per class from the number fractions (largest remainders), the largest class
  // first: random sequential insertion places the large spheres while there is room. Every
  // particle's position is drawn over the whole insertion column, so the bed starts mixed.
  const std::vector<double> f = scene.number_fractions();
  const std::vector<double>& d = scene.particles.diameters_m;
  std::vector<int> count(f.size());
  std::vector<std::pair<double, std::size_t>> remainder;
  int assigned = 0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    count[k] = static_cast<int>(std::floor(f[k] * n));
    assigned += count[k];
    remainder.push_back({f[k] * n - count[k], k});
  }
  std::sort(remainder.begin(), remainder.end(), std::greater<>());
  for (std::size_t r = 0; assigned < n; ++r, ++assigned) ++count[remainder[r].second];
  std::vector<std::size_t> order(f.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&d](std::size_t a, std::size_t b) { return d[a] > d[b]; });
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(n));
  for (std::size_t k : order) out.insert(out.end(), count[k], d[k]);
  return out;
}

double segregation_index(const Particles& p, double floor_y) {
  if (p.size() == 0) return 0.0;
  const auto [lo, hi] = std::minmax_element(p.diameter.begin(), p.diameter.end());
  if (*lo == *hi) return 0.0;
  double small = 0.0, large = 0.0, all = 0.0;
  std::size_t n_small = 0, n_large = 0;
  for (std::size_t n = 0; n < p.size(); ++n) {
    const double h = p.y[n] - floor_y;
    all += h;
    if (p.diameter[n] == *lo) small += h, ++n_small;
    if (p.diameter[n] == *hi) large += h, ++n_large;
  }
  all /= static_cast<double>(p.size());
  return all > 0.0 ? (small / n_small - large / n_large) / all : 0.0;
}

}  // namespace internal

double DpmSimulation::bed_weight_n() const {
  const double n = impl_->dem ? static_cast<double>(impl_->dem->particles().size())
                              : static_cast<double>(scene_.particle_count());
  double mass = n * scene_.particle_mass_kg();
  if (scene_.polydisperse() && impl_->dem) {
    const Particles& p = impl_->dem->particles();
    mass = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) mass += p.mass(k);
  }
  return mass * scene_.gas.gravity_m_s2 *
         (1.0 - scene_.gas.density_kg_m3 / scene_.particles.density_kg_m3);
}

void DpmSimulation::Settle(const DpmProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const Scene& s = scene_;
  const DemOptions d = MakeDemOptions();
  SettleOptions so;
  const std::int64_t count = s.particle_count();
  if (count < 1 || count > std::numeric_limits<int>::max()) {
    throw Error(ErrorCode::kInvalidArgument,
                "[particles]: " + std::to_string(count) + " particles is outside [1, 10000000]");
  }
  so.n = static_cast<int>(count);
  so.diameter = s.particles.diameter_m;
  if (s.polydisperse()) so.diameters = internal::class_diameters(s, so.n);
  so.density = s.particles.density_kg_m3;
  so.seed = s.seed;
  so.kinetic_energy_tolerance = opt_.settle_kinetic_tolerance;
  so.max_time = opt_.settle_max_time_s;
  so.checkpoint_path = opt_.settle_checkpoint_path;
  so.checkpoint_interval_s = opt_.settle_checkpoint_interval_s;
  SettleResult settled = settle_particles(d, so, [&](double f, const std::string& stage) {
    if (progress) progress(f, "settle: " + stage);
  });
  Start(std::move(settled.particles));
  result_.settle_wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

DemOptions DpmSimulation::MakeDemOptions() const {
  const Scene& s = scene_;
  DemOptions d;
  d.box_max = {s.geometry.width_m, s.geometry.height_m, s.geometry.depth_m};
  d.gravity = {0.0, -s.gas.gravity_m_s2, 0.0};
  const SceneDem& dem = dem_section(s);
  d.normal_stiffness = dem.spring_stiffness_n_m;
  d.restitution = d.wall_restitution = dem.restitution;
  d.friction = d.wall_friction = dem.friction;
  d.dt = dem.dem_dt_s;
  d.min_steps_per_contact = dem.contact_steps;
  return d;
}

void DpmSimulation::Start(Particles settled) {
  const Scene& s = scene_;
  const double settle_wall_s = result_.settle_wall_s;
  settled_height_ = 0.0;
  for (std::size_t n = 0; n < settled.size(); ++n)
    settled_height_ = std::max(settled_height_, settled.y[n] + 0.5 * settled.diameter[n]);
  // Initial layers: equal-height bands of the settled bed, by stable id (particles reorder).
  std::int64_t max_id = -1;
  for (std::size_t n = 0; n < settled.size(); ++n) max_id = std::max(max_id, settled.id[n]);
  layer_by_id_.assign(static_cast<std::size_t>(max_id + 1), 0);
  for (std::size_t n = 0; n < settled.size(); ++n) {
    const double h = settled_height_ > 0.0 ? settled.y[n] / settled_height_ : 0.0;
    layer_by_id_[static_cast<std::size_t>(settled.id[n])] =
        std::clamp(static_cast<int>(h * kInitialLayers), 0, kInitialLayers - 1);
  }
  impl_->dem = std::make_unique<DemSystem>(MakeDemOptions(), std::move(settled));

  // Gas. Incompressible: the jet's Mach number is < 0.1 (scene.h), so density changes are
  // < 0.5 % and a pressure projection is cheaper and more robust than a weakly compressible gas.
  const SceneDerived derived = derive_scene(s, *law_);
  result_ = DpmResult{};
  result_.settle_wall_s = settle_wall_s;
  result_.law = law_->record().reference();
  result_.scene = s.name;
  result_.scene_hash = s.hash();
  result_.umf_m_s = derived.umf.umf_m_s;
  result_.umf_extrapolation = derived.umf.extrapolation;
  result_.eps_mf = s.eps_mf;
  result_.t_ref_s = s.time.t_ref_s;
  {
    // Settled packing: surface = mean over 2 d wide columns of the highest particle top (the
    // single highest particle overstates a rough surface by up to a diameter).
    const Particles& p = impl_->dem->particles();
    const double d = s.particles.diameter_m, w = s.geometry.width_m;
    const int columns = std::max(1, static_cast<int>(w / (2.0 * d)));
    std::vector<double> top(static_cast<std::size_t>(columns), 0.0);
    double solids = 0.0;
    for (std::size_t n = 0; n < p.size(); ++n) {
      const int c = std::clamp(static_cast<int>(p.x[n] / w * columns), 0, columns - 1);
      top[static_cast<std::size_t>(c)] =
          std::max(top[static_cast<std::size_t>(c)], p.y[n] + 0.5 * p.diameter[n]);
      solids += p.volume(n);
    }
    double surface = 0.0;
    for (double t : top) surface += t / columns;
    result_.eps_packing = 1.0 - solids / (w * s.geometry.depth_m * std::max(surface, d));
    MinFluidizationOptions mo;
    mo.eps_mf = std::clamp(result_.eps_packing, 0.21, 0.89);
    try {
      const MinFluidizationResult packing = minimum_fluidization(*law_, s.particles, s.gas, mo);
      result_.umf_packing_m_s = packing.umf_m_s;
      if (result_.umf_extrapolation.empty()) result_.umf_extrapolation = packing.extrapolation;
    } catch (const Error& e) {
      if (s.distributor.mode == BackgroundMode::kUmfPacking && opt_.background_override_m_s < 0.0)
        throw Error(e.code(),
                    "distributor.background = \"umf_packing\": the law's U_mf at the "
                    "settled packing's eps = " +
                        Num(result_.eps_packing) + " cannot be computed (" + e.what() +
                        "); use background = \"umf\" or \"fixed\"");
      result_.umf_packing_m_s = 0.0;
    }
  }
  if (opt_.background_override_m_s >= 0.0) {
    result_.background_m_s = opt_.background_override_m_s;
    result_.background_mode = "override";
  } else {
    result_.background_m_s = s.distributor.mode == BackgroundMode::kUmfPacking
                                 ? s.distributor.umf_factor * result_.umf_packing_m_s
                                 : derived.background_m_s;
    result_.background_mode = to_string(s.distributor.mode);
  }
  const GasOptions g = internal::scene_gas_options(s, result_.background_m_s, opt_.jet);
  impl_->gas = std::make_unique<GasPhase>(g);
  gas_dt_ = opt_.gas_dt_s > 0.0     ? opt_.gas_dt_s
            : s.time.gas_dt_s > 0.0 ? s.time.gas_dt_s
                                    : derived.recommended_gas_dt_s;
  // The gas step is a whole number of DEM steps (DEM step from the contact time, never above).
  const double dem_max = impl_->dem->time_step();
  const double k = std::max(1.0, std::ceil(gas_dt_ / dem_max - 1e-9));
  result_.dem_dt_s = gas_dt_ / k;
  result_.gas_dt_s = gas_dt_;
  result_.particles = static_cast<std::int64_t>(impl_->dem->particles().size());
  result_.settled_bed_height_m = settled_height_;
  const int nx = g.nx, nz = g.nz;
  impl_->eps = Eigen::ArrayXXd::Ones(nx, nz);
  impl_->beta = impl_->upx = impl_->upz = Eigen::ArrayXXd::Zero(nx, nz);
  impl_->time = 0.0;
  // Initial void fraction (no time derivative implied).
  {
    const auto& p = impl_->dem->particles();
    const double dx = impl_->gas->dx(), dz = impl_->gas->dz();
    const double vcell = dx * dz * s.geometry.depth_m;
    Eigen::ArrayXXd solid = Eigen::ArrayXXd::Zero(nx, nz);
    for (std::size_t n = 0; n < p.size(); ++n)
      Deposit(solid, TentAt(p.x[n], p.y[n], dx, dz, nx, nz), p.volume(n));
    impl_->eps = (1.0 - solid / vcell).max(opt_.min_void_fraction);
    impl_->gas->SetVoidFraction(impl_->eps);
  }
}

GridField2D DpmSimulation::VoidFractionField() const {
  return internal::scene_grid_field(scene_, impl_->eps);
}

DpmSnapshot DpmSimulation::Snapshot() const {
  if (!impl_->gas) Fail("DpmSimulation::Snapshot: call Settle() first");
  DpmSnapshot snap;
  snap.t_s = impl_->time - scene_.jet.start_s;
  const Particles& p = impl_->dem->particles();
  snap.x = p.x;
  snap.y = p.y;
  snap.z = p.z;
  snap.diameter = p.diameter;
  snap.layers = kInitialLayers;
  snap.layer.resize(p.size());
  for (std::size_t n = 0; n < p.size(); ++n) {
    const auto id = static_cast<std::size_t>(p.id[n]);
    snap.layer[n] = id < layer_by_id_.size() ? layer_by_id_[id] : 0;
  }
  snap.void_fraction = VoidFractionField();
  snap.bubble =
      measure_bubble(snap.void_fraction, internal::scene_bubble_options(scene_, settled_height_));
  return snap;
}

const DpmStepDiagnostics& DpmSimulation::Step() {
  if (!impl_->gas) Fail("DpmSimulation::Step: call Settle() first");
  Impl& m = *impl_;
  GasPhase& gas = *m.gas;
  DemSystem& dem = *m.dem;
  Particles& p = dem.mutable_particles();
  const int nx = gas.options().nx, nz = gas.options().nz;
  const double dx = gas.dx(), dz = gas.dz(), depth = scene_.geometry.depth_m;
  const double vcell = dx * dz * depth;
  const double mu = scene_.gas.viscosity_pa_s, rho_g = scene_.gas.density_kg_m3;
  const std::size_t np = p.size();
  DpmStepDiagnostics& diag = m.diag;
  diag = DpmStepDiagnostics{};

  // Cell-centred gas velocity (average of the two faces): the field the kernel interpolates.
  Eigen::ArrayXXd ugx(nx, nz), ugz(nx, nz);
  auto centre_velocity = [&]() {
    for (int j = 0; j < nz; ++j)
      for (int i = 0; i < nx; ++i) {
        ugx(i, j) = 0.5 * (gas.u()(i, j) + gas.u()(i + 1, j));
        ugz(i, j) = 0.5 * (gas.w()(i, j) + gas.w()(i, j + 1));
      }
  };
  centre_velocity();

  // 1. Particles -> grid: void fraction.
  std::vector<Tent> tents(np);
  Eigen::ArrayXXd solid = Eigen::ArrayXXd::Zero(nx, nz);
  for (std::size_t n = 0; n < np; ++n) {
    tents[n] = TentAt(p.x[n], p.y[n], dx, dz, nx, nz);
    Deposit(solid, tents[n], p.volume(n));
  }
  Eigen::ArrayXXd eps_next = 1.0 - solid / vcell;
  diag.min_void_fraction = eps_next.minCoeff();
  if (!std::isfinite(diag.min_void_fraction) || eps_next.maxCoeff() > 1.0 + 1e-12)
    Fail("DPM: the mapped void fraction left (0, 1] at t = " + Num(m.time) +
         " s (non-finite or > 1): the particle state diverged; reduce the DEM step "
         "([dem] contact_steps) or the gas step ([time] gas_dt_s)");
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      if (eps_next(i, j) < opt_.min_void_fraction) {
        eps_next(i, j) = opt_.min_void_fraction;
        ++result_.void_fraction_clamps;
      }

  // Beds of several sizes: the local Sauter mean, sum d^3 / sum d^2 with the same kernel, is the
  // <d> a polydisperse law takes (y = d_i/<d>, Re on <d>) and the diameter a monodisperse law
  // is evaluated at (the mixture's beta, shared by volume).
  const bool sizes = scene_.polydisperse();
  const bool per_class_law = law_->num_extra_inputs() > 0;
  Eigen::ArrayXXd d3, d2;
  if (sizes) {
    d3 = Eigen::ArrayXXd::Zero(nx, nz);
    d2 = Eigen::ArrayXXd::Zero(nx, nz);
    for (std::size_t n = 0; n < np; ++n) {
      const double d = p.diameter[n];
      Deposit(d3, tents[n], d * d * d);
      Deposit(d2, tents[n], d * d);
    }
  }

  // 2. Per particle: eps and gas velocity at the centre (transpose of the mapping), beta, c_p.
  m.c.assign(np, 0.0);
  Eigen::ArrayXXd csum = Eigen::ArrayXXd::Zero(nx, nz), cux = csum, cuz = csum;
  for (std::size_t n = 0; n < np; ++n) {
    const Tent& t = tents[n];
    const double eps_p = std::min(1.0, Interpolate(eps_next, t));
    const double sx = Interpolate(ugx, t) - p.vx[n], sz = Interpolate(ugz, t) - p.vy[n];
    const double slip = std::hypot(sx, sz);
    if (!sizes && !per_class_law) {
      // dga = beta / phi: c_p = beta V_p / (1 - eps) without the 0/0 at eps = 1.
      m.c[n] = law_->dga(eps_p, mu, rho_g, slip, p.diameter[n]) * p.volume(n);
    } else {
      const double d_mean = sizes ? Interpolate(d3, t) / Interpolate(d2, t) : p.diameter[n];
      m.c[n] = per_class_law ? law_->particle_drag(eps_p, mu, rho_g, slip, p.diameter[n], d_mean)
                             : law_->dga(eps_p, mu, rho_g, slip, d_mean) * p.volume(n);
    }
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        const double cw = m.c[n] * t.wx[a] * t.wz[b];
        csum(t.i[a], t.j[b]) += cw;
        cux(t.i[a], t.j[b]) += cw * p.vx[n];
        cuz(t.i[a], t.j[b]) += cw * p.vy[n];
      }
  }
  m.beta = csum / vcell;
  m.upx = (csum > 0.0).select(cux / csum, 0.0);
  m.upz = (csum > 0.0).select(cuz / csum, 0.0);

  // 3. Gas step with implicit drag.
  gas.SetSolids(eps_next, m.beta, m.upx, m.upz);
  try {
    gas.Step(gas_dt_);
  } catch (const Error& e) {
    throw Error(e.code(), "DPM stopped at t = " + Num(m.time) + " s (gas): " + e.what());
  }
  m.eps = eps_next;
  centre_velocity();

  // 4. Grid -> particles: drag with the new gas velocity (implicit on both sides) and the
  // pressure-gradient force; gas-side drag of the cell fields for the action-reaction check.
  for (std::size_t n = 0; n < np; ++n) {
    const Tent& t = tents[n];
    const double fx = m.c[n] * (Interpolate(ugx, t) - p.vx[n]);
    const double fz = m.c[n] * (Interpolate(ugz, t) - p.vy[n]);
    const Eigen::Vector2d gp = gas.PressureGradientAt(p.x[n], p.y[n]);
    diag.drag_on_particles_x += fx;
    diag.drag_on_particles_z += fz;
    p.fx_ext[n] = opt_.freeze_particles ? 0.0 : fx - p.volume(n) * gp.x();
    p.fy_ext[n] = opt_.freeze_particles ? 0.0 : fz - p.volume(n) * gp.y();
    p.fz_ext[n] = 0.0;
  }
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      diag.drag_on_gas_x += m.beta(i, j) * vcell * (m.upx(i, j) - ugx(i, j));
      diag.drag_on_gas_z += m.beta(i, j) * vcell * (m.upz(i, j) - ugz(i, j));
    }
  result_.max_action_reaction_mismatch_n =
      std::max(result_.max_action_reaction_mismatch_n,
               std::hypot(diag.drag_on_particles_x + diag.drag_on_gas_x,
                          diag.drag_on_particles_z + diag.drag_on_gas_z));
  const GasDiagnostics& gd = gas.diagnostics();
  if (gd.mass_in_kg_s > 0.0)
    result_.max_relative_mass_imbalance = std::max(
        result_.max_relative_mass_imbalance, std::abs(gd.mass_imbalance_kg_s) / gd.mass_in_kg_s);
  ++result_.gas_steps;

  // 5. DEM substeps; the wall impulse on the particles enters the momentum balance.
  m.wall_impulse_step = 0.0;
  if (!opt_.freeze_particles) {
    const int k = static_cast<int>(std::lround(gas_dt_ / result_.dem_dt_s));
    try {
      for (int s = 0; s < k; ++s) {
        dem.step(result_.dem_dt_s);
        double fy = 0.0;
        for (int w = 0; w < 6; ++w) fy -= dem.wall_force(static_cast<Wall>(w))[1];
        m.wall_impulse_step += fy * result_.dem_dt_s;
      }
    } catch (const Error& e) {
      throw Error(e.code(), "DPM stopped at t = " + Num(m.time) + " s (DEM): " + e.what());
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("DPM stopped at t = " + Num(m.time) + " s (DEM): " + e.what());
    }
    result_.dem_steps += k;
  }
  m.time += gas_dt_;
  return diag;
}

DpmResult DpmSimulation::Run(const DpmProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool settle_here = !impl_->gas;
  if (settle_here) Settle(progress);
  Impl& m = *impl_;
  const Scene& s = scene_;
  const double duration = opt_.duration_s > 0.0 ? opt_.duration_s : s.time.duration_s;
  // Enough steps to reach the duration (rounding down could stop one step short of t_ref).
  const long steps = std::max(1L, static_cast<long>(std::ceil(duration / gas_dt_ - 1e-9)));
  const double interval = s.bubble.sample_interval_s;
  const int nx = s.grid.cells_x;
  const double area = s.geometry.width_m * s.geometry.depth_m;
  const double g = s.gas.gravity_m_s2, rho_g = s.gas.density_kg_m3;
  double particle_mass = static_cast<double>(result_.particles) * s.particle_mass_kg();
  if (s.polydisperse()) {
    particle_mass = 0.0;
    const Particles& parts = m.dem->particles();
    for (std::size_t k = 0; k < parts.size(); ++k) particle_mass += parts.mass(k);
  }
  internal::BedSampler sampler(s, settled_height_);

  // Vertical momentum of gas + particles [kg m/s].
  auto total_momentum = [&]() {
    const GasPhase& gas = *m.gas;
    double pg = 0.0;
    for (int j = 0; j < gas.options().nz; ++j)
      for (int i = 0; i < nx; ++i)
        pg += rho_g * m.eps(i, j) * 0.5 * (gas.w()(i, j) + gas.w()(i, j + 1));
    pg *= gas.dx() * gas.dz() * s.geometry.depth_m;
    double pp = 0.0;
    const auto& p = m.dem->particles();
    for (std::size_t n = 0; n < p.size(); ++n) pp += p.mass(n) * p.vy[n];
    return pg + pp;
  };
  // External vertical force on gas + particles other than the walls' contact forces: pressure
  // at the distributor minus the outlet, gravity, and the momentum flux in minus out.
  auto external_force = [&]() {
    const GasPhase& gas = *m.gas;
    const int nz = gas.options().nz;
    const double p0 = gas.WidthAveragedPressure(0.5 * gas.dz()),
                 p1 = gas.WidthAveragedPressure(1.5 * gas.dz());
    const double p_bottom = p0 + 0.5 * (p0 - p1);  // linear extrapolation to the plate
    const double gas_mass = rho_g * m.eps.sum() * gas.dx() * gas.dz() * s.geometry.depth_m;
    double flux = 0.0;
    for (int i = 0; i < nx; ++i) {
      flux += rho_g * gas.w()(i, 0) * gas.w()(i, 0) * m.eps(i, 0);
      flux -= rho_g * gas.w()(i, nz) * gas.w()(i, nz) * m.eps(i, nz - 1);
    }
    flux *= gas.dx() * s.geometry.depth_m;
    return (p_bottom - gas.options().outlet_pressure_pa) * area - (gas_mass + particle_mass) * g +
           flux;
  };

  // Files only when the scene asks: every outputs.interval_s, or (interval 0) once at t_ref.
  std::unique_ptr<BedOutputWriter> writer;
  if (s.outputs.fields || s.outputs.particles) {
    const std::string dir = !opt_.output_directory.empty() ? opt_.output_directory
                            : !s.outputs.directory.empty() ? s.outputs.directory
                                                           : "out/" + s.name;
    writer = std::make_unique<BedOutputWriter>(s, result_.law, dir, s.outputs.fields,
                                               s.outputs.particles);
  }
  double next_output = s.outputs.interval_s > 0.0 ? 0.0 : -1.0;
  bool t_ref_written = false;
  double next_sample = 0.0;
  const double t_ref_abs = s.jet.start_s + s.time.t_ref_s;
  const double p_start = total_momentum();
  double f_prev = external_force();
  for (long n = 0; n < steps; ++n) {
    Step();
    const double f_now = external_force();
    m.impulse_z += 0.5 * (f_prev + f_now) * gas_dt_ + m.wall_impulse_step;
    f_prev = f_now;
    if (m.time + 1e-12 >= next_sample) {
      const internal::BedSampler::Taken taken =
          sampler.Take(m.time, m.eps, m.gas->PressureDrop(0.5 * m.gas->dz(), s.geometry.height_m));
      result_.series.push_back(taken.sample);
      result_.series.back().segregation_index =
          internal::segregation_index(m.dem->particles(), 0.0);
      if (opt_.jet && taken.nearest_to_ref) {
        result_.bubble_at_t_ref = taken.bubble.found;
        result_.bubble_diameter_m = taken.sample.bubble_diameter_m;
        result_.snapshot = Snapshot();
        result_.has_snapshot = true;
      }
      next_sample += interval;
    }
    if (writer) {
      if (next_output >= 0.0 && m.time + 1e-12 >= next_output) {
        writer->Write(m.time, *m.gas, m.dem->particles(), layer_by_id_);
        next_output += s.outputs.interval_s;
      } else if (next_output < 0.0 && !t_ref_written && m.time + 0.5 * gas_dt_ >= t_ref_abs) {
        writer->Write(m.time, *m.gas, m.dem->particles(), layer_by_id_);
        t_ref_written = true;
      }
    }
    if (progress) progress(static_cast<double>(n + 1) / steps, "coupled run");
  }
  if (writer) {
    writer->Finish();
    result_.output_files = writer->files();
  }
  const double weight =
      (particle_mass + rho_g * s.geometry.width_m * s.geometry.height_m * s.geometry.depth_m) * g;
  result_.momentum_mismatch =
      std::abs(total_momentum() - p_start - m.impulse_z) / (weight * std::max(m.time, 1e-30));
  result_.law_out_of_range = law_->out_of_range_count();
  result_.threads = omp_get_max_threads();
  result_.wall_s = (settle_here ? 0.0 : result_.settle_wall_s) +
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result_;
}

}  // namespace consumers
}  // namespace draglab
