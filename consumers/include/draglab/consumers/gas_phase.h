// draglab/consumers/gas_phase.h: the volume-averaged gas phase shared by the DPM and TFM
// consumers (seed Eqs. 8-9, drag source Eq. 10), on a 2-D staggered (MAC) grid.
//
// The domain is the x-z plane of a pseudo-2-D bed: x across the width, z up the height (gravity
// along -z). The bed depth (y) enters only as a thickness: fields do not vary across it, the
// front/back walls exert no friction on the gas (free slip), and mass flow rates are per unit
// depth times the depth. See docs/gas_phase.md for the equations, the discretisation and the
// limits.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <string>

namespace draglab {
namespace consumers {

class MacPressureSolver;

/// Boundary condition of the gas tangential velocity at the left/right walls.
enum class WallSlip { kNoSlip, kFreeSlip };

/// Boundary condition in z: inflow at the bottom (prescribed superficial velocity profile) with
/// a pressure outlet at the top, or periodic (fully developed channel / box tests).
enum class VerticalBoundary { kInflowOutlet, kPeriodic };

/// Treatment of the drag term beta (u_p - u_g) in the gas momentum update. kImplicit (the only
/// sane choice at useful time steps, the relaxation time eps rho_g / beta is ~1e-4 s in a dense
/// bed) or kExplicit (forward Euler, unstable for dt > 2 tau: kept to demonstrate that in tests).
enum class DragCoupling { kImplicit, kExplicit };

/// Linear solver of the pressure Poisson equation.
enum class PoissonSolver { kDirectLDLT, kConjugateGradient };

/// Options of the gas phase. SI units. Limits are checked by IsValid.
struct GasOptions {
  int nx = 30;               ///< Cells across the width, >= 2.
  int nz = 90;               ///< Cells up the height, >= 2.
  double width_m = 0.15;     ///< Domain width (x), > 0.
  double height_m = 0.45;    ///< Domain height (z), > 0.
  double depth_m = 0.015;    ///< Bed depth (thickness of the pseudo-2-D slab), > 0.
  double rho_g = 1.2;        ///< Gas density [kg/m^3], > 0 (constant: incompressible gas).
  double mu_g = 1.8e-5;      ///< Gas dynamic viscosity [Pa s], > 0.
  double gravity_z = -9.81;  ///< Gravity along z [m/s^2], finite (0 for periodic tests).
  /// Extra body force along z per unit GAS volume [N/m^3], enters as eps * f like a driving
  /// mean pressure gradient -dP/dz (periodic channel tests), finite.
  double body_force_z = 0.0;
  double body_force_x = 0.0;  ///< Same along x [N/m^3], finite.
  WallSlip side_walls = WallSlip::kNoSlip;
  VerticalBoundary vertical = VerticalBoundary::kInflowOutlet;
  double outlet_pressure_pa = 0.0;  ///< Pressure at the top outlet (gauge), finite.
  // Inflow at the bottom (kInflowOutlet only): superficial velocities, gas volume flux per area.
  double background_velocity_m_s = 0.0;  ///< Background superficial velocity (porous plate).
  double jet_width_m = 0.0;              ///< Central slot width, 0 <= w <= width_m.
  double jet_velocity_m_s = 0.0;         ///< Superficial velocity through the slot (replaces bg).
  double jet_start_s = 0.0;              ///< Time at which the jet opens, >= 0.
  double jet_duration_s = 0.0;           ///< How long it stays open, >= 0.
  /// Valve opening time [s], >= 0: the background rises linearly from 0 over [0, ramp], the
  /// jet's excess over [start, start + ramp] and falls over [end, end + ramp], so the injected
  /// volume is exactly jet_width * jet_velocity * duration. An instantaneous switch in an
  /// incompressible gas is a pressure impulse on the whole bed (kPa spikes, docs/dpm.md).
  double inflow_ramp_s = 0.0;
  // Numerics.
  DragCoupling drag = DragCoupling::kImplicit;
  PoissonSolver poisson = PoissonSolver::kDirectLDLT;
  double cg_tolerance = 1e-10;   ///< Relative residual of the CG solve, in (0, 1e-3].
  int cg_max_iterations = 5000;  ///< >= 1.
  double cfl_max = 1.0;  ///< Stop with a diagnosis when the advective CFL exceeds it, (0, 1].

  /// True when every field is in range; otherwise false and *why (if given) names the first bad
  /// field and its allowed range.
  bool IsValid(std::string* why = nullptr) const;
};

/// Superficial inflow velocity [m/s] through the bottom face of column i (cells dx wide) at time
/// t for the distributor and jet of `options` (the ramps of GasOptions::inflow_ramp_s; a partly
/// covered face gets the area-weighted mean, so the injected volume is exact on any grid); 0 for
/// a periodic box. Shared by every bed model on the MAC grid.
double inflow_superficial_velocity(const GasOptions& options, double dx, int i, double t);

/// Width average of a cell-centred pressure p (nx x nz, cells dz high) at height z [m], linear
/// between cell centres; above the top centre it goes linearly to outlet_pressure_pa at the top
/// face when `outlet` (kInflowOutlet), below the first centre it is extrapolated.
double width_averaged_pressure(const Eigen::ArrayXXd& p, double dz, double z, bool outlet,
                               double outlet_pressure_pa);

/// Conservation and stability diagnostics of the last step. Flow rates in kg/s for the full
/// depth.
struct GasDiagnostics {
  double time_s = 0.0;
  long steps = 0;
  double mass_in_kg_s = 0.0;         ///< Gas mass flow in through the bottom.
  double mass_out_kg_s = 0.0;        ///< Gas mass flow out through the top.
  double storage_kg_s = 0.0;         ///< d/dt of the gas mass in the domain (rho_g d/dt int eps).
  double mass_imbalance_kg_s = 0.0;  ///< in - out - storage (round-off / solver tolerance).
  double max_divergence_1_s = 0.0;   ///< max over cells |d eps/dt + div(eps u)|.
  double cfl = 0.0;                  ///< max(|u| dt/dx + |w| dt/dz) after the step.
  double poisson_residual = 0.0;     ///< Relative residual of the pressure equation.
  int poisson_iterations = 0;        ///< CG iterations (0 for the direct solver).
  std::string BriefReport() const;
};

/// Volume-averaged incompressible gas on a staggered grid with a pressure projection.
///
/// Unknowns: interstitial velocities u (x-faces, (nx+1) x nz) and w (z-faces, nx x (nz+1)), and
/// the pressure p at cell centres (nx x nz). The caller supplies per-cell void fraction eps
/// (0 < eps <= 1), momentum-exchange coefficient beta [kg m^-3 s^-1] (beta multiplies the
/// interstitial slip, drag force on the gas per volume = beta (u_p - u_g)) and solids velocity
/// u_p; all default to eps = 1, beta = 0, u_p = 0. Cell (i, j) spans x in [i dx, (i+1) dx],
/// z in [j dz, (j+1) dz]; arrays are Eigen column-major with index (i, j).
///
/// Limits: laminar (no turbulence model); explicit upwind advection (CFL <= cfl_max) and
/// explicit viscosity (dt <= rho dx^2 dz^2 / (2 mu (dx^2 + dz^2))); the viscous stress is
/// div(eps mu grad u) (the transpose and bulk parts, which vanish for uniform eps, are dropped).
/// Throws draglab::Error(kInvalidArgument) on bad options/fields or a time step above the
/// stability limit, and stops with a diagnosis if the velocity becomes non-finite.
class GasPhase {
 public:
  explicit GasPhase(const GasOptions& options);
  ~GasPhase();
  GasPhase(GasPhase&&) noexcept;
  GasPhase& operator=(GasPhase&&) noexcept;
  GasPhase(const GasPhase&) = delete;  // owns a factorised pressure matrix
  GasPhase& operator=(const GasPhase&) = delete;

  /// Sets the solids fields for the next step: eps_next is the void fraction at the END of the
  /// next step (the start value is the one of the previous step, so d eps/dt = (eps_next -
  /// eps)/dt enters continuity exactly); beta and the solids velocity are used implicitly.
  /// Each array is nx x nz.
  void SetSolids(const Eigen::ArrayXXd& eps_next, const Eigen::ArrayXXd& beta,
                 const Eigen::ArrayXXd& up_x, const Eigen::ArrayXXd& up_z);
  /// Sets the current void fraction (initial state; no time derivative is implied).
  void SetVoidFraction(const Eigen::ArrayXXd& eps);
  /// Sets a uniform gas velocity (interstitial) as initial state.
  void SetUniformVelocity(double u_x, double u_z);

  /// Advances by dt [s]. Throws Error(kInvalidArgument) naming dt when dt is above the
  /// viscous or CFL limit, and when the step diverges (non-finite or CFL > cfl_max after it).
  void Step(double dt);

  /// Largest stable dt for the given CFL number (advective and viscous limits).
  double StableTimeStep(double cfl) const;

  const GasOptions& options() const { return opt_; }
  double dx() const { return dx_; }
  double dz() const { return dz_; }
  double time() const { return time_; }
  const Eigen::ArrayXXd& u() const { return u_; }        ///< (nx+1) x nz, x-faces [m/s].
  const Eigen::ArrayXXd& w() const { return w_; }        ///< nx x (nz+1), z-faces [m/s].
  const Eigen::ArrayXXd& p() const { return p_; }        ///< nx x nz, cell centres [Pa].
  const Eigen::ArrayXXd& eps() const { return eps_; }    ///< nx x nz.
  const Eigen::ArrayXXd& beta() const { return beta_; }  ///< nx x nz.
  const GasDiagnostics& diagnostics() const { return diag_; }

  /// Gas velocity (interstitial) at a point by bilinear interpolation of the staggered fields.
  Eigen::Vector2d VelocityAt(double x, double z) const;
  /// Pressure gradient at a point (bilinear interpolation of the face gradients) [Pa/m].
  /// Interpolates a cell-centred gradient field computed once per Step, so a call costs a few
  /// flops (the DPM calls it once per particle and gas step).
  Eigen::Vector2d PressureGradientAt(double x, double z) const;
  /// Width-averaged pressure at height z (linear between cell centres; the outlet value above
  /// the top cell centre).
  double WidthAveragedPressure(double z) const;
  /// Pressure drop p(z_low) - p(z_high) of the width-averaged pressure [Pa].
  double PressureDrop(double z_low, double z_high) const;
  /// Superficial inflow velocity at the bottom face of column i at time t [m/s].
  double InflowSuperficialVelocity(int i, double t) const;

 private:
  void Check(const Eigen::ArrayXXd& a, int rows, int cols, const char* name, double lo, double hi,
             bool lo_open) const;
  /// Recomputes grad_px_, grad_pz_ from p_; called wherever p_ changes.
  void UpdatePressureGradient();

  GasOptions opt_;
  double dx_, dz_;
  double time_ = 0.0;
  long steps_ = 0;
  Eigen::ArrayXXd u_, w_, p_;
  Eigen::ArrayXXd grad_px_, grad_pz_;  // cell-centred dp/dx, dp/dz [Pa/m] of p_
  Eigen::ArrayXXd eps_, eps_next_, beta_, upx_, upz_;
  GasDiagnostics diag_;
  std::unique_ptr<MacPressureSolver> pressure_;
};

}  // namespace consumers
}  // namespace draglab
