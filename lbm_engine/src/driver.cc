// driver.cc: run() -- relaxation times and body force from the target Re and the Mach budget,
// time stepping to a steady state, target-Re control, stability watch, drag normalisation and
// the error estimate.
//
// Choices (all in lattice units, dx = dt = 1, rho0 = 1):
//  - Velocity scale. Finite Re: the velocity plan (draglab/lbm/resolution.h; run_planned). Re =
//    0: U = 0.01 (1 - phi)/2.5: in Stokes mode the scale is immaterial (the scheme is linear)
//    and only has to stay far above round-off; with the full equilibrium at Re = 0 it keeps the
//    lattice Re (about 0.01 d / nu) and the u.u terms small.
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
//    max|u| sqrt(3) above mach_limit (a warning above 1.5x the Mach target), and tau - 1/2 < 1e-3
//    refused up front for BGK and TRT. A blow-up (non-finite values, density <= 0, or a speed
//    that grows past the limit within one check) is diagnosed as an instability with the cell
//    Reynolds number at the last healthy check and the d that would hold; a Mach stop after
//    steady growth as such. No blind retry: halving the velocity at the same Re does not change
//    the cell Reynolds number, which decides stability.
//  - Unsteady flow: see lbm.h (Convergence) and averaging.h.
//  - Checkpoint (RunOptions::checkpoint): the loop's state (LoopState, checkpoint.h) and the
//    solver's, written at a check. Checks fall on multiples of the check interval whatever the
//    stops (a stop by max_steps saves the state before its off-schedule check), so a resumed run
//    makes the uninterrupted run's decisions and reaches its bits.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "averaging.h"
#include "checkpoint.h"
#include "collision.h"
#include "drag_db_version.h"
#include "draglab/core/files.h"
#include "draglab/core/machine.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/lbm/lbm.h"
#include "draglab/lbm/resolution.h"
#include "draglab/mpi/world.h"
#include "error_model.h"
#include "lattice.h"
#include "solver.h"

#if defined(_OPENMP)
#include <omp.h>
#endif
#include <glob.h>
#include <unistd.h>

namespace draglab {
namespace lbm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMachWarning = 0.1;
constexpr double kMinTauGap = 1e-3;  ///< Refuse tau - 1/2 below this for BGK and TRT.
constexpr double kMinTauGapRegularized = 1e-5;
constexpr double kStokesMaxSpeed = 0.01;  ///< Target max |u| in Stokes mode.
constexpr double kPoreSpeedFactor = 2.5;  ///< Stokes mode: max |u| ~ 2.5 U / (1 - phi).
/// A speed that grows by more than this factor within one check interval is a blow-up, not a
/// flow that is merely too fast.
constexpr double kBlowUpGrowth = 1.5;
/// Tolerance of the Stokes run that measures the pore-speed ratio.
constexpr double kPoreSpeedTolerance = 1e-3;
/// Relative fluctuation of F below which a flow is not called unsteady whatever the tolerance:
/// round-off and the last digits of a converging run, not vortex shedding.
constexpr double kUnsteadyMinAmplitude = 1e-4;
/// Corrections of the force an averaging run may make before it gives up.
constexpr int kMaxAveragingRestarts = 3;
/// Its steps, as a share of a Stokes run to the default tolerance (for predicted_steps).
constexpr double kPoreSpeedRunShare = 0.5;
constexpr int kChecksPerTime = 10;
/// Checks (five characteristic times) over which unsteadiness is judged.
constexpr std::size_t kUnsteadyWindowChecks = 5 * kChecksPerTime;
constexpr double kAdjustBelowChange = 1e-2;  ///< Full mode: adjust G once F changes less per T.
constexpr int kMaxAdjustments = 30;
constexpr double kProgressInterval = 0.2;  ///< Seconds between progress reports.
constexpr std::int64_t kMaxCheckInterval = 5000;
constexpr double kFloatBalanceFloor = 1e-4;  ///< Momentum-balance convergence floor in float.
/// Bytes per node every rank of a decomposed box holds for the whole box (the voxel grid's
/// solid flags, with room for its links).
constexpr double kWholeGridBytesPerNode = 2.0;

using core::format_fixed;

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

/// The wall scheme of a run, recorded in result->wall with the reason for an automatic choice.
/// CLI's negative weight amplifies the short-wave modes that a relaxation time near 1/2 leaves
/// undamped; BFL's weights are all non-negative.
WallScheme choose_wall(const RunOptions& options, double tau, bool stokes, RunResult* result) {
  if (options.boundary == Boundary::kHalfwayBounceBack) {
    result->wall = "bb";
    return WallScheme::kBounceBack;
  }
  WallInterpolation choice = options.interpolation;
  if (choice == WallInterpolation::kAuto) {
    if (stokes || tau >= kCentralWallMinTau) {
      choice = WallInterpolation::kCentral;
      result->wall_reason = stokes ? "Stokes flow: CLI is stable and the more accurate"
                                   : "tau = " + format_fixed("%.4g", tau) +
                                         " >= " + format_fixed("%g", kCentralWallMinTau) +
                                         ": CLI is stable there and the more accurate";
    } else {
      choice = WallInterpolation::kBouzidi;
      result->wall_reason = "tau = " + format_fixed("%.4g", tau) + " < " +
                            format_fixed("%g", kCentralWallMinTau) +
                            ": CLI's negative weight goes unstable near tau = 1/2, BFL's "
                            "non-negative weights do not";
    }
  }
  result->wall = to_string(choice);
  return choice == WallInterpolation::kCentral ? WallScheme::kCentralLinear
                                               : WallScheme::kBouzidiLinear;
}

/// The diagnosis of a run that blew up at `step` (`what` at `node`): where the flow was fastest
/// at the last healthy check, the cell Reynolds number there, the operator's limit and the d
/// that would hold.
std::string diverged_diagnosis(const SparseLattice& lattice, const RunOptions& options, double d,
                               double nu, double target_re, double result_phi, std::int64_t step,
                               const std::string& what, std::int64_t node, double last_max_speed,
                               std::int64_t last_max_node, std::int64_t last_check_step) {
  std::string text = "diverged (numerical instability of " +
                     std::string(to_string(options.collision)) + "): " + what + " at step " +
                     std::to_string(step) + ", " + node_text(lattice, node);
  const double limit = max_cell_reynolds(options.collision);
  const double stable = stable_cell_reynolds(options.collision);
  // The central interpolation's negative weight is a cause of its own near tau = 1/2.
  const double tau = 0.5 + 3.0 * nu;
  const std::string wall_remedy =
      options.boundary == Boundary::kInterpolated &&
              options.interpolation == WallInterpolation::kCentral && tau < kCentralWallMinTau
          ? "the BFL wall (--wall-interpolation auto or bfl: CLI is unstable at tau = " +
                format_fixed("%.4g", tau) + " < " + format_fixed("%g", kCentralWallMinTau) +
                "), or "
          : std::string();
  if (last_max_speed > 0.0 && nu > 0.0) {
    const double cell_re = last_max_speed / nu;
    text += "; at step " + std::to_string(last_check_step) + " the fastest node was " +
            node_text(lattice, last_max_node) + " (|u| = " + format_fixed("%.3g", last_max_speed) +
            "), a cell Reynolds number |u| dx / nu = " + format_fixed("%.3g", cell_re);
    if (std::isfinite(stable)) {
      text += " (" + std::string(to_string(options.collision)) + " has held up to " +
              format_fixed("%g", stable) + " in every measured packing" +
              (std::isfinite(limit) ? " and diverged in all beyond " + format_fixed("%g", limit)
                                    : std::string()) +
              ")";
      if (target_re > 0.0) {
        const double d_hold =
            std::ceil(estimated_pore_speed_ratio(result_phi) * target_re / stable);
        text += "; remedy: " + wall_remedy + "--d " +
                format_fixed("%g", std::max(d_hold, std::ceil(d) + 1.0)) +
                " or more (kappa Re / d = " + format_fixed("%g", stable) + "), or a lower Re";
        return text;
      }
    }
  }
  return text + "; remedy: " + wall_remedy + "raise the resolution d" +
         (target_re > 0.0 ? std::string(" or lower Re") : std::string()) +
         (options.tau != 0.0 ? std::string(", or leave tau to the engine") : std::string());
}

/// The accuracy rules of resolution.h at the run's phi and Re: d below the gap or boundary-layer
/// bound widens the discretisation estimate (widen_for_resolution of error_model.h), and the run
/// says so.
void widen_for_resolution(const RunOptions& options, double d, RunResult* result) {
  const ResolutionNeed need =
      resolution_needed(result->phi, result->re, options.collision, result->final_pore_speed_ratio);
  result->resolution_needed = need.d;
  const ResolutionWidening w =
      widen_for_resolution(result->discretisation_error, d, need, options.boundary);
  if (w.factor == 1.0) return;
  result->discretisation_error = w.error;
  std::string how = "widened x" + format_fixed("%.3g", w.factor);
  if (w.error == w.floor) {
    how = "set to " + format_fixed("%.3g", 100.0 * w.floor) +
          " % (the layer's missing nodes squared: below the rule the flow itself can change)";
  }
  result->warnings.push_back("under-resolved: d = " + format_fixed("%.4g", d) + " is below " +
                             format_fixed("%.3g", std::max(need.gaps, need.boundary_layer)) + " (" +
                             (w.boundary_layer ? "the boundary layer" : "the pores") +
                             " span too few nodes; " + need.Summary() +
                             "): the discretisation estimate is " + how + "; extrapolate in d");
}

/// This rank's checkpoint file (RunOptions::checkpoint).
std::string checkpoint_file(const RunOptions& options, const mpi::Communicator& group) {
  if (group.size() == 1) return options.checkpoint;
  return options.checkpoint + ".rank" + std::to_string(group.rank()) + "of" +
         std::to_string(group.size());
}

std::string exact(double x) { return format_fixed("%.17g", x); }

std::string hex(std::uint64_t x) {
  char text[32];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(x));
  return text;
}

/// What a checkpoint must share with the run that resumes from it: the geometry (the grid's
/// solid flags and this rank's lattice and links), the operator, the relaxation times, the
/// initial force and every option of the loop. Left out: max_steps (raised to go on), threads
/// (they change the order of the force sums, i.e. the last bits) and the checkpoint settings.
Fingerprint run_fingerprint(const arrays::VoxelGrid& grid, const SparseLattice& lattice,
                            const LinkTable& links, const RunOptions& options,
                            const SolverSettings& settings, const RunResult& result,
                            std::int64_t interval, const mpi::Communicator& group) {
  std::uint64_t weights = fnv1a(links.weight_a.data(), links.weight_a.size() * sizeof(double));
  weights = fnv1a(links.weight_b.data(), links.weight_b.size() * sizeof(double), weights);
  weights = fnv1a(links.self.data(), links.self.size() * sizeof(std::int64_t), weights);
  return {
      // What the user set (so that the message names the cause first) ...
      {"grid", std::to_string(grid.dims[0]) + "x" + std::to_string(grid.dims[1]) + "x" +
                   std::to_string(grid.dims[2]) + " solid " +
                   hex(fnv1a(grid.solid.data(), grid.solid.size()))},
      {"rank", std::to_string(group.rank()) + " of " + std::to_string(group.size())},
      {"phi", exact(result.phi)},
      {"d", exact(result.d)},
      {"re", exact(options.re)},
      {"collision", to_string(options.collision)},
      {"boundary", to_string(options.boundary)},
      {"precision", to_string(options.precision)},
      {"re_tolerance", exact(options.re_tolerance)},
      {"tolerance", exact(options.tolerance)},
      {"mach_limit", exact(options.mach_limit)},
      {"average_time", exact(options.average_time)},
      {"average_tolerance", exact(options.average_tolerance)},
      // ... then what the engine made of it.
      {"lattice", std::to_string(lattice.num_stored()) + " stored nodes, stride " +
                      std::to_string(lattice.stride())},
      {"links", std::to_string(links.size()) + " " + hex(weights)},
      {"wall", result.wall},
      {"stokes_mode", settings.stokes ? "on" : "off"},
      {"tau", exact(result.tau)},
      {"tau_minus", exact(result.tau_minus)},
      {"wall_correction", exact(settings.wall_correction)},
      {"initial_force", exact(result.body_force)},
      {"check_interval", std::to_string(interval)},
  };
}

/// A checkpoint of the same name written by another number of ranks ("" if none): the state of
/// a decomposed box belongs to its split.
std::string checkpoint_of_other_ranks(const std::string& base, int ranks) {
  if (ranks > 1 && core::file_exists(base)) return base;
  glob_t found{};
  std::string other;
  if (::glob((base + ".rank0of*").c_str(), 0, nullptr, &found) == 0) {
    const std::string mine = base + ".rank0of" + std::to_string(ranks);
    for (std::size_t k = 0; k < found.gl_pathc && other.empty(); ++k) {
      if (found.gl_pathv[k] != mine) other = found.gl_pathv[k];
    }
  }
  ::globfree(&found);
  return other;
}

/// Resumes from `path` when it exists (collective: every rank has its file or none does);
/// false when there is none. Throws Error(kInvalidArgument) for another run's file, a damaged
/// one, or ranks whose files disagree.
bool resume_from_checkpoint(const std::string& path, const Fingerprint& fingerprint,
                            const mpi::Communicator& group, SolverBase* solver, LoopState* loop,
                            RunResult* result) {
  const std::int64_t present = group.sum(std::int64_t{core::file_exists(path) ? 1 : 0});
  if (present == 0) return false;
  if (present != group.size()) {
    throw Error(ErrorCode::kInvalidArgument,
                "checkpoint '" + path + "': only " + std::to_string(present) + " of the " +
                    std::to_string(group.size()) +
                    " ranks have their checkpoint file; remedy: remove the files (the run then "
                    "starts afresh)");
  }
  std::string code;
  on_all_ranks(group,
               [&] { code = load_run_checkpoint(path, fingerprint, loop, solver->state()); });
  if (group.sum(loop->step) != loop->step * group.size()) {
    throw Error(ErrorCode::kInvalidArgument,
                "checkpoint '" + path +
                    "': the ranks' files hold different steps; remedy: remove the files (the run "
                    "then starts afresh)");
  }
  solver->set_force(loop->force);
  result->history = loop->history;
  result->mach_max = loop->mach_max;
  result->warnings.insert(result->warnings.end(), loop->warnings.begin(), loop->warnings.end());
  result->resumed_from_step = loop->step;
  if (code != kDragDbVersion) {
    result->warnings.push_back("resumed at step " + std::to_string(loop->step) +
                               " from a checkpoint written by draglab " + code + " (this is " +
                               kDragDbVersion + ")");
  }
  return true;
}

/// RunOptions::checkpoint of one run (every rank its own file): resumes the run from it, rewrites
/// it when due, and removes it at the end, unless max_steps stopped the run (it can go on from
/// there). Off when the options name no checkpoint.
class RunCheckpoint {
 public:
  /// What a checkpoint saves: the loop's state and the result's history, Mach and the loop's
  /// warnings (those from `warnings_from` on), and the solver's state.
  RunCheckpoint(const RunOptions& options, const mpi::Communicator& group, SolverBase* solver,
                LoopState* loop, RunResult* result, std::chrono::steady_clock::time_point started)
      : options_(options),
        group_(group),
        solver_(solver),
        loop_(loop),
        result_(result),
        warnings_from_(result->warnings.size()),
        started_(started) {
    if (options.checkpoint.empty()) return;
    path_ = checkpoint_file(options, group);
    const std::string other = checkpoint_of_other_ranks(options.checkpoint, group.size());
    if (!other.empty()) {
      throw Error(ErrorCode::kInvalidArgument,
                  "checkpoint '" + other + "' was written by another number of ranks than " +
                      std::to_string(group.size()) +
                      "; remedy: run on the ranks that wrote it, or remove its files (the run "
                      "then starts afresh)");
    }
  }

  bool enabled() const { return !path_.empty(); }
  const std::string& path() const { return path_; }

  /// Resumes from the file when there is one (the same run only: `fingerprint`).
  void Resume(const Fingerprint& fingerprint) {
    fingerprint_ = fingerprint;
    if (resume_from_checkpoint(path_, fingerprint_, group_, solver_, loop_, result_)) {
      owned_ = true;
      saved_step_ = loop_->step;
      earlier_parts_s_ = loop_->elapsed_s;
      result_->earlier_parts_wall_s = earlier_parts_s_;
    }
    last_ = Clock::now();
  }

  /// Saves when checkpoint_interval has passed since the last save (one clock for all ranks).
  void SaveIfDue() {
    if (!enabled() || loop_->step <= saved_step_) return;
    bool due =
        std::chrono::duration<double>(Clock::now() - last_).count() >= options_.checkpoint_interval;
    if (group_.size() > 1) due = group_.sum(std::int64_t{due ? 1 : 0}) > 0;
    if (due) Save();
  }

  /// max_steps stopped the run: save what is new and keep the file (the run can go on).
  void KeepForMoreSteps() {
    if (!enabled()) return;
    if (loop_->step > saved_step_) Save();
    keep_ = true;
  }

  void Save() {
    loop_->history = result_->history;
    loop_->mach_max = result_->mach_max;
    loop_->warnings.assign(result_->warnings.begin() + static_cast<std::ptrdiff_t>(warnings_from_),
                           result_->warnings.end());
    loop_->elapsed_s =
        earlier_parts_s_ + std::chrono::duration<double>(Clock::now() - started_).count();
    on_all_ranks(group_,
                 [&] { save_run_checkpoint(path_, fingerprint_, *loop_, solver_->state()); });
    owned_ = true;
    saved_step_ = loop_->step;
    ++result_->checkpoints_written;
    last_ = Clock::now();
  }

  /// The run ended (converged, or failed other than by max_steps): its file goes.
  void Finish() {
    if (owned_ && !keep_) std::remove(path_.c_str());
  }

 private:
  using Clock = std::chrono::steady_clock;
  const RunOptions& options_;
  const mpi::Communicator& group_;
  SolverBase* solver_;
  LoopState* loop_;
  RunResult* result_;
  std::size_t warnings_from_;
  std::string path_;
  Fingerprint fingerprint_;
  bool owned_ = false, keep_ = false;
  std::int64_t saved_step_ = 0;
  Clock::time_point last_ = Clock::now();
  Clock::time_point started_;     ///< This part's start.
  double earlier_parts_s_ = 0.0;  ///< The wall seconds of the parts before this one.
};

/// The force that brings Re to target_re: a secant step in log G against log Re through the last
/// adjustment (*last_log_force, *last_log_re, updated), or with the BVK estimate's slope at the
/// first one.
double adjusted_force(double force, double re, double target_re, double phi, double* last_log_force,
                      double* last_log_re) {
  double slope;
  const double log_force = std::log(force), log_re = std::log(re);
  if (std::isfinite(*last_log_force) && std::abs(log_force - *last_log_force) > 1e-12) {
    slope = (log_re - *last_log_re) / (log_force - *last_log_force);
  } else {
    const double h = 1e-3;
    const double dlnf =
        (std::log(bvk2007_estimate(phi, re * (1 + h))) - std::log(bvk2007_estimate(phi, re))) /
        std::log1p(h);
    slope = 1.0 / (1.0 + dlnf);
  }
  slope = std::clamp(slope, 0.3, 1.0);
  *last_log_force = log_force;
  *last_log_re = log_re;
  return force * std::exp(std::log(target_re / re) / slope);
}

/// Initial body force for a superficial velocity U (force balance with the BVK estimate).
double force_for_velocity(double u, double nu, double d, double phi, double re) {
  const double f = bvk2007_estimate(phi, re);
  return 18.0 * nu * u * f * phi / ((1.0 - phi) * d * d);
}

/// What run_impl needs of its inputs before any work: valid options, a well-formed grid with
/// bodies, and an operator already chosen (run_planned resolves auto).
void check_run_inputs(const arrays::VoxelGrid& grid, const RunOptions& options) {
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

  if (options.collision == Collision::kAuto) {
    throw Error(ErrorCode::kInternal, "lbm run: the collision must be chosen before the run");
  }
}

/// The relaxation times of a run: a finite-Re run's from its velocity plan (resolution.h,
/// recorded in the result with the plan's kappa, Mach target and cell Reynolds number), a Stokes
/// run's given or the operator's default.
struct Relaxation {
  double tau = 0.0, tau_minus = 0.0, nu = 0.0;
};
Relaxation plan_relaxation(const RunOptions& options, const VelocityPlan* plan,
                           RunResult* result_out) {
  RunResult& result = *result_out;
  if (options.re > 0.0 && plan == nullptr) {
    throw Error(ErrorCode::kInternal, "lbm run: a finite-Re run needs its velocity plan");
  }
  const double stokes_tau = options.collision == Collision::kTrt ? 1.5 : 1.0;
  double tau = options.tau;
  if (options.re > 0.0) {
    tau = plan->tau;
    result.pore_speed_ratio = plan->kappa;
    result.pore_speed_ratio_measured = plan->kappa_measured;
    result.mach_target = plan->mach_target;
    result.cell_reynolds = plan->cell_reynolds;
    result.cell_reynolds_limit = plan->cell_reynolds_limit;
  } else if (tau == 0.0) {
    tau = stokes_tau;
  }
  const double nu = (tau - 0.5) / 3.0;
  double tau_minus = tau;
  if (options.collision == Collision::kTrt) tau_minus = 0.5 + options.magic / (tau - 0.5);
  result.tau = tau;
  result.tau_minus = tau_minus;
  result.nu = nu;
  return {tau, tau_minus, nu};
}

/// The diagnosis of relaxation times too close to 1/2 for the operator to hold ("" if they are
/// not): a run that fails before its first step.
std::string relaxation_too_close_to_half(const RunOptions& options, const Relaxation& r, double d) {
  const double min_gap =
      options.collision == Collision::kRegularized ? kMinTauGapRegularized : kMinTauGap;
  if (r.tau - 0.5 < min_gap) {
    return "tau = " + format_fixed("%.6g", r.tau) + " is within " + format_fixed("%g", min_gap) +
           " of 1/2, the stability limit of " + to_string(options.collision) +
           (options.tau == 0.0
                ? " (tau = 1/2 + 3 U d / Re from the Mach budget at Re = " +
                      format_fixed("%g", options.re) + ", d = " + format_fixed("%g", d) + ")"
                : std::string()) +
           "; remedy: raise the resolution d (tau grows with d at fixed Re), lower Re, or "
           "use the regularized collision (rr)";
  }
  if (options.collision == Collision::kTrt && r.tau_minus - 0.5 < kMinTauGap) {
    return "TRT tau- = " + format_fixed("%.6g", r.tau_minus) +
           " (Lambda = " + format_fixed("%g", options.magic) +
           ", tau+ = " + format_fixed("%g", r.tau) +
           ") is within 1e-3 of 1/2; remedy: lower tau or raise Lambda";
  }
  return "";
}

/// The solver's settings for the run's operator, relaxation and force; with rr and interpolated
/// walls, the correction that gives the reflected values TRT's wall (recorded in the result).
SolverSettings solver_settings(const RunOptions& options, const Relaxation& r, bool stokes,
                               double force, RunResult* result) {
  const double tau = r.tau, tau_minus = r.tau_minus;
  const bool interpolated = options.boundary == Boundary::kInterpolated;
  SolverSettings settings;
  settings.kernel = options.collision == Collision::kRegularized ? CollisionKernel::kRegularized
                                                                 : CollisionKernel::kTrt;
  settings.stokes = stokes;
  settings.omega_plus = 1.0 / tau;
  settings.omega_minus = 1.0 / tau_minus;
  settings.force_x = force;
  settings.interpolated = interpolated;
  // rr's odd moments relax with omega = 1: the reflected values are corrected to TRT's wall at
  // Lambda = magic where rr's effective Lambda, (tau - 1/2)/2, is the smaller (lbm.h, Numerics).
  const double wall_correction = 2.0 * options.magic / (tau - 0.5) - 1.0;
  if (options.collision == Collision::kRegularized && interpolated && options.rr_wall_correction &&
      wall_correction > 0.0) {
    settings.wall_correction = wall_correction;
    result->wall_corrected = true;
    result->wall_reason += std::string(result->wall_reason.empty() ? "" : "; ") +
                           "rr: reflected values corrected to TRT's wall at Lambda = " +
                           format_fixed("%g", options.magic);
  }
  return settings;
}

/// The lattice, its boundary links and the solver, built on every rank of the run's box (slabs
/// of z-planes, lattice.h); what one rank cannot build (memory), none goes on with.
struct Engine {
  std::unique_ptr<SparseLattice> lattice;
  std::unique_ptr<LinkTable> links;
  std::unique_ptr<SolverBase> solver;
};
Engine build_engine(const arrays::VoxelGrid& grid, const RunOptions& options, WallScheme wall,
                    const SolverSettings& settings, int threads) {
  const mpi::Communicator& group = options.ranks;
  const std::size_t element = options.precision == Precision::kFloat ? 4 : 8;
  Engine e;
  std::unique_ptr<SparseLattice>& lattice_storage = e.lattice;
  std::unique_ptr<LinkTable>& links_storage = e.links;
  std::unique_ptr<SolverBase>& solver = e.solver;
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
        ranks_here *
        (static_cast<double>(d3q19::kQ) * static_cast<double>(element) *
             static_cast<double>(lattice.stride()) +
         static_cast<double>(lattice.memory_bytes()) +
         80.0 * static_cast<double>(grid.num_links()) / group.size());  // link table + state
    const double available = core::physical_memory_bytes();
    if (available > 0.0 && needed > 0.9 * available) {
      throw Error(ErrorCode::kInvalidArgument,
                  "lbm run: the lattice needs about " +
                      format_fixed("%.3g", needed / 1073741824.0) + " GiB (" +
                      std::to_string(lattice.num_stored()) + " stored nodes" +
                      (group.size() > 1 ? " on rank " + std::to_string(group.rank()) + ", " +
                                              format_fixed("%g", ranks_here) + " ranks on its node"
                                        : std::string()) +
                      "), more than 90 % of this machine's " +
                      format_fixed("%.3g", available / 1073741824.0) +
                      " GiB; lower the resolution or use --precision float" +
                      (group.size() > 1 ? ", or spread the ranks over more nodes" : ""));
    }
    links_storage = std::make_unique<LinkTable>(lattice.build_links(grid, wall));
    solver = make_solver(options.precision, lattice, *links_storage, settings, threads, group);
  });
  return e;
}

/// What the result says of the lattice (node and link counts over every rank, memory, the
/// sub-node gaps) and the warnings that go with it.
void record_lattice(const arrays::VoxelGrid& grid, const Engine& engine,
                    const mpi::Communicator& group, RunResult* result) {
  RunResult& r = *result;
  const SparseLattice& lattice = *engine.lattice;
  const LinkTable& links = *engine.links;
  const SolverBase* solver = engine.solver.get();
  r.fluid_nodes = group.sum(lattice.num_fluid());
  r.ranks = group.size();
  r.boundary_links = group.sum(static_cast<std::int64_t>(links.size()));
  r.fallback_links = group.sum(links.fallback_links);
  r.memory_bytes = static_cast<std::size_t>(group.sum(
      static_cast<std::int64_t>(solver->bytes() + lattice.memory_bytes() + links.memory_bytes())));
  r.narrow_gap_pairs = grid.gaps.narrow_pairs;
  r.smallest_gap_nodes = grid.gaps.smallest_gap_nodes;
  r.narrow_gap_fluid_fraction = grid.gaps.narrow_fluid_fraction();
  if (grid.gaps.narrow_pairs > 0 || grid.gaps.narrow_fluid_nodes > 0) {
    r.warnings.push_back(
        std::to_string(grid.gaps.narrow_pairs) +
        " sphere pairs have gaps below one lattice spacing (smallest " +
        format_fixed("%.3g", grid.gaps.smallest_gap_nodes) + " lattice units) and " +
        format_fixed("%.3g", 100.0 * grid.gaps.narrow_fluid_fraction()) +
        " % of the fluid nodes lie in gaps one node wide: under-resolved gaps, run as the "
        "literature does (first-order bounce-back there); extrapolate in d for the error");
  }
  if (r.fallback_links > 0) {
    r.warnings.push_back(
        std::to_string(r.fallback_links) + " of " + std::to_string(r.boundary_links) +
        " interpolated links fell back to halfway bounce-back (the node behind them is solid: "
        "one-node gaps); the wall is first order there");
  }
}

/// The factor that turns the mean per-sphere drag F_d/(3 pi mu d_ref U) into the mixture drag of
/// a polydisperse packing in the convention of van der Hoef et al. (2005), F = f d_ref^2 /
/// (18 mu phi U) with f the drag force per unit volume (so that beta = 18 mu phi (1 - phi) F /
/// d_ref^2 holds as for one size; d_ref is the Sauter mean diameter): N / sum (d_s/d_ref)^3. 1
/// for a monodisperse packing (or a grid without diameters), whose F is the drag per sphere.
double mixture_factor(const arrays::VoxelGrid& grid) {
  const std::vector<double>& y = grid.diameters;
  if (y.size() != grid.links.size() || y.empty()) return 1.0;
  if (std::all_of(y.begin(), y.end(), [&y](double x) { return x == y.front(); })) return 1.0;
  double cubes = 0.0;
  for (double x : y) cubes += x * x * x;
  return static_cast<double>(y.size()) / cubes;
}

/// The scales of a run that its result is normalised with.
struct RunScales {
  double phi = 0.0, d = 0.0, nu = 0.0, tau = 0.0;
  bool stokes = false;
  std::int64_t interval = 0;  ///< Steps between checks.
  std::int64_t fluid = 0;     ///< Fluid nodes over every rank.
  std::size_t bodies = 0;
  double mixture = 1.0;  ///< mixture_factor of the grid.
};

/// The result of a converged run: F, K, beta, the achieved Re and the per-body drag (time means
/// from the end of the start-up on for unsteady flow), the spread over bodies, the convergence
/// residual and the error estimate.
void normalise_converged(const LoopState& loop, const TimeAverage& average_F,
                         const TimeAverage& average_re, const MomentSummary& m,
                         const std::vector<double>& body_force, const RunScales& sc,
                         const RunOptions& options, const arrays::VoxelGrid& grid,
                         RunResult* result_out) {
  RunResult& result = *result_out;
  double relative_change = loop.relative_change;
  result.converged = true;
  result.body_force = loop.force;
  result.superficial_velocity = loop.U;
  result.re = sc.stokes && options.re == 0.0 ? 0.0 : loop.re_lattice;
  result.body_F.resize(sc.bodies);
  for (std::size_t s = 0; s < sc.bodies; ++s) {
    result.body_F[s] = body_force[3 * s] / (3.0 * kPi * sc.nu * sc.d * loop.U);
  }
  result.momentum_balance_rel = loop.balance;
  result.final_pore_speed_ratio = loop.U > 0.0 ? std::sqrt(m.max_speed2) / loop.U : 0.0;
  result.final_cell_reynolds = std::sqrt(m.max_speed2) / sc.nu;
  result.mass_change_rel = m.sum_drho / static_cast<double>(sc.fluid);
  result.F = loop.F_mean;
  if (loop.averaging) {
    // The time means from the end of the start-up on (the same samples for every quantity).
    result.unsteady = true;
    result.F = average_F.mean;
    result.F_time_error = average_F.standard_error;
    result.re = average_re.mean;
    result.re_standard_error = average_re.standard_error;
    result.averaging_steps = static_cast<std::int64_t>(average_F.used) * sc.interval;
    result.averaging_time =
        static_cast<double>(result.averaging_steps) * (options.re * sc.nu / sc.d) / sc.d;
    result.startup_steps =
        loop.averaging_start + static_cast<std::int64_t>(average_F.truncated) * sc.interval;
    result.averaging_restarts = loop.averaging_restarts;
    for (std::size_t s = 0; s < sc.bodies; ++s) {
      result.body_F[s] = time_average(loop.series_body[s], average_F.truncated).mean;
    }
    relative_change = average_F.standard_error / std::abs(average_F.mean);
  }
  // The spread of the per-sphere drag (normalised with d_ref) around its mean, in the units of
  // F (the mixture's, sc.mixture = 1 for one size).
  const double body_mean = result.F / sc.mixture;
  double var = 0.0;
  for (double f : result.body_F) var += (f - body_mean) * (f - body_mean);
  result.F_standard_error = sc.bodies > 1
                                ? sc.mixture * std::sqrt(var / static_cast<double>(sc.bodies - 1) /
                                                         static_cast<double>(sc.bodies))
                                : 0.0;
  result.K = result.F / (1.0 - sc.phi);
  result.beta_d2_over_mu = 18.0 * sc.phi * (1.0 - sc.phi) * result.F;
  result.convergence_residual = relative_change;
  ErrorModelInput em;
  em.boundary = options.boundary;
  em.collision = options.collision;
  em.tau = sc.tau;
  em.wall_corrected = result.wall_corrected;
  em.magic = options.collision == Collision::kTrt || result.wall_corrected ? options.magic
             : options.collision == Collision::kBgk ? (sc.tau - 0.5) * (sc.tau - 0.5)
                                                    : 0.5 * (sc.tau - 0.5);
  // The smallest spheres carry the largest discretisation error: their diameter in lattice units
  // (d itself for one size of diameter d_ref).
  em.d = grid.resolution() *
         (grid.diameters.empty() ? 1.0
                                 : *std::min_element(grid.diameters.begin(), grid.diameters.end()));
  em.phi = sc.phi;
  em.re = result.re;
  em.precision = options.precision;
  result.discretisation_error = discretisation_error_estimate(em);
  widen_for_resolution(options, grid.resolution(), &result);
  result.error_estimate = result.discretisation_error + result.convergence_residual;
}

/// The stages of one check of run_impl's loop (after the pairs of steps up to it): the flow's
/// health, the drag and the balance, the Stokes-mode rescaling, unsteady flow and its average,
/// the target-Re control, convergence, progress. What a check measures lives in LoopState
/// (kept by checkpoints); the rest is the run's constants.
class RunChecks {
 public:
  /// The run's constants.
  struct Scales {
    double d = 0.0, nu = 0.0, phi = 0.0, target_re = 0.0;
    bool stokes = false;
    std::int64_t fluid = 0;
    double total_nodes = 0.0;
    std::size_t bodies = 0;
    double mixture = 1.0;
    std::int64_t interval = 0;
    double balance_tolerance = 0.0;
  };
  /// What a stage asks of the loop: go on to the next stage, step on to the next check, stop
  /// converged, or stop with `failure`.
  enum class Next { kGoOn, kNextCheck, kConverged, kFail };

  RunChecks(const RunOptions& options, const SparseLattice& lattice, SolverBase* solver,
            const Scales& scales, LoopState* loop, RunResult* result,
            const std::vector<double>* body_force, const ProgressCallback& progress)
      : options_(options),
        lattice_(lattice),
        solver_(solver),
        sc_(scales),
        loop_(*loop),
        result_(*result),
        body_force_(*body_force),
        progress_(progress),
        last_progress_(Clock::now()) {
    loop_.balance = std::numeric_limits<double>::infinity();
    loop_.last_log_force = loop_.last_log_re = std::numeric_limits<double>::quiet_NaN();
    loop_.relative_change = std::numeric_limits<double>::infinity();
  }

  const MomentSummary& moments() const { return m_; }
  const TimeAverage& average_F() const { return average_F_; }
  const TimeAverage& average_re() const { return average_re_; }
  const std::string& failure() const { return failure_; }

  /// The remedy of a Mach stop: beyond the cell Reynolds number where the operator has held, a
  /// local speed that grows steadily is the start of an instability (the d that holds); within
  /// it, the velocity plan's Mach target.
  std::string MachStopRemedy() const {
    if (sc_.target_re <= 0.0 || options_.tau != 0.0) {
      return "); remedy: lower tau (the velocity is U = Re nu / d at the target Re), or leave tau "
             "to the engine";
    }
    const double stable = stable_cell_reynolds(options_.collision);
    const double kappa = estimated_pore_speed_ratio(sc_.phi);
    if (std::isfinite(stable) && kappa * sc_.target_re / sc_.d > stable) {
      return "); kappa Re / d = " + format_fixed("%.3g", kappa * sc_.target_re / sc_.d) +
             " is beyond " + format_fixed("%g", stable) + ", where " +
             to_string(options_.collision) + " has held in every measured packing: remedy: --d " +
             format_fixed("%g", std::ceil(kappa * sc_.target_re / stable)) +
             " or more, or a lower Mach target (--mach)";
    }
    return "); remedy: lower the Mach target (--mach)";
  }

  /// The flow's health from the moment sweep: finite populations, positive density, the Mach
  /// limit (a blow-up is told from a steady rise), the Mach warning.
  Next Health() {
    m_ = solver_->moments();
    if (m_.nonfinite_node >= 0)
      return Fail(Instability("a non-finite population", m_.nonfinite_node));
    if (m_.min_rho <= 0.0)
      return Fail(
          Instability("density " + format_fixed("%.3g", m_.min_rho) + " <= 0", m_.min_rho_node));
    double& mach = loop_.mach;
    mach = std::sqrt(3.0 * m_.max_speed2);
    result_.mach_max = std::max(result_.mach_max, mach);
    const std::int64_t step = loop_.step;
    if (mach > options_.mach_limit) {
      if (loop_.last_max_speed > 0.0 &&
          std::sqrt(m_.max_speed2) > kBlowUpGrowth * loop_.last_max_speed) {
        return Fail(Instability("max |u| grew from " + format_fixed("%.3g", loop_.last_max_speed) +
                                    " to " + format_fixed("%.3g", std::sqrt(m_.max_speed2)) +
                                    " (Mach " + format_fixed("%.3g", mach) + ") within " +
                                    std::to_string(sc_.interval) + " steps",
                                m_.max_speed_node));
      }
      return Fail("Mach number " + format_fixed("%.3g", mach) + " above the limit " +
                  format_fixed("%g", options_.mach_limit) + " at step " + std::to_string(step) +
                  ", " + node_text(lattice_, m_.max_speed_node) +
                  " (max |u| = " + format_fixed("%.3g", std::sqrt(m_.max_speed2)) +
                  ", grown steadily" + MachStopRemedy());
    }
    const double mach_warning = sc_.target_re > 0.0 && options_.tau == 0.0
                                    ? std::max(kMachWarning, 1.5 * options_.mach_target)
                                    : kMachWarning;
    if (mach > mach_warning && !loop_.mach_warned) {
      loop_.mach_warned = true;
      result_.warnings.push_back(
          "Mach number " + format_fixed("%.3g", mach) + " above " +
          format_fixed("%.3g", mach_warning) + " at step " + std::to_string(step) + " (" +
          node_text(lattice_, m_.max_speed_node) +
          "): compressibility error of order Ma^2 = " + format_fixed("%.2g", mach * mach));
    }
    loop_.last_max_speed = std::sqrt(m_.max_speed2);
    loop_.last_max_node = m_.max_speed_node;
    loop_.last_check_step = step;
    return Next::kGoOn;
  }

  /// The superficial velocity, Re, the mean drag, its change per characteristic time and the
  /// momentum balance (with its round-off floor); the history point.
  Next Drag() {
    loop_.U = m_.sum_u[0] / sc_.total_nodes;
    loop_.re_lattice = loop_.U * sc_.d / sc_.nu;
    sum_fx_ = 0.0;
    for (std::size_t s = 0; s < sc_.bodies; ++s) sum_fx_ += body_force_[3 * s];
    loop_.F_mean = sum_fx_ / static_cast<double>(sc_.bodies) /
                   (3.0 * kPi * sc_.nu * sc_.d * loop_.U) * sc_.mixture;
    if (!std::isfinite(loop_.F_mean)) {
      return Fail(Instability(
          "a non-finite drag (superficial velocity " + format_fixed("%.3g", loop_.U) + ")",
          m_.max_speed_node));
    }
    auto& window = loop_.window;
    window.push_back({loop_.F_mean, loop_.U});
    double& relative_change = loop_.relative_change;
    relative_change = std::numeric_limits<double>::infinity();
    if (window.size() > static_cast<std::size_t>(kChecksPerTime)) {
      const auto& before = window[window.size() - 1 - kChecksPerTime];
      // In Stokes mode the velocity scale is arbitrary (the state may be rescaled, see
      // Rescale): only F counts there.
      relative_change = std::abs(loop_.F_mean - before.first) / std::abs(loop_.F_mean);
      if (!sc_.stokes) {
        relative_change =
            std::max(relative_change, std::abs(loop_.U - before.second) / std::abs(loop_.U));
      }
    }
    // Instantaneous unsteadiness: |sum of body forces - G N_fluid| / (G N_fluid) is the
    // relative rate of change of the fluid momentum.
    double sum_f[3] = {0, 0, 0};
    for (std::size_t s = 0; s < sc_.bodies; ++s) {
      for (int c = 0; c < 3; ++c) sum_f[c] += body_force_[3 * s + c];
    }
    const double expected = loop_.force * static_cast<double>(sc_.fluid);
    loop_.balance = std::sqrt((sum_f[0] - expected) * (sum_f[0] - expected) + sum_f[1] * sum_f[1] +
                              sum_f[2] * sum_f[2]) /
                    expected;
    // Round-off floor of the balance: the link sum carries about 1e-16 of the sum of its terms'
    // magnitudes (which cancel between the up- and downstream faces); a tolerance below that
    // could never be met.
    balance_floor_ =
        64.0 * std::numeric_limits<double>::epsilon() * solver_->force_magnitude() / expected;
    result_.history.push_back({loop_.step, loop_.F_mean, loop_.re_lattice, loop_.relative_change});
    return Next::kGoOn;
  }

  /// Stokes-mode acceleration. The slowest transient of a fixed bed is the spin-up of the mean
  /// flow, on the Darcy time d^2 (1 - phi) / (18 nu phi F) (several characteristic times for
  /// dilute arrays), during which the local flow already has its steady shape and only its
  /// amplitude lags. The scheme is linear in Stokes mode, so multiplying the whole deviation
  /// field (and the force, when a target Re sets it) by G N_fluid / sum F_x puts that amplitude
  /// where the momentum balance holds; the remaining transients are the fast local ones. It
  /// changes neither F (scale-free in Stokes mode) nor the steady state, and the convergence
  /// test (F change per T and the momentum balance) is unaffected by it.
  /// Applied at every check from half a characteristic time on (the local flow has its shape
  /// by then). With the full equilibrium at Re = 0 the flow is linear to O(Re ~ 0.01), so it is
  /// used there too; at finite Re the target-Re control rescales instead.
  void Rescale() {
    if ((sc_.stokes || sc_.target_re == 0.0) && loop_.window.size() >= kChecksPerTime / 2 &&
        loop_.balance > options_.tolerance && sum_fx_ > 0.0) {
      const double factor =
          std::clamp(loop_.force * static_cast<double>(sc_.fluid) / sum_fx_, 0.5, 2.0);
      if (factor != 1.0) solver_->scale_deviations(factor);
    }
  }

  /// Unsteady flow. A flow that fluctuates around a stationary mean at the target Re never
  /// meets the steady test: detect it, bring Re to its band on the filtered (window mean)
  /// velocity, then hold the force and average F (averaging.h).
  Next DetectUnsteady() {
    auto& window = loop_.window;
    if (loop_.averaging || !(sc_.target_re > 0.0) || sc_.stokes ||
        !(loop_.relative_change > options_.tolerance) || window.size() < kUnsteadyWindowChecks) {
      return Next::kGoOn;
    }
    std::vector<double> window_F(window.size());
    double mean_U = 0.0;
    for (std::size_t k = 0; k < window.size(); ++k) window_F[k] = window[k].first;
    for (std::size_t k = window.size() - kUnsteadyWindowChecks; k < window.size(); ++k) {
      mean_U += window[k].second / static_cast<double>(kUnsteadyWindowChecks);
    }
    if (!stationary_fluctuating(window_F, kUnsteadyWindowChecks,
                                std::max(options_.tolerance, kUnsteadyMinAmplitude))) {
      return Next::kGoOn;
    }
    const double mean_re = mean_U * sc_.d / sc_.nu;
    if (std::abs(mean_re / sc_.target_re - 1.0) > options_.re_tolerance / 3.0 &&
        loop_.adjustments < kMaxAdjustments) {
      SetForce(adjusted_force(loop_.force, mean_re, sc_.target_re, sc_.phi, &loop_.last_log_force,
                              &loop_.last_log_re));
      window.clear();
      ++loop_.adjustments;
      return Next::kNextCheck;
    }
    const std::int64_t needed = static_cast<std::int64_t>(
        std::ceil(options_.average_time * sc_.d / (sc_.target_re * sc_.nu / sc_.d)));
    const std::int64_t step = loop_.step;
    if (step + needed > options_.max_steps) {
      return Fail("unsteady flow at Re = " + format_fixed("%.4g", mean_re) + " (F fluctuates by " +
                  format_fixed("%.2g", loop_.relative_change) +
                  " per characteristic time around a "
                  "stationary mean): averaging over average_time = " +
                  format_fixed("%g", options_.average_time) + " d/U needs " +
                  std::to_string(needed) +
                  " more steps, beyond max_steps = " + std::to_string(options_.max_steps) +
                  "; remedy: --max-steps " + std::to_string(step + 2 * needed) + " or more");
    }
    loop_.averaging = true;
    loop_.averaging_start = step;
    shown_progress_.Restart();
    result_.warnings.push_back("unsteady flow from step " + std::to_string(step) +
                               ": the force is held and F time-averaged");
    return Next::kGoOn;
  }

  /// While averaging: the time means of F, Re and each body's drag; Re brought back to its band
  /// (restarting the average) or converged when the mean's standard error is small enough
  /// after average_time d/U. Returns kNextCheck while the average goes on.
  Next Average() {
    loop_.series_F.push_back(loop_.F_mean);
    loop_.series_re.push_back(loop_.re_lattice);
    loop_.series_body.resize(sc_.bodies);
    for (std::size_t s = 0; s < sc_.bodies; ++s) {
      loop_.series_body[s].push_back(body_force_[3 * s] / (3.0 * kPi * sc_.nu * sc_.d * loop_.U));
    }
    average_F_ = time_average(loop_.series_F);
    average_re_ = time_average(loop_.series_re, average_F_.truncated);
    const double averaged_time = static_cast<double>(average_F_.used * sc_.interval) *
                                 (sc_.target_re * sc_.nu / sc_.d) / sc_.d;
    if (averaged_time >= options_.average_time && average_F_.used >= 2 * kMinBlocks) {
      if (std::abs(average_re_.mean / sc_.target_re - 1.0) > options_.re_tolerance) {
        if (loop_.averaging_restarts >= kMaxAveragingRestarts) {
          return Fail("unsteady flow: the time-averaged Re " +
                      format_fixed("%.4g", average_re_.mean) +
                      " stays outside the band of the target " + format_fixed("%g", sc_.target_re) +
                      " after " + std::to_string(loop_.averaging_restarts) +
                      " corrections of the force; remedy: a wider re_tolerance");
        }
        SetForce(adjusted_force(loop_.force, average_re_.mean, sc_.target_re, sc_.phi,
                                &loop_.last_log_force, &loop_.last_log_re));
        loop_.series_F.clear();
        loop_.series_re.clear();
        loop_.series_body.clear();
        loop_.averaging_start = loop_.step;
        ++loop_.averaging_restarts;
        shown_progress_.Restart();
        return Next::kNextCheck;
      }
      if (average_F_.standard_error <= options_.average_tolerance * std::abs(average_F_.mean)) {
        return Next::kConverged;
      }
    }
    if (ProgressDue()) {
      const double se = average_F_.mean != 0.0
                            ? average_F_.standard_error / std::abs(average_F_.mean)
                            : std::numeric_limits<double>::infinity();
      progress_(shown_progress_.Show(AveragingFraction(averaged_time, se)),
                "step " + std::to_string(loop_.step) +
                    ": averaging, F = " + format_fixed("%.6g", average_F_.mean) + " +- " +
                    format_fixed("%.2g", 100.0 * se) + " % over " +
                    format_fixed("%.3g", averaged_time) +
                    " d/U, Re = " + format_fixed("%.4g", average_re_.mean) + ", " +
                    format_fixed("%.4g", result_.mflups) + " MFLUPS");
    }
    return Next::kNextCheck;
  }

  /// The share of the run done while averaging: its steps over those plus the steps still
  /// needed (averaging_steps_left); never below steps over max_steps.
  double AveragingFraction(double averaged_time, double relative_standard_error) const {
    const double steps_per_time = sc_.d / (sc_.target_re * sc_.nu / sc_.d);
    const double left =
        averaging_steps_left(std::max(0.0, options_.average_time - averaged_time) * steps_per_time,
                             static_cast<double>(average_F_.used), relative_standard_error,
                             options_.average_tolerance, static_cast<double>(sc_.interval));
    const double step = static_cast<double>(loop_.step);
    const double fraction = std::isfinite(left) ? step / (step + left) : 0.0;
    return std::clamp(std::max(fraction, step / static_cast<double>(options_.max_steps)), 0.0, 1.0);
  }

  /// The target Re: the force rescaled towards it (exactly in Stokes mode, where the scheme is
  /// linear in G; once the flow has settled otherwise, and held once Re has reached its band:
  /// finite_re_correction in averaging.h). kNextCheck after a change.
  Next ControlRe() {
    const double target_re = sc_.target_re;
    const double re_ratio = target_re > 0.0 ? loop_.re_lattice / target_re : 1.0;
    if (target_re > 0.0 && loop_.adjustments < kMaxAdjustments && loop_.re_lattice > 0.0) {
      if (sc_.stokes) {
        if (std::abs(re_ratio - 1.0) > options_.re_tolerance / 3.0) {
          // exact: the Stokes-mode scheme is linear in G
          const double velocity_factor = 1.0 / re_ratio;
          solver_->scale_deviations(velocity_factor);
          SetForce(loop_.force * velocity_factor);
          ++loop_.adjustments;
          return Next::kNextCheck;
        }
      } else if (loop_.relative_change < kAdjustBelowChange) {
        const double judged_re = finite_re_correction(loop_.re_lattice, FilteredRe(), target_re,
                                                      options_.re_tolerance, &loop_.re_control);
        if (judged_re > 0.0) {
          const double new_force = adjusted_force(loop_.force, judged_re, target_re, sc_.phi,
                                                  &loop_.last_log_force, &loop_.last_log_re);
          loop_.window.clear();
          solver_->scale_deviations(1.0 / (judged_re / target_re));
          SetForce(new_force);
          ++loop_.adjustments;
          return Next::kNextCheck;
        }
      }
    }
    const bool re_ok = target_re == 0.0 || std::abs(re_ratio - 1.0) <= options_.re_tolerance;
    if (loop_.relative_change < options_.tolerance &&
        loop_.balance < std::max(sc_.balance_tolerance, balance_floor_) && re_ok) {
      return Next::kConverged;
    }
    return Next::kGoOn;
  }

  /// Re of the mean superficial velocity over the last characteristic time.
  double FilteredRe() const {
    const auto& window = loop_.window;
    const std::size_t n = std::min<std::size_t>(window.size(), kChecksPerTime);
    double mean_U = 0.0;
    for (std::size_t k = window.size() - n; k < window.size(); ++k) mean_U += window[k].second;
    mean_U /= static_cast<double>(n);
    return mean_U * sc_.d / sc_.nu;
  }

  /// The progress line of a steady run (at most every kProgressInterval seconds).
  void Progress() {
    if (!ProgressDue()) return;
    const double relative_change = loop_.relative_change;
    double fraction = static_cast<double>(loop_.step) / static_cast<double>(options_.max_steps);
    if (std::isfinite(relative_change) && relative_change > 0.0) {
      fraction = std::max(
          fraction, std::clamp(std::log(relative_change) / std::log(options_.tolerance), 0.0, 1.0));
    }
    progress_(shown_progress_.Show(fraction),
              "step " + std::to_string(loop_.step) + ": F = " + format_fixed("%.6g", loop_.F_mean) +
                  ", Re = " + format_fixed("%.4g", loop_.re_lattice) +
                  ", change/T = " + format_fixed("%.2g", relative_change) + ", " +
                  format_fixed("%.4g", result_.mflups) + " MFLUPS");
  }

 private:
  using Clock = std::chrono::steady_clock;

  Next Fail(const std::string& why) {
    failure_ = why;
    return Next::kFail;
  }
  std::string Instability(const std::string& what, std::int64_t node) const {
    return diverged_diagnosis(lattice_, options_, sc_.d, sc_.nu, sc_.target_re, sc_.phi, loop_.step,
                              what, node, loop_.last_max_speed, loop_.last_max_node,
                              loop_.last_check_step);
  }
  void SetForce(double force) {
    loop_.force = force;
    solver_->set_force(force);
  }
  bool ProgressDue() {
    if (!progress_ ||
        std::chrono::duration<double>(Clock::now() - last_progress_).count() < kProgressInterval)
      return false;
    last_progress_ = Clock::now();
    return true;
  }

  const RunOptions& options_;
  const SparseLattice& lattice_;
  SolverBase* solver_;
  const Scales sc_;
  LoopState& loop_;
  RunResult& result_;
  const std::vector<double>& body_force_;
  const ProgressCallback& progress_;
  Clock::time_point last_progress_;
  PhaseProgress shown_progress_;
  MomentSummary m_;
  TimeAverage average_F_, average_re_;
  double sum_fx_ = 0.0;         ///< Sum of the bodies' x-forces at this check.
  double balance_floor_ = 0.0;  ///< Round-off floor of the momentum balance at this check.
  std::string failure_;
};

/// Set by request_stop(), possibly from a signal handler.
std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "request_stop must be async-signal-safe");

/// Why a run that request_stop() ended has no result, and how it goes on.
std::string stopped_diagnosis(const RunOptions& options, const LoopState& loop,
                              bool no_checkpoint) {
  return "stopped on request at step " + std::to_string(loop.step) +
         (no_checkpoint ? std::string(" (no checkpoint: the run starts afresh when run again)")
                        : "; the checkpoint '" + options.checkpoint + "' holds it: the same run " +
                              "goes on from there");
}

/// Why a run that reached max_steps has no result: how far it got, and how to go on.
std::string not_converged_diagnosis(const RunOptions& options, const RunResult& result,
                                    const LoopState& loop, bool no_checkpoint) {
  return "not converged after max_steps = " + std::to_string(options.max_steps) +
         " steps: relative change of F per characteristic time (" +
         std::to_string(result.characteristic_steps) + " steps) is " +
         format_fixed("%.3g", loop.relative_change) + ", momentum balance " +
         format_fixed("%.3g", loop.balance) + " (tolerance " +
         format_fixed("%.3g", options.tolerance) + ")" +
         (options.re > 0.0 ? ", Re = " + format_fixed("%.5g", loop.re_lattice) + " for target " +
                                 format_fixed("%g", options.re)
                           : std::string()) +
         "; remedy: raise max_steps (or loosen the tolerance); at high Re the flow "
         "may be unsteady" +
         (no_checkpoint ? std::string()
                        : "; the checkpoint '" + options.checkpoint + "' holds step " +
                              std::to_string(loop.step) +
                              ": the same run with a larger max_steps goes on from there");
}

/// One run. `plan`: the velocity plan of a finite-Re run (null at Re = 0).
RunResult run_impl(const arrays::VoxelGrid& grid, double phi_exact, const RunOptions& options,
                   Fields* fields, const ProgressCallback& progress, const VelocityPlan* plan) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  check_run_inputs(grid, options);
  RunResult result;
  result.collision = options.collision;
  result.phi_lattice = grid.phi_lattice();
  result.phi = phi_exact > 0.0 ? phi_exact : result.phi_lattice;
  result.d = options.use_hydrodynamic_diameter ? options.hydrodynamic_diameter : grid.resolution();
  const double phi = result.phi;
  const double d = result.d;
  if (!(phi > 0.0 && phi < 1.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                "lbm run: solids fraction must be in (0, 1), got " + format_fixed("%g", phi));
  }
  const bool stokes = options.stokes_mode == RunOptions::StokesMode::kOn ||
                      (options.stokes_mode == RunOptions::StokesMode::kAuto && options.re == 0.0);
  result.stokes_mode = stokes;
  const double target_re = options.re;

  // Relaxation times and the velocity scale. Finite Re: the plan (resolution.h). Re = 0 asks for
  // creeping flow: a small velocity also with the full equilibrium (so that its u.u terms are
  // negligible, not merely its Re undefined).
  const Relaxation relaxation = plan_relaxation(options, plan, &result);
  const double tau = relaxation.tau, nu = relaxation.nu;
  const double budget_u = kStokesMaxSpeed * (1.0 - phi) / kPoreSpeedFactor;
  const double target_u = target_re > 0.0 ? target_re * nu / d : budget_u;
  // Everything the run loop carries from check to check, kept together for a checkpoint.
  LoopState loop;
  double& force = loop.force;
  force = force_for_velocity(target_u, nu, d, phi, target_re);
  result.body_force = force;
  // Set once the lattice exists; a failure before has no checkpoint to remove.
  std::unique_ptr<RunCheckpoint> checkpoint;

  auto fail = [&](const std::string& diagnosis) {
    if (checkpoint) checkpoint->Finish();
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

  const std::string too_close = relaxation_too_close_to_half(options, relaxation, d);
  if (!too_close.empty()) return fail(too_close);

  // Lattice, links, solver. Several ranks share the box in slabs of z-planes (lattice.h); what
  // one rank cannot build (memory), none goes on with.
  const mpi::Communicator& group = options.ranks;
  const int threads = resolve_threads(options.threads, group);
  const WallScheme wall = choose_wall(options, tau, stokes, &result);
  const SolverSettings settings = solver_settings(options, relaxation, stokes, force, &result);
  const Engine engine = build_engine(grid, options, wall, settings, threads);
  const SparseLattice& lattice = *engine.lattice;
  const LinkTable& links = *engine.links;
  SolverBase* const solver = engine.solver.get();
  record_lattice(grid, engine, group, &result);
  // Counts over the whole box (every rank's share).
  const std::int64_t fluid = result.fluid_nodes;
  const double total_nodes = static_cast<double>(grid.num_nodes());
  const std::size_t bodies = links.num_bodies();
  const double mixture = mixture_factor(grid);

  // Characteristic time and check interval (even: the AA pattern advances in pairs).
  const double char_time = d * d / (nu * (1.0 + target_re));
  std::int64_t interval =
      static_cast<std::int64_t>(std::ceil(char_time / kChecksPerTime / 2.0)) * 2;
  interval = std::clamp<std::int64_t>(interval, 2, kMaxCheckInterval);
  result.characteristic_steps = interval * kChecksPerTime;

  std::vector<double> body_force;
  RunChecks::Scales check_scales;
  check_scales.d = d;
  check_scales.nu = nu;
  check_scales.phi = phi;
  check_scales.target_re = target_re;
  check_scales.stokes = stokes;
  check_scales.fluid = fluid;
  check_scales.total_nodes = total_nodes;
  check_scales.bodies = bodies;
  check_scales.mixture = mixture;
  check_scales.interval = interval;
  // Float storage rounds every population to ~1e-7 relative each step, which leaves a noise
  // floor in the momentum balance (measured ~1e-6 .. 1e-5); double reaches round-off.
  check_scales.balance_tolerance = options.precision == Precision::kFloat
                                       ? std::max(options.tolerance, kFloatBalanceFloor)
                                       : options.tolerance;
  RunChecks checks(options, lattice, solver, check_scales, &loop, &result, &body_force, progress);
  std::int64_t& step = loop.step;
  double& stepping_s = loop.stepping_s;

  // Checkpoint: resume from it (the same run only), then rewrite it now and then.
  loop.measured_pore_speed_ratio = plan != nullptr && plan->kappa_measured ? plan->kappa : 0.0;
  checkpoint = std::make_unique<RunCheckpoint>(options, group, solver, &loop, &result, start);
  if (checkpoint->enabled()) {
    checkpoint->Resume(
        run_fingerprint(grid, lattice, links, options, settings, result, interval, group));
  }
  // A check's stage that stops the run: the fields as they are, then the diagnosis.
  auto stop = [&](const std::string& diagnosis) {
    if (fields != nullptr) solver->fill_fields(fields);
    return fail(diagnosis);
  };

  while (true) {
    checkpoint->SaveIfDue();
    bool stopping = g_stop_requested.load();
    if (group.size() > 1) stopping = group.sum(std::int64_t{stopping ? 1 : 0}) > 0;
    if (stopping) {
      checkpoint->KeepForMoreSteps();
      result.steps = step;
      result.mflups = stepping_s > 0.0 ? static_cast<double>(fluid) * step / stepping_s / 1e6 : 0.0;
      result.stopped_on_request = true;
      return stop(stopped_diagnosis(options, loop, !checkpoint->enabled()));
    }
    if (step >= options.max_steps) {
      checkpoint->KeepForMoreSteps();
      result.steps = step;
      result.mflups = stepping_s > 0.0 ? static_cast<double>(fluid) * step / stepping_s / 1e6 : 0.0;
      return stop(not_converged_diagnosis(options, result, loop, !checkpoint->enabled()));
    }
    // Checks at every multiple of the interval (a resumed run keeps the schedule), the last
    // one cut short at max_steps (rounded up to a pair).
    const std::int64_t next_check = (step / interval + 1) * interval;
    const std::int64_t pairs = (std::min(next_check, options.max_steps) - step + 1) / 2;
    const auto t_step = Clock::now();
    for (std::int64_t p = 0; p < pairs; ++p) {
      solver->advance_pair(p + 1 == pairs ? &body_force : nullptr);
    }
    stepping_s += seconds_since(t_step);
    step += 2 * pairs;
    if (checkpoint->enabled() && step % interval != 0) {
      // Cut short by max_steps: the state before this check, which the run that goes on
      // from it will not make.
      checkpoint->Save();
    }
    result.steps = step;
    result.mflups = stepping_s > 0.0 ? static_cast<double>(fluid) * step / stepping_s / 1e6 : 0.0;
    result.force_adjustments = loop.adjustments;

    using Next = RunChecks::Next;
    if (checks.Health() == Next::kFail || checks.Drag() == Next::kFail) {
      return stop(checks.failure());
    }
    checks.Rescale();
    Next next = checks.DetectUnsteady();
    if (next == Next::kFail) return stop(checks.failure());
    if (next == Next::kNextCheck) continue;
    next = loop.averaging ? checks.Average() : checks.ControlRe();
    if (next == Next::kFail) return stop(checks.failure());
    if (next == Next::kConverged) break;
    if (next == Next::kNextCheck) continue;
    checks.Progress();
  }

  // Converged: normalise.
  RunScales scales;
  scales.phi = phi;
  scales.d = d;
  scales.nu = nu;
  scales.tau = tau;
  scales.stokes = stokes;
  scales.interval = interval;
  scales.fluid = fluid;
  scales.bodies = bodies;
  scales.mixture = mixture;
  normalise_converged(loop, checks.average_F(), checks.average_re(), checks.moments(), body_force,
                      scales, options, grid, &result);
  if (fields != nullptr) solver->fill_fields(fields);
  checkpoint->Finish();
  result.wall_s = seconds_since(start);
  if (progress) progress(1.0, "converged after " + std::to_string(step) + " steps");
  return result;
}

/// The Stokes run that measures kappa = max|u|/U on the run's own lattice: TRT with the central
/// wall (stable and second order there), its automatic tau, a loose tolerance (kappa to about
/// a per cent is all the plan needs).
RunOptions pore_speed_options(const RunOptions& options) {
  RunOptions s = options;
  s.re = 0.0;
  s.tau = 0.0;
  s.collision = Collision::kTrt;
  s.magic = 3.0 / 16.0;
  s.boundary = Boundary::kInterpolated;
  s.interpolation = WallInterpolation::kCentral;
  s.stokes_mode = RunOptions::StokesMode::kOn;
  s.tolerance = kPoreSpeedTolerance;
  s.throw_on_failure = false;
  s.checkpoint.clear();  // the run it plans keeps the checkpoint
  return s;
}

/// run_impl behind the velocity plan of a finite-Re run: refused before any stepping when the
/// operator cannot hold the estimated cell Reynolds number (Error(kInvalidArgument)); when the
/// engine chooses tau, the velocity is planned with kappa measured by a Stokes run on the same
/// lattice (resolution.h).
RunResult run_planned(const arrays::VoxelGrid& grid, double phi_exact, const RunOptions& options,
                      Fields* fields, const ProgressCallback& progress) {
  const double phi = phi_exact > 0.0 ? phi_exact : grid.phi_lattice();
  const double d =
      options.use_hydrodynamic_diameter ? options.hydrodynamic_diameter : grid.resolution();
  const CollisionChoice choice = choose_collision(phi, options.re, d, options.collision);
  auto finish = [&](RunResult r) {
    r.collision_reason = choice.reason;
    if (!r.converged && options.throw_on_failure) {
      throw Error(ErrorCode::kOutOfValidity, "lbm run: " + r.diagnosis);
    }
    return r;
  };
  RunOptions quiet = options;
  quiet.collision = choice.collision;
  quiet.throw_on_failure = false;
  if (options.re == 0.0) return finish(run_impl(grid, phi_exact, quiet, fields, progress, nullptr));
  VelocityPlan plan = plan_velocity(phi, options.re, d, quiet.collision, options.mach_target, 0.0,
                                    false, options.tau);
  std::string refusal = cell_reynolds_refusal(plan, options.re, d, quiet.collision);
  if (!refusal.empty()) throw Error(ErrorCode::kInvalidArgument, "lbm run: " + refusal);
  RunResult stokes;
  // A run that goes on from a checkpoint plans with the kappa its Stokes run measured.
  const double resumed_kappa =
      options.checkpoint.empty() || options.tau != 0.0
          ? 0.0
          : checkpoint_pore_speed_ratio(checkpoint_file(options, options.ranks));
  if (resumed_kappa > 0.0) {
    plan = plan_velocity(phi, options.re, d, quiet.collision, options.mach_target, resumed_kappa,
                         true);
    stokes.converged = true;
  } else if (options.tau == 0.0) {
    ProgressCallback stokes_progress;
    if (progress) {
      stokes_progress = [&progress](double fraction, const std::string& status) {
        (void)fraction;
        progress(0.0, "pore-speed ratio (Stokes run): " + status);
      };
    }
    stokes =
        run_impl(grid, phi_exact, pore_speed_options(options), nullptr, stokes_progress, nullptr);
    if (stokes.converged && stokes.final_pore_speed_ratio > 0.0) {
      plan = plan_velocity(phi, options.re, d, quiet.collision, options.mach_target,
                           stokes.final_pore_speed_ratio, true);
    }
  }
  RunResult r = run_impl(grid, phi_exact, quiet, fields, progress, &plan);
  if (options.tau == 0.0) {
    r.wall_s += stokes.wall_s;
    if (!stokes.converged) {
      r.warnings.insert(r.warnings.begin(),
                        "the Stokes run for the pore-speed ratio did not converge (" +
                            stokes.diagnosis + "); the velocity was planned with kappa " +
                            "estimated from phi");
    }
  }
  if (plan.cell_reynolds > stable_cell_reynolds(quiet.collision)) {
    r.warnings.push_back(
        "cell Reynolds number kappa Re / d = " + format_fixed("%.3g", plan.cell_reynolds) +
        " is beyond " + format_fixed("%g", stable_cell_reynolds(quiet.collision)) + ", where " +
        to_string(quiet.collision) +
        " has held in every measured packing; it may diverge (at --d " +
        format_fixed("%g", plan.d_stable) + " it would not)");
  }
  return finish(r);
}

}  // namespace

void request_stop() { g_stop_requested.store(true); }
bool stop_requested() { return g_stop_requested.load(); }
void clear_stop_request() { g_stop_requested.store(false); }

double predicted_steps(double phi, double re, double d, Collision collision) {
  collision = choose_collision(phi, re, d, collision).collision;
  const double stokes_tau = collision == Collision::kTrt ? 1.5 : 1.0;
  auto steps_at = [phi, d](double tau, double re) {
    const double nu = (tau - 0.5) / 3.0;
    const double characteristic = d * d / (nu * (1.0 + re));
    const double darcy = d * d / (nu * phi * bvk2007_estimate(phi, re));
    return std::max(2.5 * characteristic, 0.9 * darcy);
  };
  if (re == 0.0) return steps_at(stokes_tau, 0.0);
  // The Stokes run that measures kappa (TRT, tau 1.5, a loose tolerance), then the run itself:
  // its approach to the target Re, and where the flow is expected to turn unsteady the time
  // average over average_time d/U after it.
  const VelocityPlan plan = plan_velocity(phi, re, d, collision, kDefaultMachTarget, 0.0, false);
  const double averaging = expects_unsteady_flow(phi, re)
                               ? RunOptions().average_time * d * d / (re * ((plan.tau - 0.5) / 3.0))
                               : 0.0;
  return kPoreSpeedRunShare * steps_at(1.5, 0.0) + steps_at(plan.tau, re) + averaging;
}

RunResult run(const arrays::VoxelGrid& grid, double phi_exact, const RunOptions& options,
              const ProgressCallback& progress) {
  return run_planned(grid, phi_exact, options, nullptr, progress);
}

RunResult run_with_fields(const arrays::VoxelGrid& grid, double phi_exact,
                          const RunOptions& options, Fields* fields,
                          const ProgressCallback& progress) {
  return run_planned(grid, phi_exact, options, fields, progress);
}

double physical_memory_bytes() { return core::physical_memory_bytes(); }

double estimated_run_bytes(double nodes, Precision precision) {
  // Populations (19 per node) plus flags, links and fields: a generous per-node budget.
  return nodes * (precision == Precision::kFloat ? 110.0 : 200.0);
}

void check_run_size(const arrays::Packing& packing, double resolution, const RunOptions& options,
                    const std::string& field) {
  if (!std::isfinite(resolution) || resolution < kMinResolution || resolution > kMaxResolution) {
    throw Error(ErrorCode::kInvalidArgument,
                field + " = " + format_fixed("%g", resolution) + " is outside [" +
                    format_fixed("%g", kMinResolution) + ", " + format_fixed("%g", kMaxResolution) +
                    "] lattice units per diameter");
  }
  const double gap = options.min_gap_nodes > 0.0
                         ? arrays::min_gap_lattice_units(packing, resolution)
                         : std::numeric_limits<double>::infinity();  // opt-in check
  if (gap < options.min_gap_nodes) {
    const double needed = gap > 0.0 ? resolution * options.min_gap_nodes / gap : 0.0;
    throw Error(
        ErrorCode::kInvalidArgument,
        field + " = " + format_fixed("%g", resolution) +
            " is too low for the gaps: the smallest gap between spheres spans " +
            format_fixed("%.3g", gap) +
            " lattice units, below min_gap_nodes = " + format_fixed("%g", options.min_gap_nodes) +
            (gap > 0.0 && needed <= kMaxResolution
                 ? "; raise the resolution to at least " + format_fixed("%.4g", needed) + ", or"
                 : std::string(gap > 0.0
                                   ? " (the resolution it would need, " +
                                         format_fixed("%.4g", needed) + ", is beyond the limit " +
                                         format_fixed("%g", kMaxResolution) + ");"
                                   : "; the spheres touch or overlap;")) +
            " generate the packing with a minimum surface gap of at least " +
            format_fixed("%.3g", options.min_gap_nodes / resolution) +
            " diameters (draglab pack --min-gap " +
            format_fixed("%.3g", 1.5 * options.min_gap_nodes / resolution) +
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
  const double memory = core::physical_memory_bytes();
  if (memory > 0.0 && bytes > 0.8 * memory) {
    throw Error(
        ErrorCode::kInvalidArgument,
        field + " = " + format_fixed("%g", resolution) + " needs about " +
            format_fixed("%.1f", bytes / 1073741824.0) + " GiB for " + format_fixed("%.3g", nodes) +
            " lattice nodes" +
            (ranks > 1 ? " on this node (" + std::to_string(ranks_on_this_node(options.ranks)) +
                             " of the " + std::to_string(ranks) + " ranks)"
                       : std::string()) +
            ", more than 80 % of this machine's " + format_fixed("%.1f", memory / 1073741824.0) +
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
  return run_planned(grid, packing.phi(), options, nullptr, progress);
}

}  // namespace lbm
}  // namespace draglab
