// tfm/tfm.h: the two-fluid model (TFM) of a pseudo-2-D fluidized bed with the
// kinetic theory of granular flow, one loaded drag law coupling the phases.
//
// Equations (seed Eqs. 8-9 gas, 11-13 solids, 15 granular temperature), on the 2-D staggered
// grid of the gas phase (gas_phase.h: x across the width, z up, cell (i, j) over
// [i dx, (i+1) dx] x [j dz, (j+1) dz]):
//   d(eps rho_g)/dt + div(eps rho_g u) = 0,  d(phi rho_s)/dt + div(phi rho_s v) = 0, eps + phi = 1
//   eps rho_g Du/Dt = -eps grad p + div(eps mu_g grad u) + beta (v - u) + eps rho_g g
//   phi rho_s Dv/Dt = -phi grad p - grad P_s + div tau_s + beta (u - v) + phi rho_s g
//   (3/2)[d(phi rho_s theta)/dt + div(phi rho_s theta v)]
//       = (-P_s I + tau_s):grad v + div(kappa grad theta) - 3 beta theta - gamma
// with beta = Law::beta(eps, mu_g, rho_g, |u - v|, d) (interstitial slip, the draglab
// convention), P_s, tau_s (shear and bulk viscosity), kappa and gamma from ktgf.h.
//
// Numerics (docs/tfm.md): first order in time; explicit upwind advection and explicit stresses
// (the solids viscosity optionally point-implicit, SolidsViscosity; the granular pressure
// optionally implicit, SolidsPressure);
// the interphase drag by partial elimination (the 2 x 2 face system of both momentum equations
// is solved exactly, so any beta is stable); one pressure equation for the mixture volume flux
// (div(eps u + phi v) = 0, mac_pressure.h); phi transported with the projected solids flux
// (upwind), bounded to [0, packing_limit] by limiting a face's solids flux and giving the
// difference to the gas on the same face (both phases stay conserved to round-off); theta with
// its conduction and sinks (dissipation, drag, expansion) implicit, an M-matrix solve, so it
// cannot become negative. The time step adapts to the smallest of the CFL limit of both phases,
// the granular pressure wave speed sqrt(dP_s/dphi / rho_s) (explicit pressure), the solids
// viscosity (explicit viscosity) and dt_max; every step records which one set it. Below
// residual_solids the solids carry no stress and no theta; the kinetic transport coefficients
// are Knudsen-limited to the cell size (ktgf.h knudsen_length_m).
// The run stops with a diagnosis (Error naming the limit and a remedy) on a non-finite field,
// a negative theta, phi outside [0, packing_limit] or a time step below dt_min.
//
// Units SI. Limits: laminar gas; one cell across the depth (no front/back wall friction);
// monodisperse solids; free-slip or no-slip solids walls; frictional stress optional (ktgf.h).
#pragma once

#include <Eigen/Core>

#include <limits>
#include <memory>
#include <string>

#include "draglab/consumers/gas_phase.h"
#include "draglab/drag_db/law.h"
#include "tfm/ktgf.h"

namespace draglab {
namespace consumers {

/// How a face's solids fraction is taken from its cells: the donor cell's (first-order upwind)
/// or van Leer's TVD reconstruction (second order where the fraction is smooth, upwind at
/// extrema and walls).
enum class FractionScheme { kUpwind, kVanLeer };

/// How the solids viscous stress enters the momentum predictor: explicitly (the step is bounded
/// by the viscous stability limit, dt <= 0.25 phi rho_s / ((2 mu + lambda) (1/dx^2 + 1/dz^2)))
/// or point-implicitly, for viscosities (frictional, near packing) that would make that limit
/// the smallest: where a face's explicit term would be unstable at the step, the face's own
/// velocity in its viscous term is taken at the new time level with the smallest coefficient
/// that makes the update stable; elsewhere the term stays explicit and the results are the
/// explicit scheme's.
enum class SolidsViscosity { kExplicit, kPointImplicit };

/// How the granular pressure enters: explicitly (in the momentum predictor at the old solids
/// fraction; the step is bounded by the granular pressure wave, dt <= CFL h / c) or implicitly:
/// the predictor keeps the old pressure and, after the projection, the solids fluxes are
/// corrected by the pressure increment P'(phi) (phi_new - phi_old) at the new fractions, one
/// symmetric positive definite solve per step, with the mixture flux held (the gas takes the
/// difference on each face). Stable at any step for the pressure wave (the step is not bounded
/// by it); near packing, where P' is large, the correction spreads the compression over the
/// neighbouring cells at once.
enum class SolidsPressure { kExplicit, kImplicit };

/// How the granular temperature is found: transported (Eq. 15 with convection and conduction)
/// or in local equilibrium each step (KtgfClosures::EquilibriumTheta; cheaper, no memory).
enum class GranularTemperature { kTransport, kAlgebraic };

/// Everything a TFM run needs besides the law. The gas member holds the grid, the gas, gravity
/// (gravity_z < 0 points down) and the inflow (background, jet, ramp).
struct TfmOptions {
  GasOptions gas;
  double particle_diameter_m = 2.5e-3;     ///< > 0.
  double particle_density_kg_m3 = 2526.0;  ///< > rho_g.
  KtgfOptions ktgf;  ///< knudsen_length_m = 0 here means the cell size (min(dx, dz)).
  // Initial state: solids fraction initial_solids below initial_bed_height_m, 0 above.
  double initial_solids = 0.58;       ///< [0, packing_limit).
  double initial_bed_height_m = 0.0;  ///< [0, height].
  double initial_theta_m2_s2 = 1e-4;  ///< >= 0.
  double residual_solids = 1e-4;      ///< Below it: no solids stress, theta = 0; (0, 1e-2].
  double cfl = 0.3;                   ///< Of both phases and the pressure wave, (0, 0.5].
  double dt_max_s = 5e-4;             ///< Largest step, > 0.
  double dt_min_s = 1e-8;             ///< Stop with a diagnosis below it, (0, dt_max].
  /// Fixed step [s] instead of the adaptive one (0: adaptive). A fixed step above the stability
  /// limit stops the run with a diagnosis naming the limit.
  double fixed_dt_s = 0.0;      ///< [0, dt_max_s].
  bool freeze_solids = false;   ///< Solids held at rest (fixed bed): validation.
  bool interphase_drag = true;  ///< false: beta = 0 (granular-gas validations).
  /// Tangential solids velocity at the walls and the bottom plate: free slip (no wall shear)
  /// or no slip (v = 0 on the wall, the wall shear from the solids viscosity).
  WallSlip solids_walls = WallSlip::kFreeSlip;
  FractionScheme fraction_scheme = FractionScheme::kUpwind;
  SolidsViscosity solids_viscosity = SolidsViscosity::kExplicit;
  SolidsPressure solids_pressure = SolidsPressure::kExplicit;
  GranularTemperature granular_temperature = GranularTemperature::kTransport;
  /// With the algebraic theta: cells below this solids fraction get theta = 0. Local
  /// equilibrium needs collisions to relax theta faster than the flow changes it; in a dilute
  /// cell (dissipation ~ phi^2) the equilibrium under the shear of the gas-borne particles is
  /// unbounded (10^4-10^5 m^2/s^2 at phi ~ 1e-4), where transported it never builds up.
  /// [0, packing_limit).
  double algebraic_theta_min_solids = 0.05;

  bool IsValid(std::string* error) const;
};

/// What limited a time step.
enum class TfmStepLimit {
  kGasCfl,
  kSolidsCfl,
  kPressureWave,
  kSolidsViscosity,
  kMaximum,
  kFixed,
  kLanding,  ///< Shortened to land on an output time (not a stability limit).
};
const char* to_string(TfmStepLimit limit);

/// Diagnostics: conservation, bounds, the time step and its limits.
struct TfmDiagnostics {
  double time_s = 0.0;
  long steps = 0;
  double last_dt_s = 0.0;
  double min_dt_s = 0.0;  ///< Smallest step a stability limit set (landing steps left out).
  TfmStepLimit last_limit = TfmStepLimit::kMaximum;
  long steps_by_limit[7] = {0, 0, 0, 0, 0, 0, 0};  ///< Indexed by TfmStepLimit.
  double solids_mass_kg = 0.0;                     ///< Current, full depth.
  double initial_solids_mass_kg = 0.0;
  double gas_mass_imbalance_kg = 0.0;  ///< Integrated in - out - storage since start.
  double gas_mass_in_kg = 0.0;         ///< Integrated inflow since start.
  double max_solids_fraction = 0.0;
  double max_theta_m2_s2 = 0.0;
  long flux_limited_faces = 0;        ///< Faces whose solids flux the bounds limited.
  long positivity_limited_cells = 0;  ///< Cell-steps whose outflow was cut to their content.
  long packing_limited_cells = 0;     ///< Cell-steps whose inflow was cut at the packing limit.
  /// Face-steps whose solids viscous term was taken point-implicitly (SolidsViscosity).
  long implicit_viscosity_faces = 0;
  /// Largest |phi correction| of the implicit solids pressure in a step (SolidsPressure).
  double max_pressure_correction = 0.0;
  double max_wave_speed_m_s = 0.0;  ///< sqrt(dP_s/dphi / rho_s), max over cells and steps.
  double poisson_residual = 0.0;
  std::string BriefReport() const;
};

/// The two-fluid model on one grid.
class TfmSimulation {
 public:
  /// Throws Error(kInvalidArgument) for invalid options or a null law.
  TfmSimulation(const TfmOptions& options, std::shared_ptr<const Law> law);
  ~TfmSimulation();
  TfmSimulation(const TfmSimulation&) = delete;
  TfmSimulation& operator=(const TfmSimulation&) = delete;

  /// Replaces the solids fraction (nx x nz, in [0, packing_limit]) and theta (>= 0).
  void SetState(const Eigen::ArrayXXd& solids_fraction, const Eigen::ArrayXXd& theta);
  /// Sets both phases to a uniform interstitial velocity (walls stay impermeable).
  void SetUniformVelocity(double gas_x, double gas_z, double solids_x, double solids_z);

  /// The step the stability limits allow now (and which limit), capped by dt_max.
  double StableTimeStep(TfmStepLimit* limit = nullptr) const;
  /// One step; returns its length [s]. Throws Error(kInvalidArgument) with a diagnosis when
  /// the run cannot go on (see the file comment).
  double Step();
  /// Steps until time() >= t_end (the last step is shortened to land on t_end).
  void AdvanceTo(double t_end);

  const TfmOptions& options() const { return opt_; }
  double time() const;
  double dx() const;
  double dz() const;
  const Eigen::ArrayXXd& solids_fraction() const;  ///< phi, nx x nz.
  Eigen::ArrayXXd gas_fraction() const;            ///< 1 - phi.
  const Eigen::ArrayXXd& theta() const;            ///< nx x nz [m^2/s^2].
  const Eigen::ArrayXXd& pressure() const;         ///< nx x nz [Pa].
  const Eigen::ArrayXXd& gas_u() const;            ///< (nx+1) x nz, x-faces [m/s].
  const Eigen::ArrayXXd& gas_w() const;            ///< nx x (nz+1), z-faces.
  const Eigen::ArrayXXd& solids_u() const;
  const Eigen::ArrayXXd& solids_w() const;
  const Eigen::ArrayXXd& beta() const;  ///< Last step's cell beta [kg m^-3 s^-1].
  const TfmDiagnostics& diagnostics() const;
  /// Width-averaged pressure drop between heights z_low < z_high (gas_phase.h convention).
  double PressureDrop(double z_low, double z_high) const;

 private:
  friend class TfmStepStages;
  /// One step of min(stable, dt_cap) (or the fixed step); returns its length.
  double StepCapped(double dt_cap);
  struct Impl;
  TfmOptions opt_;
  std::shared_ptr<const Law> law_;
  std::unique_ptr<Impl> impl_;
};

/// One step of a TfmSimulation as its stages, each a call: TfmSimulation::Step runs them all in
/// this order; a test runs them one by one and looks at what a stage left. A stage called out of
/// order is a bug of the caller (each reads what the earlier ones computed).
class TfmStepStages {
 public:
  /// Begins a step of at most dt_cap seconds on `simulation` (which it changes from Project on).
  explicit TfmStepStages(TfmSimulation& simulation,
                         double dt_cap = std::numeric_limits<double>::infinity());
  ~TfmStepStages();
  TfmStepStages(const TfmStepStages&) = delete;
  TfmStepStages& operator=(const TfmStepStages&) = delete;

  /// The closures and the step (stable, fixed or landing on dt_cap); returns it [s].
  double ChooseStep();
  /// beta of every cell from the law (the simulation's beta()).
  void DragCoefficients();
  /// The granular stresses at cell centres and corners.
  void SolidsStress();
  /// Both phases' face velocities without the new pressure gradient (drag eliminated).
  void PredictFaces();
  /// The mixture pressure equation (the new pressure()).
  void SolvePressure();
  /// The face velocities with the new pressure gradient (gas_u() ... solids_w()).
  void Project();
  /// The solids and mixture volume fluxes of every face.
  void SolidsFluxes();
  /// The implicit granular-pressure increment (SolidsPressure::kImplicit; else nothing).
  void ImplicitSolidsPressure();
  /// The solids fluxes limited to keep phi in [0, packing_limit] (the gas takes the volume).
  void LimitSolidsFluxes();
  /// The limited faces' velocities made consistent with their fluxes.
  void CorrectLimitedFaces();
  /// The new granular temperature (transported or algebraic, as the options say).
  void UpdateGranularTemperature();
  /// The new state, the time and the diagnostics.
  void Record();

  double dt() const;
  /// Mixture volume fluxes [m^2/s per unit depth] through the x-faces ((nx+1) x nz) and z-faces
  /// (nx x (nz+1)) after SolidsFluxes (and after the limiter, which holds them).
  const Eigen::ArrayXXd& mixture_flux_x() const;
  const Eigen::ArrayXXd& mixture_flux_z() const;
  /// The solids fraction the step leads to (after LimitSolidsFluxes).
  const Eigen::ArrayXXd& new_solids_fraction() const;

 private:
  TfmSimulation& sim_;
  double dt_cap_;
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace consumers
}  // namespace draglab
