// driver.cc: run() -- relaxation times and body force from the target Re and the Mach budget,
// time stepping to a steady state, target-Re control, stability watch, drag normalisation and
// the error estimate.
//
// Choices (all in lattice units, dx = dt = 1, rho0 = 1):
//  - Velocity scale. Pore velocities reach about 2.5 U/(1 - phi) (lbm.md 4.5), so the superficial
//    velocity is budgeted as U = 0.1 (1 - phi)/2.5 (max |u| about 0.1, Mach about 0.17) for
//    finite Re, and 10x less for Re = 0: in Stokes mode the scale is immaterial (the scheme is
//    linear) and only has to stay far above round-off; with the full equilibrium at Re = 0 it
//    keeps the lattice Re (about 0.01 d / nu) and the u.u terms small.
//  - Relaxation time (RunOptions::tau == 0). Stokes (re == 0): tau = 1 (BGK, regularized) or
//    tau+ = 1.5 for TRT: with Lambda fixed the TRT steady state does not depend on tau+ at all,
//    and a larger viscosity reaches it in fewer steps. Finite Re: nu = U d / Re from the budget,
//    tau = 1/2 + 3 nu, capped at the Stokes value (then U = Re nu / d is below the budget).
//  - TRT: tau- = 1/2 + Lambda/(tau+ - 1/2).
//  - Body force: the force balance G (1 - phi) V = N 3 pi nu d U F with the BVK 2007 estimate of
//    F(phi, Re) gives the first G; then the achieved Re is measured and G adjusted (exactly, by
//    rescaling the state, in Stokes mode; by a secant step in log G - log Re, with the population
//    deviations rescaled to the target velocity, in full mode) until Re is within re_tolerance.
//  - Characteristic time T = d^2 / (nu (1 + Re)) steps: the time momentum needs to cross one
//    diameter by diffusion (d^2/nu) or, at higher Re, by advection (~ d/U), rounded to an even
//    number of steps divisible into 10 checks. Convergence: the relative change of F (and of
//    U) over the last T below RunOptions::tolerance, the momentum balance |sum of body forces -
//    G N_fluid| / (G N_fluid) (the relative rate of change of the fluid momentum, i.e. the
//    instantaneous unsteadiness) below the tolerance too (1e-4 in float, whose rounding leaves
//    a noise floor there), Re within re_tolerance of a positive target, and at least one T
//    after the last force change. The transients of a fixed bed decay in a fraction of T (the
//    slowest viscous mode of a periodic cell of edge L decays in L^2/(4 pi^2 nu), 0.17 d^2/nu for
//    the dilute simple-cubic case), so the change per T bounds the remaining error.
//  - Stability watch at every check (10 per T): non-finite populations, density <= 0, Mach number
//    max|u| sqrt(3) above mach_limit (a warning above 0.1), and tau - 1/2 < 1e-3 refused up front
//    for BGK and TRT. Each stops the run with the limit, the step, the node and a remedy.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "collision.h"
#include "draglab/drag_db/error.h"
#include "draglab/lbm/lbm.h"
#include "draglab/mpi/world.h"
#include "error_model.h"
#include "lattice.h"
#include "solver.h"

#if defined(_OPENMP)
#include <omp.h>
#endif
#include <unistd.h>

namespace draglab {
namespace lbm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMachWarning = 0.1;
constexpr double kMinTauGap = 1e-3;  ///< Refuse tau - 1/2 below this for BGK and TRT.
constexpr double kMinTauGapRegularized = 1e-5;
constexpr double kBudgetMaxSpeed = 0.1;   ///< Target max |u| at finite Re.
constexpr double kStokesMaxSpeed = 0.01;  ///< Target max |u| in Stokes mode.
constexpr double kPoreSpeedFactor = 2.5;  ///< max |u| ~ 2.5 U / (1 - phi).
constexpr int kChecksPerTime = 10;
constexpr double kAdjustBelowChange = 1e-2;  ///< Full mode: adjust G once F changes less per T.
constexpr int kMaxAdjustments = 30;
constexpr double kProgressInterval = 0.2;  ///< Seconds between progress reports.
constexpr std::int64_t kMaxCheckInterval = 5000;
constexpr double kFloatBalanceFloor = 1e-4;  ///< Momentum-balance convergence floor in float.
/// Bytes per node every rank of a decomposed box holds for the whole box (the voxel grid's
/// solid flags, with room for its links).
constexpr double kWholeGridBytesPerNode = 2.0;

std::string fmt(const char* format, double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

/// `dense`: a node index in the whole box.
std::string node_text(const SparseLattice& lattice, std::int64_t dense) {
  if (dense < 0) return "(unknown node)";
  const auto& n = lattice.dims();
  return "node (" + std::to_string(dense % n[0]) + ", " + std::to_string((dense / n[0]) % n[1]) +
         ", " + std::to_string(dense / (n[0] * n[1])) + ")";
}

/// Ranks of `group` on this node (they share its memory and cores).
int ranks_on_this_node(const mpi::Communicator& group) {
  return group.size() > 1 ? std::max(1, std::min(group.size(), mpi::local_size())) : 1;
}

/// 0 = all cores, shared among the ranks that run on this node.
int resolve_threads(int requested, const mpi::Communicator& group) {
#if defined(_OPENMP)
  if (requested > 0) return requested;
  // OMP_NUM_THREADS, when set, is already per process (per rank).
  if (std::getenv("OMP_NUM_THREADS") != nullptr) return std::max(1, omp_get_max_threads());
  return std::max(1, omp_get_max_threads() / ranks_on_this_node(group));
#else
  (void)requested, (void)group;
  return 1;
#endif
}

/// Runs `step` on every rank of `group`; when it throws on any rank, every rank throws the error
/// of the lowest failing one (the same code and text), so that no rank goes on into a
/// collective call the others never reach (a refusal for memory on one node, an allocation
/// that fails on one rank).
template <typename Step>
void on_all_ranks(const mpi::Communicator& group, Step&& step) {
  if (group.size() == 1) {
    step();
    return;
  }
  std::string failure;
  try {
    step();
  } catch (const Error& e) {
    failure = std::to_string(static_cast<int>(e.code())) + ":" + e.what();
  } catch (const std::exception& e) {
    failure = std::to_string(static_cast<int>(ErrorCode::kInternal)) + ":" + e.what();
  }
  for (const std::string& f : group.allgather(failure)) {
    if (f.empty()) continue;
    const std::size_t colon = f.find(':');
    throw Error(static_cast<ErrorCode>(std::stoi(f.substr(0, colon))), f.substr(colon + 1));
  }
}

double machine_memory_bytes() {
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
#else
  return 0.0;
#endif
}

/// Initial body force for a superficial velocity U (force balance with the BVK estimate).
double force_for_velocity(double u, double nu, double d, double phi, double re) {
  const double f = bvk2007_estimate(phi, re);
  return 18.0 * nu * u * f * phi / ((1.0 - phi) * d * d);
}

/// One run. `velocity_scale` (<= 1) scales the Mach budget of the velocity (see run_checked).
RunResult run_impl(const arrays::VoxelGrid& grid, double phi_exact, const RunOptions& options,
                   Fields* fields, const ProgressCallback& progress, double velocity_scale) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, "lbm run: " + error);
  if (grid.dims[0] <= 0 || grid.dims[1] <= 0 || grid.dims[2] <= 0 ||
      static_cast<std::int64_t>(grid.solid.size()) != grid.num_nodes() || !(grid.dx > 0.0)) {
    throw Error(ErrorCode::kInvalidArgument, "lbm run: malformed voxel grid");
  }
  if (grid.links.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                "lbm run: the voxel grid has no bodies, so there is no drag to measure");
  }

  RunResult result;
  result.phi_lattice = grid.phi_lattice();
  result.phi = phi_exact > 0.0 ? phi_exact : result.phi_lattice;
  result.d = options.use_hydrodynamic_diameter ? options.hydrodynamic_diameter : grid.resolution();
  const double phi = result.phi;
  const double d = result.d;
  if (!(phi > 0.0 && phi < 1.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                "lbm run: solids fraction must be in (0, 1), got " + fmt("%g", phi));
  }
  const bool stokes = options.stokes_mode == RunOptions::StokesMode::kOn ||
                      (options.stokes_mode == RunOptions::StokesMode::kAuto && options.re == 0.0);
  result.stokes_mode = stokes;
  const double target_re = options.re;

  // Relaxation times and the velocity scale.
  // Re = 0 asks for creeping flow: a small velocity also with the full equilibrium (so that its
  // u.u terms are negligible, not merely its Re undefined).
  const double budget_u = velocity_scale * (target_re == 0.0 ? kStokesMaxSpeed : kBudgetMaxSpeed) *
                          (1.0 - phi) / kPoreSpeedFactor;
  const double stokes_tau = options.collision == Collision::kTrt ? 1.5 : 1.0;
  double tau = options.tau;
  if (tau == 0.0) {
    tau =
        target_re == 0.0 ? stokes_tau : std::min(stokes_tau, 0.5 + 3.0 * budget_u * d / target_re);
  }
  const double nu = (tau - 0.5) / 3.0;
  double tau_minus = tau;
  if (options.collision == Collision::kTrt) tau_minus = 0.5 + options.magic / (tau - 0.5);
  result.tau = tau;
  result.tau_minus = tau_minus;
  result.nu = nu;
  const double target_u = target_re > 0.0 ? target_re * nu / d : budget_u;
  double force = force_for_velocity(target_u, nu, d, phi, target_re);
  result.body_force = force;

  auto fail = [&](const std::string& diagnosis) {
    result.converged = false;
    result.diagnosis = diagnosis;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    result.F = result.K = result.beta_d2_over_mu = result.F_standard_error = nan;
    result.error_estimate = nan;
    result.body_F.clear();
    // The last Re the run reached (not a measurement: it says how far the run got).
    if (!result.history.empty() && !(stokes && target_re == 0.0)) {
      result.re = result.history.back().re;
    }
    result.wall_s = seconds_since(start);
    if (options.throw_on_failure) throw Error(ErrorCode::kOutOfValidity, "lbm run: " + diagnosis);
    return result;
  };

  const double min_gap =
      options.collision == Collision::kRegularized ? kMinTauGapRegularized : kMinTauGap;
  if (tau - 0.5 < min_gap) {
    return fail("tau = " + fmt("%.6g", tau) + " is within " + fmt("%g", min_gap) +
                " of 1/2, the stability limit of " + to_string(options.collision) +
                (options.tau == 0.0 ? " (tau = 1/2 + 3 U d / Re from the Mach budget at Re = " +
                                          fmt("%g", target_re) + ", d = " + fmt("%g", d) + ")"
                                    : std::string()) +
                "; remedy: raise the resolution d (tau grows with d at fixed Re), lower Re, or "
                "use the regularized collision (rr)");
  }
  if (options.collision == Collision::kTrt && tau_minus - 0.5 < kMinTauGap) {
    return fail("TRT tau- = " + fmt("%.6g", tau_minus) + " (Lambda = " + fmt("%g", options.magic) +
                ", tau+ = " + fmt("%g", tau) +
                ") is within 1e-3 of 1/2; remedy: lower tau or raise Lambda");
  }

  // Lattice, links, solver. Several ranks share the box in slabs of z-planes (lattice.h); what
  // one rank cannot build (memory), none goes on with.
  const mpi::Communicator& group = options.ranks;
  const int threads = resolve_threads(options.threads, group);
  const std::size_t element = options.precision == Precision::kFloat ? 4 : 8;
  const bool interpolated = options.boundary == Boundary::kInterpolated;
  SolverSettings settings;
  settings.kernel = options.collision == Collision::kRegularized ? CollisionKernel::kRegularized
                                                                 : CollisionKernel::kTrt;
  settings.stokes = stokes;
  settings.omega_plus = 1.0 / tau;
  settings.omega_minus = 1.0 / tau_minus;
  settings.force_x = force;
  settings.interpolated = interpolated;
  std::unique_ptr<SparseLattice> lattice_storage;
  std::unique_ptr<LinkTable> links_storage;
  std::unique_ptr<SolverBase> solver;
  on_all_ranks(group, [&] {
    PlaneRange planes;
    if (group.size() > 1) {
      const std::vector<std::int64_t> split = split_planes(grid, group.size());
      planes.begin = split[static_cast<std::size_t>(group.rank())];
      planes.end = split[static_cast<std::size_t>(group.rank()) + 1];
      planes.decomposed = true;
    }
    lattice_storage = std::make_unique<SparseLattice>(grid, threads, element, planes);
    const SparseLattice& lattice = *lattice_storage;
    // Refuse what cannot fit rather than let the system kill the process half-way (the ranks
    // on one node share its memory).
    const double ranks_here = ranks_on_this_node(group);
    const double needed =
        ranks_here * (static_cast<double>(d3q19::kQ) * static_cast<double>(element) *
                          static_cast<double>(lattice.stride()) +
                      static_cast<double>(lattice.memory_bytes()) +
                      48.0 * static_cast<double>(grid.num_links()) / group.size());
    const double available = machine_memory_bytes();
    if (available > 0.0 && needed > 0.9 * available) {
      throw Error(ErrorCode::kInvalidArgument,
                  "lbm run: the lattice needs about " + fmt("%.3g", needed / 1073741824.0) +
                      " GiB (" + std::to_string(lattice.num_stored()) + " stored nodes" +
                      (group.size() > 1 ? " on rank " + std::to_string(group.rank()) + ", " +
                                              fmt("%g", ranks_here) + " ranks on its node"
                                        : std::string()) +
                      "), more than 90 % of this machine's " +
                      fmt("%.3g", available / 1073741824.0) +
                      " GiB; lower the resolution or use --precision float" +
                      (group.size() > 1 ? ", or spread the ranks over more nodes" : ""));
    }
    links_storage = std::make_unique<LinkTable>(lattice.build_links(grid, interpolated));
    solver = make_solver(options.precision, lattice, *links_storage, settings, threads, group);
  });
  const SparseLattice& lattice = *lattice_storage;
  const LinkTable& links = *links_storage;
  // Counts over the whole box (every rank's share).
  const std::int64_t fluid = group.sum(lattice.num_fluid());
  const double total_nodes = static_cast<double>(grid.num_nodes());
  const std::size_t bodies = links.num_bodies();
  result.fluid_nodes = fluid;
  result.ranks = group.size();
  result.boundary_links = group.sum(static_cast<std::int64_t>(links.size()));
  result.fallback_links = group.sum(links.fallback_links);
  result.memory_bytes = static_cast<std::size_t>(group.sum(
      static_cast<std::int64_t>(solver->bytes() + lattice.memory_bytes() + links.memory_bytes())));
  result.narrow_gap_pairs = grid.gaps.narrow_pairs;
  result.smallest_gap_nodes = grid.gaps.smallest_gap_nodes;
  result.narrow_gap_fluid_fraction = grid.gaps.narrow_fluid_fraction();
  if (grid.gaps.narrow_pairs > 0 || grid.gaps.narrow_fluid_nodes > 0) {
    result.warnings.push_back(
        std::to_string(grid.gaps.narrow_pairs) +
        " sphere pairs have gaps below one lattice spacing (smallest " +
        fmt("%.3g", grid.gaps.smallest_gap_nodes) + " lattice units) and " +
        fmt("%.3g", 100.0 * grid.gaps.narrow_fluid_fraction()) +
        " % of the fluid nodes lie in gaps one node wide: under-resolved gaps, run as the "
        "literature does (first-order bounce-back there); extrapolate in d for the error");
  }
  if (result.fallback_links > 0) {
    result.warnings.push_back(
        std::to_string(result.fallback_links) + " of " + std::to_string(result.boundary_links) +
        " interpolated links fell back to halfway bounce-back (the node behind them is solid: "
        "one-node gaps); the wall is first order there");
  }

  // Characteristic time and check interval (even: the AA pattern advances in pairs).
  const double char_time = d * d / (nu * (1.0 + target_re));
  std::int64_t interval =
      static_cast<std::int64_t>(std::ceil(char_time / kChecksPerTime / 2.0)) * 2;
  interval = std::clamp<std::int64_t>(interval, 2, kMaxCheckInterval);
  result.characteristic_steps = interval * kChecksPerTime;

  std::vector<double> body_force;
  std::vector<std::pair<double, double>> window;  // (F, U) at the checks since the last change
  double balance = std::numeric_limits<double>::infinity();
  // Float storage rounds every population to ~1e-7 relative each step, which leaves a noise
  // floor in the momentum balance (measured ~1e-6 .. 1e-5); double reaches round-off.
  const double balance_tolerance = options.precision == Precision::kFloat
                                       ? std::max(options.tolerance, kFloatBalanceFloor)
                                       : options.tolerance;
  std::int64_t step = 0;
  double stepping_s = 0.0;
  int adjustments = 0;
  double last_log_force = std::numeric_limits<double>::quiet_NaN(), last_log_re = last_log_force;
  double relative_change = std::numeric_limits<double>::infinity();
  bool mach_warned = false;
  auto last_progress = Clock::now();
  double F_mean = 0.0, U = 0.0, re_lattice = 0.0, mach = 0.0;
  MomentSummary m;

  while (true) {
    if (step >= options.max_steps) {
      result.steps = step;
      result.mflups = stepping_s > 0.0 ? static_cast<double>(fluid) * step / stepping_s / 1e6 : 0.0;
      if (fields != nullptr) solver->fill_fields(fields);
      return fail("not converged after max_steps = " + std::to_string(options.max_steps) +
                  " steps: relative change of F per characteristic time (" +
                  std::to_string(result.characteristic_steps) + " steps) is " +
                  fmt("%.3g", relative_change) + ", momentum balance " + fmt("%.3g", balance) +
                  " (tolerance " + fmt("%.3g", options.tolerance) + ")" +
                  (target_re > 0.0
                       ? ", Re = " + fmt("%.5g", re_lattice) + " for target " + fmt("%g", target_re)
                       : std::string()) +
                  "; remedy: raise max_steps (or loosen the tolerance); at high Re the flow "
                  "may be unsteady");
    }
    const std::int64_t pairs =
        std::max<std::int64_t>(1, std::min(interval, options.max_steps - step) / 2);
    const auto t_step = Clock::now();
    for (std::int64_t p = 0; p < pairs; ++p) {
      solver->advance_pair(p + 1 == pairs ? &body_force : nullptr);
    }
    stepping_s += seconds_since(t_step);
    step += 2 * pairs;
    result.steps = step;
    result.mflups = stepping_s > 0.0 ? static_cast<double>(fluid) * step / stepping_s / 1e6 : 0.0;

    m = solver->moments();
    if (m.nonfinite_node >= 0) {
      if (fields != nullptr) solver->fill_fields(fields);
      return fail("diverged: non-finite population at step " + std::to_string(step) + ", " +
                  node_text(lattice, m.nonfinite_node) +
                  "; remedy: raise the resolution, lower Re or use the regularized collision "
                  "(rr)");
    }
    if (m.min_rho <= 0.0) {
      if (fields != nullptr) solver->fill_fields(fields);
      return fail("diverged: density " + fmt("%.3g", m.min_rho) + " <= 0 at step " +
                  std::to_string(step) + ", " + node_text(lattice, m.min_rho_node) +
                  "; remedy: raise the resolution, lower Re or use the regularized collision (rr)");
    }
    mach = std::sqrt(3.0 * m.max_speed2);
    result.mach_max = std::max(result.mach_max, mach);
    if (mach > options.mach_limit) {
      if (fields != nullptr) solver->fill_fields(fields);
      return fail("Mach number " + fmt("%.3g", mach) + " above the limit " +
                  fmt("%g", options.mach_limit) + " at step " + std::to_string(step) + ", " +
                  node_text(lattice, m.max_speed_node) +
                  " (max |u| = " + fmt("%.3g", std::sqrt(m.max_speed2)) +
                  "); remedy: raise the resolution d or lower tau (the velocity is U = Re nu / d "
                  "at the target Re), or lower Re");
    }
    if (mach > kMachWarning && !mach_warned) {
      mach_warned = true;
      result.warnings.push_back(
          "Mach number " + fmt("%.3g", mach) + " above 0.1 at step " + std::to_string(step) + " (" +
          node_text(lattice, m.max_speed_node) +
          "): compressibility error of order Ma^2 = " + fmt("%.2g", mach * mach));
    }

    U = m.sum_u[0] / total_nodes;
    re_lattice = U * d / nu;
    double sum_fx = 0.0;
    for (std::size_t s = 0; s < bodies; ++s) sum_fx += body_force[3 * s];
    F_mean = sum_fx / static_cast<double>(bodies) / (3.0 * kPi * nu * d * U);
    if (!std::isfinite(F_mean)) {
      if (fields != nullptr) solver->fill_fields(fields);
      return fail("diverged: non-finite drag at step " + std::to_string(step) +
                  " (superficial velocity " + fmt("%.3g", U) +
                  "); remedy: raise the resolution or use the regularized collision (rr)");
    }
    window.push_back({F_mean, U});
    relative_change = std::numeric_limits<double>::infinity();
    if (window.size() > static_cast<std::size_t>(kChecksPerTime)) {
      const auto& before = window[window.size() - 1 - kChecksPerTime];
      // In Stokes mode the velocity scale is arbitrary (the state may be rescaled, see below):
      // only F counts there.
      relative_change = std::abs(F_mean - before.first) / std::abs(F_mean);
      if (!stokes) {
        relative_change = std::max(relative_change, std::abs(U - before.second) / std::abs(U));
      }
    }
    // Instantaneous unsteadiness: |sum of body forces - G N_fluid| / (G N_fluid) is the
    // relative rate of change of the fluid momentum.
    double sum_f[3] = {0, 0, 0};
    for (std::size_t s = 0; s < bodies; ++s) {
      for (int c = 0; c < 3; ++c) sum_f[c] += body_force[3 * s + c];
    }
    const double expected = force * static_cast<double>(fluid);
    balance = std::sqrt((sum_f[0] - expected) * (sum_f[0] - expected) + sum_f[1] * sum_f[1] +
                        sum_f[2] * sum_f[2]) /
              expected;
    // Round-off floor of the balance: the link sum carries about 1e-16 of the sum of its terms'
    // magnitudes (which cancel between the up- and downstream faces); a tolerance below that
    // could never be met.
    const double balance_floor =
        64.0 * std::numeric_limits<double>::epsilon() * solver->force_magnitude() / expected;
    result.history.push_back({step, F_mean, re_lattice, relative_change});

    // Stokes-mode acceleration. The slowest transient of a fixed bed is the spin-up of the mean
    // flow, on the Darcy time d^2 (1 - phi) / (18 nu phi F) (several characteristic times for
    // dilute arrays), during which the local flow already has its steady shape and only its
    // amplitude lags. The scheme is linear in Stokes mode, so multiplying the whole deviation
    // field (and the force, when a target Re sets it) by G N_fluid / sum F_x puts that amplitude
    // where the momentum balance holds; the remaining transients are the fast local ones. It
    // changes neither F (scale-free in Stokes mode) nor the steady state, and the convergence
    // test (F change per T and the momentum balance) is unaffected by it.
    // Applied at every check from half a characteristic time on (the local flow has its shape
    // by then). With the full equilibrium at Re = 0 the flow is linear to O(Re ~ 0.01), so it is
    // used there too; at finite Re the target-Re control below rescales instead.
    if ((stokes || target_re == 0.0) && window.size() >= kChecksPerTime / 2 &&
        balance > options.tolerance && sum_fx > 0.0) {
      const double factor = std::clamp(force * static_cast<double>(fluid) / sum_fx, 0.5, 2.0);
      if (factor != 1.0) solver->scale_deviations(factor);
    }

    // Target Re.
    const double re_ratio = target_re > 0.0 ? re_lattice / target_re : 1.0;
    if (target_re > 0.0 && std::abs(re_ratio - 1.0) > options.re_tolerance / 3.0 &&
        adjustments < kMaxAdjustments && re_lattice > 0.0 &&
        (stokes || relative_change < kAdjustBelowChange)) {
      const double velocity_factor = 1.0 / re_ratio;
      double new_force;
      if (stokes) {
        new_force = force * velocity_factor;  // exact: the Stokes-mode scheme is linear in G
      } else {
        // Secant in log G vs log Re; the first step uses the BVK estimate's slope.
        double slope;
        const double log_force = std::log(force), log_re = std::log(re_lattice);
        if (std::isfinite(last_log_force) && std::abs(log_force - last_log_force) > 1e-12) {
          slope = (log_re - last_log_re) / (log_force - last_log_force);
        } else {
          const double h = 1e-3;
          const double dlnf = (std::log(bvk2007_estimate(phi, re_lattice * (1 + h))) -
                               std::log(bvk2007_estimate(phi, re_lattice))) /
                              std::log1p(h);
          slope = 1.0 / (1.0 + dlnf);
        }
        slope = std::clamp(slope, 0.3, 1.0);
        last_log_force = log_force;
        last_log_re = log_re;
        new_force = force * std::exp(std::log(target_re / re_lattice) / slope);
        window.clear();
      }
      solver->scale_deviations(velocity_factor);
      force = new_force;
      solver->set_force(force);
      ++adjustments;
      continue;
    }
    const bool re_ok = target_re == 0.0 || std::abs(re_ratio - 1.0) <= options.re_tolerance;
    if (relative_change < options.tolerance &&
        balance < std::max(balance_tolerance, balance_floor) && re_ok) {
      break;
    }

    if (progress && seconds_since(last_progress) >= kProgressInterval) {
      last_progress = Clock::now();
      double fraction = static_cast<double>(step) / static_cast<double>(options.max_steps);
      if (std::isfinite(relative_change) && relative_change > 0.0) {
        fraction =
            std::max(fraction,
                     std::clamp(std::log(relative_change) / std::log(options.tolerance), 0.0, 1.0));
      }
      progress(std::min(fraction, 1.0),
               "step " + std::to_string(step) + ": F = " + fmt("%.6g", F_mean) + ", Re = " +
                   fmt("%.4g", re_lattice) + ", change/T = " + fmt("%.2g", relative_change) + ", " +
                   fmt("%.4g", result.mflups) + " MFLUPS");
    }
  }

  // Converged: normalise.
  result.converged = true;
  result.body_force = force;
  result.superficial_velocity = U;
  result.re = stokes && target_re == 0.0 ? 0.0 : re_lattice;
  result.body_F.resize(bodies);
  for (std::size_t s = 0; s < bodies; ++s) {
    result.body_F[s] = body_force[3 * s] / (3.0 * kPi * nu * d * U);
  }
  result.momentum_balance_rel = balance;
  result.mass_change_rel = m.sum_drho / static_cast<double>(fluid);
  result.F = F_mean;
  double var = 0.0;
  for (double f : result.body_F) var += (f - F_mean) * (f - F_mean);
  result.F_standard_error =
      bodies > 1 ? std::sqrt(var / static_cast<double>(bodies - 1) / static_cast<double>(bodies))
                 : 0.0;
  result.K = result.F / (1.0 - phi);
  result.beta_d2_over_mu = 18.0 * phi * (1.0 - phi) * result.F;
  result.convergence_residual = relative_change;
  ErrorModelInput em;
  em.boundary = options.boundary;
  em.collision = options.collision;
  em.tau = tau;
  em.magic = options.collision == Collision::kTrt   ? options.magic
             : options.collision == Collision::kBgk ? (tau - 0.5) * (tau - 0.5)
                                                    : 0.5 * (tau - 0.5);
  em.d = grid.resolution();
  em.phi = phi;
  em.re = result.re;
  em.precision = options.precision;
  result.discretisation_error = discretisation_error_estimate(em);
  result.error_estimate = result.discretisation_error + result.convergence_residual;
  if (fields != nullptr) solver->fill_fields(fields);
  result.wall_s = seconds_since(start);
  if (progress) progress(1.0, "converged after " + std::to_string(step) + " steps");
  return result;
}

/// run_impl with one remedy applied automatically: a finite-Re run whose relaxation time the
/// engine chose (tau == 0) and that stops at the Mach limit is repeated with half the velocity
/// (hence a smaller tau at the same Re), at most twice. The velocity budget assumes pore speeds
/// of about 2.5 U/(1 - phi); narrow throats of dense random packings exceed that (phi = 0.4,
/// d = 10: Mach 0.32 in the start-up). The retries are reported in the warnings, and their time
/// is included in wall_s; any other failure, or a Mach stop with a user-given tau, is returned
/// (or thrown) as it is.
RunResult run_checked(const arrays::VoxelGrid& grid, double phi_exact, const RunOptions& options,
                      Fields* fields, const ProgressCallback& progress) {
  RunOptions attempt_options = options;
  attempt_options.throw_on_failure = false;
  const bool may_retry = options.tau == 0.0 && options.re > 0.0;
  double scale = 1.0, earlier_wall_s = 0.0;
  std::vector<std::string> notes;
  RunResult previous;
  auto finish = [&](RunResult r) {
    r.wall_s += earlier_wall_s;
    r.warnings.insert(r.warnings.begin(), notes.begin(), notes.end());
    if (!r.converged && options.throw_on_failure) {
      throw Error(ErrorCode::kOutOfValidity, "lbm run: " + r.diagnosis);
    }
    return r;
  };
  for (int attempt = 0;; ++attempt) {
    RunResult r = run_impl(grid, phi_exact, attempt_options, fields, progress, scale);
    if (attempt > 0 && !r.converged && r.steps == 0) {
      // The slower run is refused up front (tau too close to 1/2): the Mach stop stands.
      notes.pop_back();
      earlier_wall_s -= previous.wall_s;
      return finish(previous);
    }
    const bool mach_stop = !r.converged && r.diagnosis.rfind("Mach number", 0) == 0;
    if (mach_stop && may_retry && attempt < 2) {
      notes.push_back("attempt " + std::to_string(attempt + 1) + " (tau = " + fmt("%.4g", r.tau) +
                      ") stopped at the Mach limit after " + std::to_string(r.steps) +
                      " steps; repeated with half the velocity");
      earlier_wall_s += r.wall_s;
      scale *= 0.5;
      previous = r;
      continue;
    }
    return finish(r);
  }
}

}  // namespace

double predicted_steps(double phi, double re, double d, Collision collision) {
  const double stokes_tau = collision == Collision::kTrt ? 1.5 : 1.0;
  const double budget_u =
      (re == 0.0 ? kStokesMaxSpeed : kBudgetMaxSpeed) * (1.0 - phi) / kPoreSpeedFactor;
  const double tau = re == 0.0 ? stokes_tau : std::min(stokes_tau, 0.5 + 3.0 * budget_u * d / re);
  const double nu = (tau - 0.5) / 3.0;
  const double characteristic = d * d / (nu * (1.0 + re));
  const double darcy = d * d / (nu * phi * bvk2007_estimate(phi, re));
  return std::max(2.5 * characteristic, 0.9 * darcy);
}

RunResult run(const arrays::VoxelGrid& grid, double phi_exact, const RunOptions& options,
              const ProgressCallback& progress) {
  return run_checked(grid, phi_exact, options, nullptr, progress);
}

RunResult run_with_fields(const arrays::VoxelGrid& grid, double phi_exact,
                          const RunOptions& options, Fields* fields,
                          const ProgressCallback& progress) {
  return run_checked(grid, phi_exact, options, fields, progress);
}

double physical_memory_bytes() { return machine_memory_bytes(); }

double estimated_run_bytes(double nodes, Precision precision) {
  // Populations (19 per node) plus flags, links and fields: a generous per-node budget.
  return nodes * (precision == Precision::kFloat ? 110.0 : 200.0);
}

void check_run_size(const arrays::Packing& packing, double resolution, const RunOptions& options,
                    const std::string& field) {
  if (!std::isfinite(resolution) || resolution < kMinResolution || resolution > kMaxResolution) {
    throw Error(ErrorCode::kInvalidArgument, field + " = " + fmt("%g", resolution) +
                                                 " is outside [" + fmt("%g", kMinResolution) +
                                                 ", " + fmt("%g", kMaxResolution) +
                                                 "] lattice units per diameter");
  }
  const double gap = options.min_gap_nodes > 0.0
                         ? arrays::min_gap_lattice_units(packing, resolution)
                         : std::numeric_limits<double>::infinity();  // opt-in check
  if (gap < options.min_gap_nodes) {
    const double needed = gap > 0.0 ? resolution * options.min_gap_nodes / gap : 0.0;
    throw Error(
        ErrorCode::kInvalidArgument,
        field + " = " + fmt("%g", resolution) +
            " is too low for the gaps: the smallest gap between spheres spans " + fmt("%.3g", gap) +
            " lattice units, below min_gap_nodes = " + fmt("%g", options.min_gap_nodes) +
            (gap > 0.0 && needed <= kMaxResolution
                 ? "; raise the resolution to at least " + fmt("%.4g", needed) + ", or"
                 : std::string(gap > 0.0
                                   ? " (the resolution it would need, " + fmt("%.4g", needed) +
                                         ", is beyond the limit " + fmt("%g", kMaxResolution) + ");"
                                   : "; the spheres touch or overlap;")) +
            " generate the packing with a minimum surface gap of at least " +
            fmt("%.3g", options.min_gap_nodes / resolution) +
            " diameters (draglab pack --min-gap " +
            fmt("%.3g", 1.5 * options.min_gap_nodes / resolution) +
            "), or set min_gap_nodes to 0 to run the under-resolved gaps (they are reported, "
            "and a sweep in d estimates their error)");
  }
  // Lattice nodes of the box at this resolution (the voxelizer's rounding).
  const double nx = std::max(1.0, std::round(resolution * packing.box_length[0]));
  const double dx = packing.box_length[0] / nx;
  const double nodes =
      nx * std::round(packing.box_length[1] / dx) * std::round(packing.box_length[2] / dx);
  // Decomposed across ranks, each holds its share of the lattice and the whole voxel grid; the
  // ranks on one node share its memory.
  const int ranks = options.ranks.size();
  const double per_rank = ranks > 1 ? estimated_run_bytes(nodes, options.precision) / ranks +
                                          kWholeGridBytesPerNode * nodes
                                    : estimated_run_bytes(nodes, options.precision);
  const double bytes = per_rank * ranks_on_this_node(options.ranks);
  const double memory = machine_memory_bytes();
  if (memory > 0.0 && bytes > 0.8 * memory) {
    throw Error(
        ErrorCode::kInvalidArgument,
        field + " = " + fmt("%g", resolution) + " needs about " +
            fmt("%.1f", bytes / 1073741824.0) + " GiB for " + fmt("%.3g", nodes) +
            " lattice nodes" +
            (ranks > 1 ? " on this node (" + std::to_string(ranks_on_this_node(options.ranks)) +
                             " of the " + std::to_string(ranks) + " ranks)"
                       : std::string()) +
            ", more than 80 % of this machine's " + fmt("%.1f", memory / 1073741824.0) +
            " GiB; lower " + field + " (or use --precision float" +
            (ranks > 1 ? ", or spread the ranks over more nodes)" : ")"));
  }
}

RunResult run(const arrays::Packing& packing, double resolution, const RunOptions& options,
              const ProgressCallback& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, "lbm run: " + error);
  on_all_ranks(options.ranks,
               [&] { check_run_size(packing, resolution, options, "lbm run: resolution"); });
  arrays::VoxelizationOptions vox;
  vox.resolution = resolution;
  const arrays::VoxelGrid grid = arrays::voxelize(packing, vox);
  return run_checked(grid, packing.phi(), options, nullptr, progress);
}

}  // namespace lbm
}  // namespace draglab
