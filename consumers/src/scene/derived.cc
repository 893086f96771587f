// Numbers derived from a scene and one law (draglab scene check): U_mf, time scales, steps.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "draglab/consumers/scene.h"
#include "draglab/error.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::kPi;

// Convective Courant number of the recommended gas step (the explicit advection limit is 1;
// 0.5 leaves room for the jet's acceleration through the bed).
constexpr double kGasCourant = 0.5;

std::string fmt(double x) { return scene_util::fmt(x, 4); }

}  // namespace

SceneDerived derive_scene(const Scene& scene, const Law& law) {
  scene.Validate();
  SceneDerived r;
  r.particle_count = scene.particle_count();
  r.bed_height_mf_m = scene.bed_height_mf_m();
  MinFluidizationOptions options;
  options.eps_mf = scene.eps_mf;
  r.umf = minimum_fluidization(law, scene.particles, scene.gas, options);
  r.archimedes = r.umf.archimedes;
  // kUmfPacking: the packing's own U_mf is known only after settling (DpmSimulation); the
  // eps_mf value is the estimate used for the time steps here.
  r.background_m_s = scene.distributor.mode != BackgroundMode::kFixed
                         ? scene.distributor.umf_factor * r.umf.umf_m_s
                         : scene.distributor.velocity_m_s;
  const double d = scene.particles.diameter_m, rho_p = scene.particles.density_kg_m3;
  const double mu = scene.gas.viscosity_pa_s, rho = scene.gas.density_kg_m3;
  r.stokes_number = rho_p * r.umf.umf_m_s * d / (9.0 * mu);
  r.particle_response_s = rho_p * d * d / (18.0 * mu);
  r.gas_drag_relaxation_s = scene.eps_mf * rho / r.umf.beta_mf;
  r.solids_drag_relaxation_s = (1.0 - scene.eps_mf) * rho_p / r.umf.beta_mf;
  const double dx = scene.geometry.width_m / scene.grid.cells_x;
  const double dy = scene.geometry.height_m / scene.grid.cells_y;
  // Fastest gas: the jet's interstitial velocity in the bed, or the background in the bed.
  const double u_max =
      std::max({scene.jet.velocity_m_s / scene.eps_mf, r.background_m_s / scene.eps_mf, 1e-12});
  r.recommended_gas_dt_s = kGasCourant * std::min(dx, dy) / u_max;
  r.jet_area_rate_m2_s = scene.jet.velocity_m_s * scene.jet.slot_width_m;
  r.leakage_bubble_diameter_m = r.jet_area_rate_m2_s / (kPi * r.umf.umf_m_s);
  if (scene.time.gas_dt_s > 0.0 && scene.time.gas_dt_s > dx / u_max) {
    throw Error(ErrorCode::kInvalidArgument,
                "[time] gas_dt_s = " + fmt(scene.time.gas_dt_s) +
                    " s is above the convective stability limit min(dx, dy)/u_max = " +
                    fmt(std::min(dx, dy) / u_max) + " s (u_max = " + fmt(u_max) +
                    " m/s in the jet); use 0 = auto (" + fmt(r.recommended_gas_dt_s) +
                    " s) or a smaller step");
  }
  return r;
}

std::string SceneDerived::BriefReport() const {
  std::ostringstream s;
  s << umf.law << ": N = " << particle_count << ", H_mf = " << fmt(bed_height_mf_m)
    << " m, Ar = " << fmt(archimedes) << ", U_mf = " << fmt(umf.umf_m_s)
    << " m/s (Re_mf = " << fmt(umf.re_mf) << "), background " << fmt(background_m_s)
    << " m/s, St = " << fmt(stokes_number) << ", drag relaxation gas " << fmt(gas_drag_relaxation_s)
    << " s / solids " << fmt(solids_drag_relaxation_s) << " s, gas dt " << fmt(recommended_gas_dt_s)
    << " s, D* = q/(pi U_mf) = " << fmt(leakage_bubble_diameter_m) << " m";
  return s.str();
}

}  // namespace consumers
}  // namespace draglab
