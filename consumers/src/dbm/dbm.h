// dbm/dbm.h: the discrete bubble model (seed Section 5, Eqs. 16-19): bubbles as
// Lagrangian spheres in a continuous emulsion, for reactor-scale beds.
//
// Emulsion: the volume-averaged Navier-Stokes equations of an incompressible Newtonian fluid of
// density rho_e and apparent viscosity mu_e filling the emulsion fraction eps_e = 1 - eps_b on a
// 3-D staggered grid (x across the width, y across the depth, z up; mac_pressure.h layout):
//   d(eps_e)/dt + div(eps_e u) = 0,
//   eps_e rho_e (du/dt + u.grad u) = -eps_e grad p + div(eps_e mu_e grad u) + eps_e rho_e g + R,
// R the reaction of the bubbles' drag, virtual-mass and lift forces. Bubbles and cells exchange
// fraction, force and the fields the bubbles see through a smooth kernel of a fixed physical
// width, the coupling width (particle_kernel.h Smooth3), so the coupled fields converge as the
// grid is refined under it; a bubble wider than half of it is spread over twice its diameter.
// Projection with the shared pressure equation, on the pressure less the emulsion's hydrostatic
// head. Walls: side walls no-slip (or free-slip) and a closed bottom; the top of the column is the
// bed surface, a pressure outlet through which the emulsion the bubbles displace leaves (and
// returns as they leave).
//
// Bubbles: spheres of volume-equivalent diameter d_b and density rho_b, moved by Newton's second
// law with gravity, the emulsion pressure gradient, drag calibrated to the Davies-Taylor rise
// velocity and virtual mass (dbm_closures.h), lift optional (F_L = -C_L rho_e V (v - u) x
// curl u). The emulsion carries the bubbles' added mass C_VM eps_b rho_e as inertia. Each nozzle
// on the bottom forms a bubble from its share of the flow (the forming bubble displaces emulsion
// as it grows) and releases it at d_b, from a seeded random start per nozzle; bubbles leave when
// their centre reaches the bed surface (displacing less emulsion as they break through).
// Coalescence (optional): bubbles that touch (|x1 - x2| < r1 + r2) for at least the film-drainage
// time merge, conserving volume and momentum, at the volume-weighted centre. Without it, bubbles
// collide (overlaps pushed apart, the approach velocity removed, volume-weighted) unless
// collisions are switched off. Pair search with cell lists, O(N).
//
// Time step: dt_s, optionally cut by an emulsion CFL number; the bubble step is implicit in the
// drag, the emulsion explicit in advection and viscosity, so dt is bounded by the emulsion's
// viscous and convective limits and, for the explicitly mapped reaction, by the bubbles' momentum
// relaxation time (DbmOptions::StableTimeStep and CheckTimeStep). A run whose emulsion velocity
// exceeds the convective limit stops with a diagnosis (std::runtime_error).
//
// Units SI. Limits: spherical bubbles of one diameter each; collisions resolved by position
// (a few sweeps per step), not by impulse timing; no wake, cloud or wall effect on the
// rise velocity; bubbles larger than the column (slugs) stop the run.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dbm/dbm_closures.h"
#include "draglab/consumers/gas_phase.h"

namespace draglab {
namespace consumers {

/// A nozzle on the bottom plate: its centre [m] (x across the width, y across the depth).
struct DbmNozzle {
  double x_m = 0.0;
  double y_m = 0.0;
};

/// The nozzles of a square array of n x n nozzles with pitch p centred on the bottom plate.
std::vector<DbmNozzle> square_nozzle_array(int nozzles_per_side, double pitch_m, double width_m,
                                           double depth_m);

/// The default coupling width in injected bubble diameters: Euler-Lagrange bubble-column models
/// map bubbles over a few diameters; five puts two cells in the kernel's half-width on the
/// reactor's default grid and keeps one bubble's fraction small.
constexpr double kCouplingWidthInDiameters = 5.0;

/// With an adaptive step (DbmOptions::cfl > 0), how many times a step that passed the convective
/// limit is taken again, shorter, before the run stops.
constexpr int kMaxStepRetakes = 4;
/// A step whose CFL number reaches this is diverging: it is not retaken.
constexpr double kRetakeAtMost = 10.0;

/// Everything a DBM run needs. Checked by IsValid (each message names the field and range).
struct DbmOptions {
  double width_m = 1.0;           ///< x, > 0.
  double depth_m = 1.0;           ///< y, > 0.
  double height_m = 3.0;          ///< z: the bed surface, > 0.
  int nx = 10, ny = 10, nz = 30;  ///< Cells; nx, nz >= 2, ny >= 1 (1: a 2-D column).
  double emulsion_density_kg_m3 = 400.0;
  double emulsion_viscosity_pa_s = 1.0;  ///< Apparent viscosity mu_e, > 0.
  double gravity_m_s2 = 9.81;
  WallSlip walls = WallSlip::kNoSlip;        ///< The emulsion at the x walls.
  WallSlip depth_walls = WallSlip::kNoSlip;  ///< At the y walls (free slip: a 2-D column).

  double bubble_density_kg_m3 = 25.0;
  double virtual_mass_coefficient = 0.5;
  bool lift = false;
  double lift_coefficient = 0.5;

  std::vector<DbmNozzle> nozzles;
  double bubble_gas_flow_m3_s = 0.0;  ///< Total over the nozzles, >= 0 (two-phase theory).
  double bubble_diameter_m = 0.04;    ///< Injected size, > 0 and < the column's width and depth.
  std::uint64_t seed = 1;             ///< Injection phases.
  /// Start-up: the bubble gas flow rises linearly from 0 over this time [s], >= 0, so the
  /// emulsion's circulation can form before the full flow crowds the nozzles.
  double injection_ramp_s = 0.0;

  /// Width [m] of the kernel that maps each bubble to the cells (and the cells to it), fixed so
  /// the results converge as the grid is refined under it; at least a cell is used on each
  /// axis. 0: kCouplingWidthInDiameters injected bubble diameters. In [0, column width].
  double coupling_width_m = 0.0;

  bool coalescence = false;
  double film_drainage_s = 0.0;  ///< Contact time before two touching bubbles merge, >= 0.
  /// Without coalescence: bubbles that overlap are pushed apart (perfectly inelastic hard-sphere
  /// collisions, as the seed's DBM); false: they may overlap.
  bool collisions = true;
  /// The bubbles' response to the new pressure in the pressure equation (semi-implicit: their
  /// mobility dt / (m + k dt) joins the emulsion's, and they are corrected by the pressure
  /// change); false: they feel the last step's pressure only (unstable where they crowd).
  bool implicit_bubble_pressure = true;

  double dt_s = 2e-3;  ///< The step, > 0, at most StableTimeStep().
  /// > 0: the step is cut below dt_s so the emulsion moves at most this many cells per step,
  /// (0, 0.9]; 0: dt_s always.
  double cfl = 0.0;
  PoissonSolver solver = PoissonSolver::kConjugateGradient;
  double cg_tolerance = 1e-9;
  /// Time averages (emulsion velocity, hold-up, bubble sizes) start here [s].
  double average_from_s = 0.0;
  /// Spacing of the bubble-size and hold-up samples [s], > 0.
  double sample_interval_s = 0.05;

  bool IsValid(std::string* error) const;
  /// The coupling width in use [m].
  double CouplingWidth() const;
  /// The largest stable step: min of the emulsion's explicit viscous limit h^2 rho_e / (2 d mu_e)
  /// (d the number of dimensions), and the relaxation time of the injected bubble's slip
  /// (rho_b + C_VM rho_e) / (3/4 C_D rho_e u_br / d_b), below which the mapped reaction of an
  /// implicitly stepped bubble stays bounded. The convective limit is checked as the run goes.
  double StableTimeStep() const;
};

/// One bubble. Position and velocity (x, y, z), z up.
struct DbmBubble {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  double diameter_m = 0.0;
  double volume_m3 = 0.0;
  std::uint64_t id = 0;
  /// Where the emulsion sees the gas after a jump of the bubble's centre (a coalescence, or a
  /// merged bubble pushed off a wall it has grown into): still where it was, drawn to the centre
  /// as lobe_remaining falls from 1 to 0 over the time the bubble takes to rise its own
  /// diameter: lobe_volume_m3 at x + lobe_remaining * lobe_offset, the rest at x +
  /// lobe_remaining * rest_offset. So such a jump displaces the emulsion no faster than a rising
  /// bubble does, not within one step (which no step can resolve: two 0.3 m bubbles meeting
  /// move 0.3 m of gas). Only the mapped fraction uses the lobes.
  Eigen::Vector3d lobe_offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d rest_offset = Eigen::Vector3d::Zero();
  double lobe_volume_m3 = 0.0;
  double lobe_remaining = 0.0;
};

/// Coalescence of two bubbles: one bubble of their summed volume at the volume-weighted centre
/// with the volume-weighted velocity (volume and momentum conserved; the id is a's), mapped as
/// two lobes where the parents' gas was (lobe_remaining 1): the parents' centres, or, for a
/// parent still relaxing from a merger, its lobes, joined to two so the least gas moves.
DbmBubble merge_bubbles(const DbmBubble& a, const DbmBubble& b);

/// Moves a bubble's centre by delta while the emulsion still sees its gas where it was (the
/// lobes, relaxing to the centre as after a merger).
void move_bubble_centre(DbmBubble* b, const Eigen::Vector3d& delta);

/// Counters and balances of a run.
struct DbmDiagnostics {
  long steps = 0;
  std::int64_t bubble_steps = 0;  ///< Sum over steps of the bubbles moved.
  std::int64_t bubbles_injected = 0;
  std::int64_t bubbles_left = 0;  ///< At the bed surface.
  std::int64_t coalescences = 0;
  std::int64_t collision_sweeps = 0;  ///< Overlap-resolution sweeps that moved bubbles.
  double gas_injected_m3 = 0.0;       ///< Bubble volume injected.
  double gas_left_m3 = 0.0;           ///< Bubble volume that left at the surface.
  double max_cfl = 0.0;               ///< max |u| dt / h of the emulsion over steps.
  /// Steps taken again, shorter, because the emulsion passed the convective limit (cfl > 0).
  std::int64_t retaken_steps = 0;
  double min_dt_s = 0.0;                 ///< The smallest step taken.
  double max_bubble_fraction = 0.0;      ///< Largest cell bubble fraction before the clamp.
  std::int64_t fraction_clamps = 0;      ///< Cell-steps with eps_e clamped at its minimum.
  double max_continuity_residual = 0.0;  ///< Relative residual of the pressure solve, max.
  int max_cg_iterations = 0;
  double max_bubble_diameter_m = 0.0;
  double emulsion_wall_s = 0.0;  ///< Wall time in the emulsion (predictor + pressure).
  double bubble_wall_s = 0.0;    ///< Wall time in the bubbles (forces, motion, mapping, merging).
};

/// Time averages since DbmOptions::average_from_s, kept as sums: the cell fields are integrals
/// over time (divide by time_s), the bubble statistics sums over samples (divide by samples).
struct DbmAverages {
  double time_s = 0.0;     ///< Averaged time.
  Eigen::VectorXd u_cell;  ///< Cell-centred emulsion velocity x, y, z [m s], cell layout.
  Eigen::VectorXd v_cell, w_cell;
  Eigen::VectorXd bubble_fraction;  ///< Cell bubble fraction [s].
  int samples = 0;                  ///< Bubble samples (every sample_interval_s).
  /// Hold-up per height bin (one per cell row): bubble volume with its centre in the row / row
  /// volume.
  Eigen::VectorXd holdup_by_height;
  /// Bubble diameters per height bin (rows), summed over the samples (for means), and counts.
  Eigen::VectorXd diameter_sum_by_height, count_by_height;
  /// Histogram of bubble diameters per height bin: rows x size bins of width size_bin_m.
  Eigen::MatrixXd size_histogram;
  double size_bin_m = 0.01;
};

/// A DBM run.
class DbmSimulation {
 public:
  /// Throws Error(kInvalidArgument) naming the field for invalid options or a step above
  /// StableTimeStep().
  explicit DbmSimulation(const DbmOptions& options);
  ~DbmSimulation();
  DbmSimulation(const DbmSimulation&) = delete;
  DbmSimulation& operator=(const DbmSimulation&) = delete;

  /// Advances by whole steps to the first step at or after t. Throws std::runtime_error with a
  /// diagnosis when the emulsion exceeds the convective limit (with an adaptive step: after
  /// kMaxStepRetakes shorter tries) or a bubble outgrows the column.
  void AdvanceTo(double t_s);
  void Step();

  /// Adds a bubble (tests; the run injects its own). Returns its id.
  std::uint64_t AddBubble(const Eigen::Vector3d& x, const Eigen::Vector3d& v, double diameter_m);

  double time() const { return time_; }
  const DbmOptions& options() const { return opt_; }
  const std::vector<DbmBubble>& bubbles() const { return bubbles_; }
  double gas_in_bubbles_m3() const;
  /// Gas in the bubbles still forming at the nozzles [m^3].
  double gas_forming_m3() const;
  const DbmDiagnostics& diagnostics() const { return diag_; }
  const DbmAverages& averages() const { return avg_; }
  const BubbleForceModel& force_model() const { return force_; }

  /// The emulsion velocity at a point (trilinear from the cell centres) [m/s].
  Eigen::Vector3d EmulsionVelocityAt(const Eigen::Vector3d& x) const;
  /// Cell-centred fields (layout of mac_pressure.h): bubble fraction, emulsion velocity
  /// component c (0 x, 1 y, 2 z), pressure less the hydrostatic head [Pa].
  const Eigen::VectorXd& bubble_fraction() const;
  Eigen::VectorXd emulsion_velocity(int component) const;
  const Eigen::VectorXd& dynamic_pressure() const;
  /// Net emulsion volume flux out through the bed surface in the last step [m^3/s].
  double top_outflow_m3_s() const;

 private:
  friend class DbmStepStages;
  struct Impl;
  DbmOptions opt_;
  BubbleForceModel force_;
  double time_ = 0.0;
  std::vector<DbmBubble> bubbles_;
  DbmDiagnostics diag_;
  DbmAverages avg_;
  std::unique_ptr<Impl> impl_;

  /// One step of dt (all but the time averages); returns the emulsion's CFL number reached.
  double TakeStep(double dt);
  // The stages of TakeStep, in order (dbm.cc).
  struct Projection;
  void DepositFractions(bool count);
  void SampleEmulsion(double dt);
  void InjectBubbles(double dt);
  void KeepInside(DbmBubble& bubble) const;
  void MoveBubbles(double dt);
  void RemoveLeavingBubbles();
  void CollideBubbles();
  void CoalesceBubbles(double t1);
  std::vector<double> BubbleMobility(double dt);
  void PredictEmulsion(double dt);
  Projection ProjectionCoefficients(double dt) const;
  void SolveEmulsionPressure(double dt, double t1, const Projection& projection);
  double CorrectEmulsionVelocities(double dt, const Projection& projection, int* fastest_cell);
  void FollowPressureChange(double dt, const Eigen::VectorXd& dp,
                            const std::vector<double>& bubble_mobility);
  /// The time averages and bubble samples of the step just taken.
  void Accumulate(double dt);
};

/// One step of a DbmSimulation as its stages, each a call: DbmSimulation::Step runs them in this
/// order (the bubbles', then the emulsion's); a test runs them one by one and looks at what a
/// stage left. A stage called out of order is a bug of the caller.
class DbmStepStages {
 public:
  /// Begins a step of dt seconds on `simulation` (the first step of a run deposits the initial
  /// bubbles' fractions first: they are the initial state, not a displacement).
  DbmStepStages(DbmSimulation& simulation, double dt);
  ~DbmStepStages();
  DbmStepStages(const DbmStepStages&) = delete;
  DbmStepStages& operator=(const DbmStepStages&) = delete;

  /// The emulsion velocity and pressure each bubble feels.
  void SampleEmulsion();
  /// The nozzles' gas into forming bubbles, released at the bubble diameter.
  void InjectBubbles();
  /// Bubble motion (drag implicit) and each bubble's force on the emulsion.
  void MoveBubbles();
  /// Bubbles that reached the bed surface leave (their gas counted).
  void RemoveLeavingBubbles();
  /// Collisions or coalescence, as the options say.
  void BubbleInteractions();
  /// The bubble and emulsion fractions from the bubbles' volumes.
  void DepositFractions();
  /// Each bubble's response to a pressure change (the implicit bubble pressure).
  void BubbleMobility();
  /// The emulsion momentum without the new pressure.
  void PredictEmulsion();
  /// The projection's face coefficients, then the pressure equation.
  void SolveEmulsionPressure();
  /// The emulsion velocities with the new pressure; returns the CFL number reached.
  double CorrectEmulsionVelocities();
  /// The bubbles follow the pressure change (implicit bubble pressure; else nothing).
  void FollowPressureChange();
  /// The new emulsion fraction, the time and the diagnostics.
  void Finish();

  double cfl() const { return cfl_; }

 private:
  DbmSimulation& sim_;
  double dt_, t1_;
  double cfl_ = 0.0;
  int fastest_cell_ = 0;
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace consumers
}  // namespace draglab
