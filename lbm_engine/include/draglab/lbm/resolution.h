// draglab/lbm/resolution.h: the velocity, relaxation time and stability margin of a finite-Re
// run, and the resolution d a point needs (lbm run, campaign plan and campaigns use the same).
//
// Three numbers decide a finite-Re run at resolution d (lattice units per diameter):
//  - the pore-speed ratio kappa = max|u| / U (largest pore speed over the superficial velocity):
//    a property of the packing's geometry that falls with Re as inertia evens the pore flow out
//    (in dense packings the Stokes value is 1.3 - 1.5x the one at Re 30). The velocity is planned
//    with the Stokes value, measured by a short Stokes run on the same lattice (an upper bound,
//    so the Mach target holds); stability is judged with estimated_pore_speed_ratio(phi), a fit
//    to finite-Re runs;
//  - the Mach target Ma = max|u| sqrt(3), which fixes U = Ma c_s / kappa (c_s = 1/sqrt 3);
//  - the cell Reynolds number Re_cell = max|u| dx / nu = kappa Re / d, which decides stability:
//    an operator holds up to its measured limit (max_cell_reynolds), whatever U is.
// Then nu = U d / Re and tau = 1/2 + 3 nu. Mach sets U; Re_cell sets d; tau follows.
//
// Resolution rule (resolution_needed), three lower bounds on d:
//  (a) gaps: D_h = (2/3) (1 - phi)/phi d (hydraulic diameter of the pores) spans kGapNodes nodes
//      (the dense Stokes sweeps of docs/validation.md: phi 0.5 at d 12, D_h = 8 nodes, within
//      0.2 % of d 24; phi 0.6 at d 16, D_h = 7, within 0.05 %);
//  (b) boundary layer: the thinner of the sphere's, d / sqrt(Re_p) with Re_p = Re / (1 - phi),
//      and the pores', D_h / sqrt(Re_h) with Re_h = Re (2/3)/phi, spans kLayerNodes nodes;
//  (c) stability: kappa Re / d below the operator's stable_cell_reynolds.
// (a) and (b) are accuracy rules (docs/validation.md checks them against d sweeps); (c) is the
// one a run refuses on.
#pragma once

#include <string>

#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {

/// Default Mach target max|u| sqrt(3) of finite-Re runs. The compressibility error is of order
/// Ma^2; measured, F moves by under 0.1 % between targets 0.05, 0.1 and 0.2 (docs/validation.md),
/// while the cost is proportional to 1/Ma.
constexpr double kDefaultMachTarget = 0.15;

/// Nodes across the pores' hydraulic diameter (rule a) and across the boundary layer (rule b).
constexpr double kGapNodes = 8.0;
constexpr double kLayerNodes = 1.5;

/// kappa = max|u|/U of a random packing at solids fraction phi in (0, 1) at finite Re, fitted to
/// the engine's runs on 16 - 27 sphere packings at Re 20 - 30 (phi 0.3 - 0.6, docs/validation.md):
/// 2.7 / (1 - phi)^1.7. It falls slowly with Re, so at higher Re it errs on the safe side.
double estimated_pore_speed_ratio(double phi);

/// The cell Reynolds number kappa Re / d (kappa estimated) beyond which every measured run of
/// `collision` diverged (docs/validation.md, the stability map): runs are refused above it.
/// Infinite for the regularized operator (robust; a divergence is diagnosed, not refused) and
/// for kAuto.
double max_cell_reynolds(Collision collision);
/// The cell Reynolds number at which every measured run of `collision` was stable, whatever
/// phi: the resolution suggested to a refused or diverged run, and rule (c) of the resolution
/// rule. For regularized (and auto, which takes it beyond TRT's) the value measured with TRT's
/// wall: a run beyond it is warned and planned for, not refused.
double stable_cell_reynolds(Collision collision);

/// The operator of a run: `requested` itself, or for Collision::kAuto TRT in Stokes flow and
/// where the estimated cell Reynolds number kappa Re / d is within stable_cell_reynolds(kTrt)
/// (TRT's wall is exact at Lambda 3/16), the regularized operator beyond it (with TRT's wall
/// where the wall is interpolated: RunOptions::rr_wall_correction).
struct CollisionChoice {
  Collision collision = Collision::kTrt;
  std::string reason;  ///< Why, for an automatic choice (empty otherwise).
};
CollisionChoice choose_collision(double phi, double re, double d, Collision requested);

/// The velocity and relaxation plan of one finite-Re run.
struct VelocityPlan {
  double kappa = 0.0;            ///< Pore-speed ratio the velocity is planned with.
  bool kappa_measured = false;   ///< From a Stokes run on the lattice (else estimated from phi).
  double kappa_stability = 0.0;  ///< estimated_pore_speed_ratio(phi): for Re_cell.
  double mach_target = kDefaultMachTarget;
  double velocity = 0.0;  ///< Superficial U (lattice units).
  double tau = 0.0;       ///< Relaxation time (capped at the Stokes value: U then smaller).
  double nu = 0.0;
  double cell_reynolds = 0.0;        ///< kappa_stability Re / d.
  double cell_reynolds_limit = 0.0;  ///< max_cell_reynolds of the operator.
  /// The d that brings kappa Re / d to stable_cell_reynolds (0 when that is infinite).
  double d_stable = 0.0;
  bool within_limit() const { return cell_reynolds <= cell_reynolds_limit; }
  /// "kappa = 17.1 (measured), Ma target 0.1 -> U = 0.00337, tau = 0.5054, Re_cell = 21.3 ...".
  std::string Summary() const;
};

/// The plan at solids fraction phi, target Re > 0 and resolution d: U from the Mach target and
/// kappa, tau = min(stokes_tau, 1/2 + 3 U d / Re). `tau` > 0 forces the relaxation time (U
/// then follows from Re). Collision::kAuto plans for the operator choose_collision picks.
VelocityPlan plan_velocity(double phi, double re, double d, Collision collision, double mach_target,
                           double kappa, bool kappa_measured, double tau = 0.0);

/// The refusal of a plan beyond the operator's limit: the message names the cell Reynolds
/// number, the limit and the d that would hold (for Error(kInvalidArgument)); empty if within.
std::string cell_reynolds_refusal(const VelocityPlan& plan, double re, double d,
                                  Collision collision);

/// The resolution rule at (phi, Re) for an operator: each bound and the largest.
struct ResolutionNeed {
  double gaps = 0.0;            ///< Rule (a).
  double boundary_layer = 0.0;  ///< Rule (b); 0 at Re = 0.
  double stability = 0.0;       ///< Rule (c); 0 at Re = 0 or for an unlimited operator.
  double d = 0.0;               ///< The largest of the three.
  std::string Summary() const;  ///< "d >= 48 (gaps 23, boundary layer 45, stability 48)".
};
/// kappa 0: estimated from phi. Collision::kAuto has no stability bound (rr takes over where
/// TRT's ends).
ResolutionNeed resolution_needed(double phi, double re, Collision collision, double kappa = 0.0);

/// The a-priori relative discretisation error (RunResult::discretisation_error, before any run)
/// of one run at (phi, Re, d) with the operator `requested` resolves to, the planned tau and the
/// default wall: the engine's error model, widened below the accuracy rules as a run widens it.
/// For planning (how many resolutions a point needs); a run's own estimate uses its measured Re.
double planned_discretisation_error(double phi, double re, double d, Collision requested,
                                    Boundary boundary, Precision precision);

/// Whether a run at (phi, Re) is expected to end in unsteady flow, time-averaged over
/// RunOptions::average_time d/U after its start-up: where both the sphere-scale Reynolds number
/// Re_p = Re/(1 - phi) reaches kUnsteadySphereRe and the pores' Re_h = Re (2/3)/phi reaches
/// kUnsteadyPoreRe. A planning rule, not a stability criterion: it sets the predicted cost
/// (predicted_steps), while each run judges its own flow. The thresholds lie between the
/// measured steady and unsteady runs of random packings (docs/campaigns.md): unsteady at
/// phi 0.3 / Re 100 (Re_p 143, Re_h 222) and phi 0.5 - 0.6 / Re 300 (Re_h 333 - 400), steady at
/// phi 0.5 - 0.6 / Re 100 (Re_h 111 - 133) and everywhere at Re <= 30.
constexpr double kUnsteadySphereRe = 100.0, kUnsteadyPoreRe = 150.0;
bool expects_unsteady_flow(double phi, double re);

}  // namespace lbm
}  // namespace draglab
