// draglab/lbm/lbm.h: D3Q19 lattice-Boltzmann flow through fixed sphere arrays, drag by momentum
// exchange.
//
// Set-up: a periodic box of fixed solid bodies (arrays::VoxelGrid: solid flags and per-body
// boundary links with wall fractions q), flow driven by a uniform body force (Guo forcing) on the
// fluid: the mean pressure gradient of a fixed bed. Lattice units: dx = dt = 1, rho0 = 1,
// nu = (tau - 1/2)/3. Steady state: sum over bodies of the momentum-exchange force equals the body
// force times the fluid volume (reported as momentum_balance_rel).
//
// Outputs use the canonical drag convention (drag_db/conventions.h): with U the superficial
// velocity (sum of fluid velocities / box volume), u = U/eps the interstitial one,
//   Re = U d / nu,  F = <F_d> / (3 pi nu rho d U)  (mean over bodies of the drag-only force),
//   K = F / (1 - phi),  beta d^2/mu = 18 phi (1 - phi) F.
// d is the reference diameter in lattice units (VoxelGrid::resolution(), or the calibrated
// hydrodynamic diameter when RunOptions::use_hydrodynamic_diameter is set).
//
// Limits: Mach number max|u| sqrt(3) < mach_limit (default 0.3 stops the run; 0.1 warns), tau >
// 1/2 strictly (tau - 1/2 < 1e-3 is refused for BGK and TRT). Spheres closer than a lattice
// spacing (touching, in contact, sub-node gaps: dense random arrays at any practical resolution)
// are normal input: a node inside any sphere is solid, a link takes its wall at the first surface
// it crosses, and an interpolated link whose second node is solid bounces back halfway. The run
// reports how many sphere pairs have gaps below one node and the fraction of fluid nodes in
// such gaps (RunResult::narrow_gap_*), with a warning; min_gap_nodes > 0 turns that into a
// refusal (opt-in). A run that diverges or does not
// converge within max_steps reports converged = false and a diagnosis, and never a drag value
// (F etc. are NaN and run() throws draglab::Error unless RunOptions::throw_on_failure is false).
//
// Errors: invalid options, a malformed grid or packing, no bodies, a resolution too low for the
// gaps, or a lattice too large for memory throw Error(kInvalidArgument) always (bad input). A
// run that stops at a stability limit (tau too close to 1/2, Mach limit, NaN, density <= 0) or
// does not converge within max_steps throws Error(kOutOfValidity) with the diagnosis as message,
// unless throw_on_failure is false.
//
// Numerics (lbm_engine/src): D3Q19, populations stored shifted by their weight (f - w_i), fluid
// nodes only (plus a one-node ghost layer of solid boundary nodes), AA-pattern in-place
// streaming, SIMD collision. Guo forcing with the second-order velocity u = (sum f c + G/2)/rho.
// TRT: tau+ from nu, tau- = 1/2 + Lambda/(tau+ - 1/2). Stokes mode: linear equilibrium (no u.u
// terms; u = j). Interpolated bounce-back, linear in the wall fraction q: Ginzburg's central
// linear interpolation (CLI, the more accurate: its wall does not move with tau at fixed Lambda)
//   f_ib(x, t+1) = f*_i(x) + kappa (f*_i(x - c_i) - f*_ib(x)),  kappa = (1 - 2q)/(1 + 2q),
// or Bouzidi-Firdaouss-Lallemand's (BFL, all weights non-negative: stable near tau = 1/2, where
// CLI's negative weight blows up), 2q f*_i(x) + (1 - 2q) f*_i(x - c_i) for q < 1/2 and
// f*_i(x)/(2q) + (2q - 1)/(2q) f*_ib(x) above; WallInterpolation::kAuto takes CLI in Stokes flow
// and for tau >= kCentralWallMinTau, BFL below. Both fall back to halfway bounce-back on links
// whose node x - c_i is solid; the net mass leak is fed back through the rest populations of the
// wall nodes (no momentum change). Momentum exchange per link (f*_i + f_ib(t+1)) c_i (Ladd; Mei et
// al. 2002 with the interpolated value), averaged over the two steps of an AA pair.
// Regularized collision (rr): its odd non-equilibrium is dropped at every collision (odd moments
// relax with omega = 1, an effective Lambda = (tau - 1/2)/2 that goes to 0 as tau -> 1/2), so
// the same link closures put the wall about half a node off (docs/validation.md, "rr with TRT's
// wall").
// RunOptions::rr_wall_correction adds to each reflected value the difference between the
// closures' steady residuals under TRT at Lambda = magic and under rr, which a link-wise analysis
// gives as c (n- + g/2): n- the pre-collision odd non-equilibrium of the link pair at the wall
// node, g = 3 w_i c_i.G, c = (1 - b)(2 Lambda/(tau - 1/2) - 1) with b the closure's weight on
// f*_ib(x). n- is estimated from this step's post-collision values and the reflected value itself
// (implicitly, so its feedback is divided out): f_ib(x, t+1) = (K + c ((f*_i(x - c_i) - f*_i(x)
// + f*_ib(x))/2 + g)) / (1 + c/2), K the plain closure; a link in a one-node gap is solved
// together with the opposite link of its node. The correction is relaxed towards that value
// with a factor min(1/10, 5/c) per step, which damps its feedback through the wall node's moments
// (a feedback that grows with c) and leaves the steady state unchanged. It is applied where c > 0
// (tau < 1/2 + 2 Lambda). Precision::kFloat stores the shifted populations in float and collides in
// float (16 SIMD lanes instead of 8); moments, forces and the link pass arithmetic are accumulated
// in double. Shifting keeps the O(Ma) deviations at float's 7 digits (F agrees with double to ~1e-6
// on the simple-cubic cases); the momentum balance then has a noise floor of ~1e-5, so the float
// convergence test accepts a balance up to max(tolerance, 1e-4).
//
// Automatic choices (RunOptions::tau == 0): Re = 0 -> tau = 1.5 for TRT (its steady state does
// not depend on tau at fixed Lambda, and a larger viscosity converges faster), 1 otherwise;
// Re > 0 -> the velocity plan of draglab/lbm/resolution.h: a short Stokes run on the same
// lattice measures kappa = max|u|/U, U = mach_target c_s / kappa, tau = min(tau_Stokes,
// 1/2 + 3 U d / Re). Collision::kAuto (the default) runs TRT where kappa Re / d is within what
// TRT held in every measured packing (and in Stokes flow), rr with TRT's wall beyond it
// (RunResult::collision, collision_reason). A run whose cell Reynolds number kappa Re / d is
// beyond what the chosen operator holds is refused before any stepping (Error(kInvalidArgument),
// naming the d that would hold); a run that blows up is diagnosed as an instability (where, when,
// the cell Reynolds number there, the d that would hold). The body force starts from the force
// balance with the BVK 2007 drag and is rescaled until Re is within re_tolerance of the target;
// once it is, the force is held unless the Re of the velocity filtered over one characteristic
// time leaves the band (with a few corrections inside it), so that a fluctuating flow is not
// chased (RunResult::force_adjustments counts the corrections).
//
// Convergence: characteristic time T = d^2 / (nu (1 + Re)) steps (momentum crossing a diameter by
// diffusion, or by advection at higher Re); checks every T/10; converged when the relative
// change of F over the last T (and of U, with the full equilibrium) is below `tolerance`, the
// momentum balance is below `tolerance` too (1e-4 in float), and Re is within its band.
// Unsteady flow (F fluctuating around a stationary mean over five T, src/averaging.h): Re is
// brought to its band on the window mean, then the force is held and F time-averaged from the
// end of the start-up (MSER); converged when the blocking standard error of the mean is below
// average_tolerance after at least average_time d/U. F and Re are then time means with their
// standard errors (RunResult::unsteady).
// error_estimate = convergence_residual (the last relative change per T) +
// discretisation_error: the hydrodynamic-radius model S 2 delta / d, S = 1 + 3 phi d ln F/d phi
// (van der Hoef 2005), with the wall offset delta = 0.15 (bounce-back) or 0.2/d (interpolated)
// lattice units, fitted with a safety factor ~1.5 to the engine's simple-cubic Stokes errors
// against Sangani-Acrivos (phi 0.027 - 0.216, d 8 - 24), plus 0.35 sqrt|Lambda - 3/16| for the
// viscosity-dependent wall of BGK (Lambda = (tau - 1/2)^2), regularized ((tau - 1/2)/2) or TRT
// with another Lambda, and a growth with Re from the thinning boundary layer: sqrt(1 + Re/7) for
// bounce-back (first order), 1 + Re/7 for the interpolated wall (second order; the 7 bounds the
// measured d sweeps, dense packings at Re 100 included: src/error_model.cc). rr with TRT's wall
// adds what is left of its wall shift, 0.8/d lattice units (the largest measured against TRT at the
// same d, rounded up). It is an a-priori scale for one run; campaigns should still extrapolate in
// d.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/mpi/communicator.h"

namespace draglab {
namespace lbm {

enum class Collision {
  kBgk,          ///< Single relaxation time (the seed's baseline).
  kTrt,          ///< Two relaxation times, magic parameter Lambda (default 3/16).
  kRegularized,  ///< Regularized BGK (non-equilibrium projected on 2nd-order Hermite): robust at
                 ///< high Re / tau -> 1/2.
  /// Chosen per run (choose_collision in resolution.h): TRT where the cell Reynolds number is
  /// within what TRT held in every measured packing, rr with TRT's wall beyond it.
  kAuto,
};
const char* to_string(Collision c);
Collision collision_from_string(const std::string& s);  ///< "bgk", "trt", "rr", "auto"

enum class Boundary {
  kHalfwayBounceBack,  ///< Ladd's link bounce-back, wall at q = 1/2 regardless of geometry.
  kInterpolated,       ///< Interpolated bounce-back using q (second order for curved walls).
};
const char* to_string(Boundary b);
Boundary boundary_from_string(const std::string& s);  ///< "bb", "ibb"

/// Which linear interpolation an interpolated wall (Boundary::kInterpolated) uses.
enum class WallInterpolation {
  kAuto,     ///< CLI where it is stable (tau >= kCentralWallMinTau, and Stokes), BFL below.
  kCentral,  ///< Ginzburg's central linear interpolation (CLI): the more accurate in Stokes
             ///< flow, but one weight is negative and it blows up near tau = 1/2.
  kBouzidi,  ///< Bouzidi-Firdaouss-Lallemand linear (BFL): non-negative weights, stable near
             ///< tau = 1/2, its wall moving with tau more than CLI's at large tau.
};
const char* to_string(WallInterpolation w);
WallInterpolation wall_interpolation_from_string(const std::string& s);  ///< "auto", "cli", "bfl"

/// The smallest tau at which `auto` keeps the central interpolation. Below it BFL is stable where
/// CLI is not, and their drags differ by little (SC Stokes: 0.05 % at tau 0.52; dense packings
/// at Re 10 - 20: 0.2 - 0.4 %; docs/validation.md, "Finite Re in dense packings").
constexpr double kCentralWallMinTau = 0.52;

enum class Precision { kDouble, kFloat };
const char* to_string(Precision p);
Precision precision_from_string(const std::string& s);  ///< "double", "float"

/// Largest target Reynolds number RunOptions accepts.
constexpr double kMaxReynolds = 1e4;

/// Progress: fraction in [0, 1] (of max_steps or of convergence), and a status line.
using ProgressCallback = std::function<void(double fraction, const std::string& status)>;

struct RunOptions {
  Collision collision = Collision::kAuto;
  double magic = 3.0 / 16.0;  ///< TRT Lambda = (tau+ - 1/2)(tau- - 1/2).
  Boundary boundary = Boundary::kInterpolated;
  WallInterpolation interpolation = WallInterpolation::kAuto;  ///< With kInterpolated.
  Precision precision = Precision::kDouble;
  double re = 0.0;   ///< Target Reynolds number U d / nu, >= 0; 0 = Stokes flow.
  double tau = 0.0;  ///< Relaxation time; 0 = choose from Re and the Mach budget.
  /// Stokes mode (linear equilibrium, no u.u terms). Default: on exactly when re == 0.
  enum class StokesMode { kAuto, kOn, kOff } stokes_mode = StokesMode::kAuto;
  double re_tolerance = 0.01;  ///< Achieved Re within this relative band of the target.
  double tolerance = 1e-6;     ///< Relative drag change per characteristic time at convergence.
  std::int64_t max_steps = 200000;
  double mach_limit = 0.3;  ///< max |u| sqrt(3) above this stops the run.
  /// Finite Re with tau == 0: the Mach number max|u| sqrt(3) the velocity is planned for, in
  /// (0, 0.3] (draglab/lbm/resolution.h: U = Ma c_s / kappa).
  double mach_target = 0.15;  // = kDefaultMachTarget (resolution.h)
  /// Unsteady flow (F fluctuating around a stationary mean at the target Re): the force is held
  /// and F time-averaged until its standard error is below average_tolerance (relative, in
  /// [1e-4, 0.1]) over at least average_time d/U (in [1, 1e4]) after the start-up.
  double average_tolerance = 5e-3;
  double average_time = 20.0;
  /// Opt-in check: refuse a packing whose smallest sphere gap spans fewer lattice units (0 = off,
  /// the default: sub-node gaps are run and reported).
  double min_gap_nodes = 0.0;
  /// Regularized collision with interpolated walls: correct the reflected populations so that
  /// the wall sits where TRT at `magic` puts it (see Numerics above). Off only to compare.
  bool rr_wall_correction = true;
  bool use_hydrodynamic_diameter = false;  ///< Normalise with a calibrated d_h (bounce-back).
  double hydrodynamic_diameter = 0.0;      ///< d_h in lattice units when the above is set.
  int threads = 0;  ///< OpenMP threads per rank; 0 = all (shared by the ranks of a node).
  /// The ranks that share this box, each a slab of z-planes (at least 2 planes per rank), in
  /// rank order along z: every rank of the group calls run() with the same grid and options,
  /// and gets the same result (fields on the group's rank 0 only). Default: this process alone.
  mpi::Communicator ranks = mpi::Communicator::self();
  bool throw_on_failure = true;  ///< Throw draglab::Error on divergence / non-convergence.
  /// Checkpoint file, empty for none. A run that finds it resumes from it, bit for bit where
  /// the uninterrupted run would have been (the same grid and options, max_steps, threads and
  /// the checkpoint's own settings aside; another run's file is refused with
  /// Error(kInvalidArgument) naming what differs); it is rewritten after every
  /// checkpoint_interval seconds of stepping and when max_steps stops the run (raise max_steps
  /// and run again to go on), and removed when the run converges or fails otherwise. Rank r of
  /// a decomposed box keeps its share in "<checkpoint>.rank<r>of<n>".
  std::string checkpoint;
  double checkpoint_interval = 600.0;  ///< Seconds of stepping, in [0, 1e6]; 0: at every check.
  bool IsValid(std::string* error) const;
};

/// One convergence check.
struct HistoryPoint {
  std::int64_t step;
  double F;
  double re;
  double relative_change;
};

struct RunResult {
  bool converged = false;
  std::string diagnosis;  ///< Why the run stopped if not converged (limit, where, remedy).
  std::int64_t steps = 0;
  double wall_s = 0.0;
  double mflups = 0.0;  ///< Million fluid-node updates per second.
  // Drag (NaN unless converged). One sphere size: F = F_d/(3 pi mu d U), the mean over the
  // spheres. Several sizes (d_ref the Sauter mean): the mixture's F = f d_ref^2/(18 mu phi U),
  // f the drag force per unit volume (van der Hoef et al. 2005), so that K and beta follow from
  // F as for one size.
  double F = 0.0, K = 0.0, beta_d2_over_mu = 0.0;
  double F_standard_error = 0.0;  ///< Over the bodies (spread of per-sphere drag / sqrt(N)).
  /// Per body (sphere s of the packing): F_d/(3 pi mu d_ref U) along the flow (x) direction.
  std::vector<double> body_F;
  // State.
  /// Achieved Re = U d / nu; 0 for a Stokes-mode run with target 0 (the linear scheme solves
  /// the Re -> 0 limit; the lattice U d / nu is then only a scale, kept in the history).
  double re = 0.0;
  double phi = 0.0;  ///< Exact solids fraction of the packing (or lattice, without one).
  double phi_lattice = 0.0;
  double d = 0.0;  ///< Diameter used in the normalisation (lattice units).
  double tau = 0.0, nu = 0.0, body_force = 0.0, superficial_velocity = 0.0;
  double momentum_balance_rel = 0.0;  ///< |sum F_bodies - g rho V_fluid| / (g rho V_fluid).
  double mach_max = 0.0;
  double error_estimate = 0.0;  ///< Estimated relative discretisation + convergence error of F.
  std::vector<HistoryPoint> history;
  /// Unsteady flow: F and Re are time means, with their standard errors (blocking), over
  /// averaging_steps (averaging_time d/U) after startup_steps.
  bool unsteady = false;
  double F_time_error = 0.0;
  double re_standard_error = 0.0;
  std::int64_t averaging_steps = 0;
  double averaging_time = 0.0;
  std::int64_t startup_steps = 0;
  int averaging_restarts = 0;  ///< Force corrections after averaging began (restarting it).
  int force_adjustments = 0;   ///< Corrections of the force towards the target Re before that.
  // Additions (engine diagnostics).
  std::vector<std::string> warnings;  ///< Non-fatal findings (Mach above 0.1, boundary fallbacks).
  std::int64_t fluid_nodes = 0;       ///< Fluid nodes updated per step.
  int ranks = 1;                      ///< MPI ranks that shared the box.
  std::int64_t boundary_links = 0;    ///< Links of all bodies.
  /// Interpolated links that fell back to halfway bounce-back (second node solid).
  std::int64_t fallback_links = 0;
  /// Sphere pairs (images included) with a surface gap below one lattice spacing; -1 if unknown
  /// (a grid not made by arrays::voxelize).
  std::int64_t narrow_gap_pairs = 0;
  double smallest_gap_nodes = 0.0;  ///< Smallest gap of pairs closer than one link (lattice units).
  /// Fraction of fluid nodes with solid nodes on both sides along a lattice direction.
  double narrow_gap_fluid_fraction = 0.0;
  double tau_minus = 0.0;  ///< TRT odd relaxation time (= tau for BGK / regularized).
  /// Finite Re: the velocity plan (draglab/lbm/resolution.h). kappa = max|u|/U used to set U
  /// (measured by a Stokes run on the same lattice when tau is automatic, else estimated), the
  /// cell Reynolds number kappa Re / d and the operator's limit.
  double pore_speed_ratio = 0.0;
  bool pore_speed_ratio_measured = false;
  double mach_target = 0.0;
  double cell_reynolds = 0.0;
  double cell_reynolds_limit = 0.0;
  /// max|u|/U at the end of this run (what a Stokes run measures for the plan).
  double final_pore_speed_ratio = 0.0;
  double final_cell_reynolds = 0.0;  ///< max|u| / nu at the end of this run.
  /// The resolution rule's d at this phi and Re (draglab/lbm/resolution.h); below its accuracy
  /// bounds the estimate is widened and a warning says so.
  double resolution_needed = 0.0;
  /// The wall scheme used: "bb", "cli" or "bfl", and why (the automatic choice).
  std::string wall;
  std::string wall_reason;
  bool wall_corrected = false;  ///< rr: the reflected values carry TRT's wall correction.
  /// The operator that ran (never kAuto) and, when RunOptions::collision was kAuto, why.
  Collision collision = Collision::kTrt;
  std::string collision_reason;
  bool stokes_mode = false;               ///< Linear equilibrium used.
  double mass_change_rel = 0.0;           ///< (fluid mass at end - at start) / start.
  double convergence_residual = 0.0;      ///< Last relative change of F per characteristic time.
  double discretisation_error = 0.0;      ///< The discretisation part of error_estimate.
  std::int64_t characteristic_steps = 0;  ///< Steps per characteristic time (see run()).
  std::size_t memory_bytes = 0;           ///< Populations plus lattice tables.
  std::int64_t resumed_from_step = 0;     ///< The checkpoint's step it went on from (0: none).
  /// A resumed run: the wall seconds of its earlier parts, up to the checkpoint it went on from
  /// (wall_s is this part's; the run's cost is their sum).
  double earlier_parts_wall_s = 0.0;
  int checkpoints_written = 0;
  /// request_stop() ended the run at a check (its checkpoint, if it keeps one, holds the step).
  bool stopped_on_request = false;
  std::string BriefReport() const;
  std::string FullReport() const;
  /// Every scalar of the run as a JSON object (text) with the options that shaped it
  /// (collision, boundary, precision, magic for TRT, d_hydrodynamic): what `draglab lbm run
  /// --json` prints and what a campaign stores per unit. A value that is not finite (a run that
  /// did not converge) is null.
  std::string ToJson(const RunOptions& options) const;
};

/// Before any work: a RunOptions::checkpoint that exists must be a draglab checkpoint (else
/// Error(kInvalidArgument) naming it); whether it was written by the same run is checked when
/// the run starts.
void check_checkpoint_file(const std::string& path);

/// Asks every run of this process to end at its next check: a run that keeps a checkpoint saves
/// it there (the same run goes on from it), and each returns unconverged with
/// RunResult::stopped_on_request. Async-signal-safe: what a SIGTERM handler calls, so that a
/// batch system's stop (or the end of a working session) loses no stepping. The ranks of a
/// decomposed run stop together.
void request_stop();
bool stop_requested();
/// The request stays until cleared: a program that goes on running after a stop clears it.
void clear_stop_request();

/// Where a run stood when its checkpoint was last written, read from the file's header alone
/// (not its populations): what the owner of an hours-long run reads while it goes on (`draglab
/// campaign status`). "Recent" spans the last kRecentChecks checks of its history.
struct CheckpointProgress {
  static constexpr std::size_t kRecentChecks = 40;
  std::string code;  ///< Version of the binary that wrote it.
  std::int64_t step = 0;
  std::size_t checks = 0;                           ///< Checks in its history.
  double F = 0.0, re = 0.0, relative_change = 0.0;  ///< At the last check (nan before one).
  double recent_F_min = 0.0, recent_F_max = 0.0, recent_re_min = 0.0, recent_re_max = 0.0;
  int force_adjustments = 0;
  bool averaging = false;            ///< Unsteady flow: the time average has begun ...
  std::int64_t averaging_start = 0;  ///< ... at this step,
  std::size_t averaged_samples = 0;  ///< with this many samples so far,
  /// whose mean after the start-up (MSER) and blocking standard error stand here (nan with
  /// fewer than two samples).
  double F_average = 0.0, F_average_standard_error = 0.0;
  std::string BriefReport() const;
};

/// The progress a checkpoint (RunOptions::checkpoint) records. Throws Error(kInvalidArgument)
/// naming the file if it is not a draglab checkpoint or its header is damaged, kNotFound if it
/// does not exist.
CheckpointProgress read_checkpoint_progress(const std::string& path);

/// A-priori number of time steps a run with the automatic relaxation time (RunOptions::tau == 0)
/// needs to converge at tolerance ~1e-5, for planning (draglab campaign plan): the larger of
/// 2.5 characteristic times d^2/(nu (1 + Re)) and 0.9 times d^2/(nu phi F), the viscous time of
/// the Darcy relaxation of the mean flow (permeability ~ d^2/(18 phi F)), with F the BVK 2007
/// estimate, plus average_time d/U where the flow is expected to turn unsteady
/// (expects_unsteady_flow, resolution.h). Calibrated on the measured step counts of 60 units
/// (phi 0.1 - 0.4, Re 0 - 25, d = 10): every unit within a factor 2.6, median 1.2; checked on the
/// dense sweeps at Re 100 and 300, d 32 - 64 (docs/campaigns.md). phi in (0, 1), re >= 0, d > 0.
double predicted_steps(double phi, double re, double d, Collision collision = Collision::kAuto);

/// The resolutions a run accepts, lattice units per sphere diameter: below 4 a sphere is a few
/// voxels; above 512 the box of even one sphere outgrows any memory.
constexpr double kMinResolution = 4.0, kMaxResolution = 512.0;

/// This machine's physical memory in bytes (0 when unknown).
double physical_memory_bytes();
/// Memory of a run on `nodes` lattice nodes (19 populations, flags, links and fields), bytes:
/// a generous estimate, so that a refusal comes before the system kills the process.
double estimated_run_bytes(double nodes, Precision precision);

/// Checks, before any work, that `packing` can be run at `resolution`: the resolution within
/// [kMinResolution, kMaxResolution], the gaps between spheres resolved when
/// options.min_gap_nodes > 0, and the lattice's estimated memory within 80 % of this machine's.
/// Throws Error(kInvalidArgument) naming `field` (the option that sets the resolution, e.g.
/// "--d") with the limit and a remedy.
void check_run_size(const arrays::Packing& packing, double resolution, const RunOptions& options,
                    const std::string& field);

/// Runs to steady state on a voxelized geometry (flow along +x). `phi_exact` is the exact solids
/// fraction (Packing::phi()) or <= 0 to use the lattice one.
RunResult run(const arrays::VoxelGrid& grid, double phi_exact, const RunOptions& options,
              const ProgressCallback& progress = nullptr);

/// Convenience: voxelize `packing` at `resolution` (check_run_size first) and run.
RunResult run(const arrays::Packing& packing, double resolution, const RunOptions& options,
              const ProgressCallback& progress = nullptr);

/// Velocity, density and solid mask of the last run's final state, for HDF5/XDMF output.
struct Fields {
  std::array<std::int64_t, 3> dims{0, 0, 0};
  std::vector<float> velocity;      ///< 3 components per node (zero in solids), z-y-x node order.
  std::vector<float> density;       ///< rho (0 in solids).
  std::vector<std::uint8_t> solid;  ///< 1 = solid.
};
/// Same as run() but also returns the final fields.
RunResult run_with_fields(const arrays::VoxelGrid& grid, double phi_exact,
                          const RunOptions& options, Fields* fields,
                          const ProgressCallback& progress = nullptr);

/// Performance measurement (`draglab lbm bench`): medians of `repeat` interleaved runs (see
/// src/bench.cc); working sets >= 4x the last-level cache.
struct BenchOptions {
  int threads = 0;           ///< OpenMP threads (0: all).
  int repeat = 5;            ///< Interleaved repetitions (median), [1, 100].
  double packing_phi = 0.4;  ///< Solid fraction of the random packing, [0.1, 0.6].
  bool IsValid(std::string* error) const;
};
struct BenchResult {
  double mflups = 0.0;                   ///< All-fluid periodic box (box_edge^3), double, TRT.
  double mflups_fluid_packing = 0.0;     ///< Fluid-node updates/s on the random packing (d 16;
                                         ///< TRT, interpolated bounce-back: the default scheme).
  double mflups_fluid_packing_bb = 0.0;  ///< Same packing, halfway bounce-back (no link pass).
  /// Fluid-node updates/s on RRZE lbm-benchmark-kernels' `blocks-8` geometry (100^3), with the
  /// interpolated path (q = 1/2 links) and with halfway bounce-back.
  double mflups_blocks = 0.0;
  double mflups_blocks_bb = 0.0;
  /// The regularized operator (rr) beside TRT, on the same all-fluid box and packing (there with
  /// interpolated walls and TRT's wall correction, as --collision auto runs it at high Re).
  double mflups_rr = 0.0;
  double mflups_fluid_packing_rr = 0.0;
  double roofline_fraction_rr = 0.0;  ///< mflups_rr / (bandwidth / 304 bytes).
  std::int64_t blocks_fluid_nodes = 0;
  double bandwidth_gbs = 0.0;      ///< STREAM-like in-place update kernel.
  double roofline_fraction = 0.0;  ///< mflups / (bandwidth / 304 bytes).
  int threads = 0;
  /// Working sets are >= 4x this: the all-fluid box edge and the packing's sphere count.
  double last_level_cache_bytes = 0.0;
  std::int64_t box_edge = 0;
  int packing_spheres = 0;
  double packing_phi = 0.0;
};
BenchResult benchmark(const BenchOptions& options = BenchOptions());

}  // namespace lbm
}  // namespace draglab
