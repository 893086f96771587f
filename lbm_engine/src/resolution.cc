// resolution.cc: see draglab/lbm/resolution.h.
#include "draglab/lbm/resolution.h"

#include "draglab/core/text.h"
#include "error_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace draglab {
namespace lbm {
namespace {

constexpr double kCs = 0.57735026918962576;  // 1/sqrt(3)
/// TRT (Lambda = 3/16) with BFL or bounce-back, kappa estimated (docs/validation.md): phi 0.6
/// stable at 24 and diverged at 28 and 32; phi 0.3 stable at 31. Refused beyond the largest,
/// suggested at the smallest stable value.
constexpr double kTrtMaxCellReynolds = 35.0;
constexpr double kTrtStableCellReynolds = 23.0;
/// rr with TRT's wall (the default with interpolated walls), kappa estimated (docs/validation.md,
/// the dense sweeps): every run up to 82 held (phi 0.6 at d 48 and Re 300: 79.9, converged); one
/// at 82.7 diverged (27 spheres, phi 0.5, d 32, Re 300) where one at 82.2 converged (8 spheres),
/// and every run from 120 on diverged (phi 0.6, d 32, Re 300; phi 0.3, d 32, Re 1000: 155).
/// Not refused (plain rr, --rr-wall-correction off, held 155): suggested, and planned for.
constexpr double kRegularizedStableCellReynolds = 82.0;

using core::format_fixed;

}  // namespace

double estimated_pore_speed_ratio(double phi) {
  const double p = std::clamp(phi, 0.0, 0.7);
  return 2.7 / std::pow(1.0 - p, 1.7);
}

double max_cell_reynolds(Collision collision) {
  switch (collision) {
    case Collision::kBgk:
    case Collision::kTrt:
      return kTrtMaxCellReynolds;
    case Collision::kRegularized:
    case Collision::kAuto:
      return std::numeric_limits<double>::infinity();
  }
  return kTrtMaxCellReynolds;
}

double stable_cell_reynolds(Collision collision) {
  switch (collision) {
    case Collision::kBgk:
    case Collision::kTrt:
      return kTrtStableCellReynolds;
    case Collision::kRegularized:
    case Collision::kAuto:
      return kRegularizedStableCellReynolds;
  }
  return kTrtStableCellReynolds;
}

CollisionChoice choose_collision(double phi, double re, double d, Collision requested) {
  if (requested != Collision::kAuto) return {requested, std::string()};
  if (re <= 0.0) {
    return {Collision::kTrt, "Stokes flow: TRT, whose wall does not move with tau at Lambda 3/16"};
  }
  const double kappa = estimated_pore_speed_ratio(phi);
  const double cell_re = kappa * re / d;
  const std::string what = "kappa Re / d = " + format_fixed("%.3g", kappa) + " x " +
                           format_fixed("%g", re) + " / " + format_fixed("%.4g", d) + " = " +
                           format_fixed("%.3g", cell_re);
  if (cell_re <= kTrtStableCellReynolds) {
    return {Collision::kTrt, what + " <= " + format_fixed("%g", kTrtStableCellReynolds) +
                                 ", where TRT has held in every measured packing: TRT, whose "
                                 "wall is exact at Lambda 3/16"};
  }
  return {Collision::kRegularized,
          what + " > " + format_fixed("%g", kTrtStableCellReynolds) +
              ", beyond what TRT holds in every measured packing (it would need --d " +
              format_fixed("%g", std::ceil(kappa * re / kTrtStableCellReynolds)) +
              "): rr, which holds it, with TRT's wall correction (its remaining wall error is "
              "in error_estimate)"};
}

std::string VelocityPlan::Summary() const {
  std::string s = "kappa = u_max/U = " + format_fixed("%.3g", kappa) +
                  (kappa_measured ? " (measured)" : " (estimated from phi)") + ", Ma target " +
                  format_fixed("%g", mach_target) + " -> U = " + format_fixed("%.4g", velocity) +
                  ", tau = " + format_fixed("%.5g", tau) +
                  ", Re_cell = kappa Re/d = " + format_fixed("%.3g", cell_reynolds);
  if (std::isfinite(cell_reynolds_limit))
    s += " (limit " + format_fixed("%g", cell_reynolds_limit) + ")";
  return s;
}

VelocityPlan plan_velocity(double phi, double re, double d, Collision collision, double mach_target,
                           double kappa, bool kappa_measured, double tau) {
  collision = choose_collision(phi, re, d, collision).collision;
  VelocityPlan plan;
  plan.kappa = kappa > 0.0 ? kappa : estimated_pore_speed_ratio(phi);
  plan.kappa_measured = kappa > 0.0 && kappa_measured;
  plan.mach_target = mach_target;
  const double stokes_tau = collision == Collision::kTrt ? 1.5 : 1.0;
  if (tau > 0.0) {
    plan.tau = tau;
    plan.nu = (tau - 0.5) / 3.0;
    plan.velocity = re * plan.nu / d;
  } else {
    plan.velocity = mach_target * kCs / plan.kappa;
    plan.tau = std::min(stokes_tau, 0.5 + 3.0 * plan.velocity * d / re);
    plan.nu = (plan.tau - 0.5) / 3.0;
    plan.velocity = re * plan.nu / d;  // below the budget where tau is capped
  }
  plan.kappa_stability = estimated_pore_speed_ratio(phi);
  plan.cell_reynolds = plan.kappa_stability * re / d;
  plan.cell_reynolds_limit = max_cell_reynolds(collision);
  const double stable = stable_cell_reynolds(collision);
  plan.d_stable = std::isfinite(stable) ? std::ceil(plan.kappa_stability * re / stable) : 0.0;
  return plan;
}

std::string cell_reynolds_refusal(const VelocityPlan& plan, double re, double d,
                                  Collision collision) {
  if (plan.within_limit()) return std::string();
  return "the cell Reynolds number kappa Re / d = " + format_fixed("%.3g", plan.kappa_stability) +
         " x " + format_fixed("%g", re) + " / " + format_fixed("%.4g", d) + " = " +
         format_fixed("%.3g", plan.cell_reynolds) +
         " (kappa = u_max/U at finite Re, estimated from phi) is beyond what " +
         to_string(collision) + " holds (" + format_fixed("%g", plan.cell_reynolds_limit) +
         ": it diverges there whatever the velocity); " + "remedy: --d " +
         format_fixed("%g", plan.d_stable) + " or more, or a lower Re";
}

std::string ResolutionNeed::Summary() const {
  return "d >= " + format_fixed("%.3g", d) + " (gaps " + format_fixed("%.3g", gaps) +
         ", boundary layer " + format_fixed("%.3g", boundary_layer) + ", stability " +
         format_fixed("%.3g", stability) + ")";
}

ResolutionNeed resolution_needed(double phi, double re, Collision collision, double kappa) {
  ResolutionNeed need;
  // D_h = h d with h = (2/3)(1 - phi)/phi.
  const double h = (2.0 / 3.0) * (1.0 - phi) / phi;
  need.gaps = kGapNodes / h;
  if (re > 0.0) {
    const double re_h = re * (2.0 / 3.0) / phi;
    const double re_p = re / (1.0 - phi);
    need.boundary_layer = kLayerNodes * std::max(std::sqrt(re_p), std::sqrt(re_h) / h);
    const double stable = stable_cell_reynolds(collision);
    const double k = kappa > 0.0 ? kappa : estimated_pore_speed_ratio(phi);
    need.stability = std::isfinite(stable) ? k * re / stable : 0.0;
  }
  need.d = std::max({need.gaps, need.boundary_layer, need.stability});
  return need;
}

bool expects_unsteady_flow(double phi, double re) {
  return re / (1.0 - phi) >= kUnsteadySphereRe && re * (2.0 / 3.0) / phi >= kUnsteadyPoreRe;
}

double planned_discretisation_error(double phi, double re, double d, Collision requested,
                                    Boundary boundary, Precision precision) {
  const Collision collision = choose_collision(phi, re, d, requested).collision;
  const RunOptions defaults;
  ErrorModelInput em;
  em.boundary = boundary;
  em.collision = collision;
  em.tau = re > 0.0 ? plan_velocity(phi, re, d, collision, kDefaultMachTarget, 0.0, false).tau
                    : (collision == Collision::kTrt ? 1.5 : 1.0);
  // As the driver: rr's reflected values corrected to TRT's wall where its own Lambda is smaller.
  em.wall_corrected = collision == Collision::kRegularized && boundary == Boundary::kInterpolated &&
                      defaults.rr_wall_correction &&
                      2.0 * defaults.magic / (em.tau - 0.5) - 1.0 > 0.0;
  em.magic = collision == Collision::kTrt || em.wall_corrected ? defaults.magic
             : collision == Collision::kBgk                    ? (em.tau - 0.5) * (em.tau - 0.5)
                                                               : 0.5 * (em.tau - 0.5);
  em.d = d;
  em.phi = phi;
  em.re = re;
  em.precision = precision;
  return widen_for_resolution(discretisation_error_estimate(em), d,
                              resolution_needed(phi, re, requested), boundary)
      .error;
}

}  // namespace lbm
}  // namespace draglab
