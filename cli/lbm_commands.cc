// `draglab lbm run|bench|convergence|calibrate`: the lattice-Boltzmann drag engine.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "cli/stop_signal.h"
#include "draglab/arrays/packing.h"
#include "draglab/arrays/packing_io.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/lbm/calibration.h"
#include "draglab/lbm/case_run.h"
#include "draglab/lbm/convergence.h"
#include "draglab/lbm/fields_io.h"
#include "draglab/lbm/lbm.h"
#include "draglab/lbm/resolution.h"
#include "draglab/mpi/communicator.h"
#include "draglab/mpi/world.h"
#include "draglab/workflows/bed_results.h"
#include "draglab/workflows/convergence_plot.h"

namespace draglab {
namespace cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using workflows::number_or_null;
constexpr int kMaxThreads = 1024;       // as campaign run --threads-per-unit
constexpr double kMaxReferenceF = 1e6;  // far above any drag F of a fixed bed
constexpr double kMaxRe = 1000.0;       // the range; beyond it the Mach budget needs d > 80

/// Which geometry: a packing file or an ordered array.
struct CaseOptions {
  std::string packing_file;
  std::string array;  // sc, bcc, fcc
  double phi = kNaN;
  int cells = 1;
};

/// Solver settings shared by run, convergence and calibrate.
struct SolverOptions {
  double re = kNaN;
  std::string collision = "trt";
  std::string boundary = "ibb";
  std::string wall_interpolation = "auto";
  std::string rr_wall_correction = "on";
  std::string precision = "double";
  double tau = 0.0;
  double magic = 3.0 / 16.0;
  double mach = 0.15;
  double average_time = 20.0;
  bool average_time_given = false;
  double average_tolerance = 5e-3;
  std::int64_t max_steps = 200000;
  double tolerance = 1e-6;
  int threads = 0;
  double min_gap_nodes = 0.0;  // opt-in gap check; 0 = run sub-node gaps and report them
};

/// lbm run's solver settings: the operator chosen per run (resolution.h, choose_collision).
SolverOptions auto_collision() {
  SolverOptions s;
  s.collision = "auto";
  return s;
}

struct RunCommand {
  CaseOptions case_options;
  SolverOptions solver = auto_collision();
  double d = kNaN;
  std::string fields;
  double d_hydro = 0.0;
  bool d_hydro_given = false;
  bool calibrate = false;
  std::string checkpoint;
  double checkpoint_interval = 600.0;
};

struct ConvergenceCommand {
  CaseOptions case_options;
  SolverOptions solver;
  std::string d_list = "8,12,16,24";
  std::string schemes = "bgk-bb,trt-bb,trt-ibb";
  std::string plot;
  double reference = kNaN;
};

struct CalibrateCommand {
  SolverOptions solver;
  double d = kNaN;
  double phi = 0.01;
  double check_phi = 0.0;
  int positions = 4;
};

struct BenchCommand {
  int threads = 0;
  int repeat = 5;
  double phi = 0.4;
};

/// The geometry of a run, and how to describe it.
struct Case {
  arrays::Packing packing;
  std::string description;
};

Case load_case(const CaseOptions& o) {
  if (o.packing_file.empty() == o.array.empty()) {
    throw UsageError("give exactly one of --packing FILE.h5 or --array sc|bcc|fcc (with --phi)");
  }
  Case c;
  if (!o.packing_file.empty()) {
    if (!std::isnan(o.phi)) {
      throw UsageError("--phi goes with --array; a packing file has its own phi");
    }
    c.packing = arrays::read_packing_hdf5(o.packing_file);  // Error(kInvalidArgument): exit 2
    c.description = fmt::format("{} ({} spheres, phi = {:.6g})", o.packing_file, c.packing.size(),
                                c.packing.phi());
    return c;
  }
  const arrays::Lattice lattice = arrays::lattice_from_string(o.array);
  const double max_phi = arrays::close_packing_phi(lattice);
  if (std::isnan(o.phi)) throw UsageError("--phi is required with --array");
  // Close packing (touching spheres, Zick & Homsy's densest case) is allowed: the contacts are
  // sub-node gaps, run and reported like those of random packings.
  if (!std::isfinite(o.phi) || o.phi <= 0.0 || o.phi > max_phi * (1.0 + 1e-12)) {
    throw UsageError(fmt::format(
        "--phi = {} is outside (0, {:.6f}] for --array {} (the upper end is close packing: "
        "touching spheres)",
        o.phi, max_phi, o.array));
  }
  if (o.cells < 1 || o.cells > 16) throw UsageError("--cells must lie in [1, 16]");
  arrays::OrderedPackingOptions oo;
  oo.lattice = lattice;
  oo.phi = o.phi;
  oo.cells = o.cells;
  c.packing = arrays::generate_ordered_packing(oo);
  c.description = fmt::format("{} array, phi = {:.6g} ({} sphere{})", o.array, o.phi,
                              c.packing.size(), c.packing.size() == 1 ? "" : "s");
  return c;
}

lbm::RunOptions run_options(const SolverOptions& s) {
  lbm::RunOptions r;
  if (std::isnan(s.re)) throw UsageError("--re is required (0 = Stokes flow)");
  if (!std::isfinite(s.re) || s.re < 0.0 || s.re > kMaxRe) {
    throw UsageError(fmt::format("--re = {} is outside [0, {}]", s.re, kMaxRe));
  }
  r.collision = lbm::collision_from_string(s.collision);
  r.boundary = lbm::boundary_from_string(s.boundary);
  r.interpolation = lbm::wall_interpolation_from_string(s.wall_interpolation);
  r.rr_wall_correction = s.rr_wall_correction == "on";
  r.precision = lbm::precision_from_string(s.precision);
  r.re = s.re;
  r.tau = s.tau;
  r.magic = s.magic;
  r.mach_target = s.mach;
  r.average_time = s.average_time;
  r.average_tolerance = s.average_tolerance;
  r.max_steps = s.max_steps;
  r.tolerance = s.tolerance;
  r.threads = s.threads;
  r.min_gap_nodes = s.min_gap_nodes;
  if (!std::isfinite(s.min_gap_nodes) || s.min_gap_nodes < 0.0 || s.min_gap_nodes > 100.0) {
    throw UsageError(
        fmt::format("--min-gap-nodes = {} is outside [0, 100] (0 = no check)", s.min_gap_nodes));
  }
  if (s.max_steps < 1) throw UsageError("--max-steps must be >= 1");
  if (s.threads < 0 || s.threads > kMaxThreads) {
    throw UsageError(
        fmt::format("--threads = {} is outside [0, {}] (0 = all)", s.threads, kMaxThreads));
  }
  std::string error;
  if (!r.IsValid(&error)) throw UsageError(error);
  return r;
}

/// Exit code main() gives an exception (see cli_context.h).
int exit_code_of(const std::exception& e) {
  if (dynamic_cast<const UsageError*>(&e) != nullptr) return 2;
  if (const auto* error = dynamic_cast<const Error*>(&e)) return error->is_bad_input() ? 2 : 1;
  return 1;
}

/// Runs `step` on every rank of `group`, then ends every rank if it failed on any: rank 0
/// reports the failure of the lowest failing rank (its message and exit code), the others end
/// silently with that code. So that no rank is left waiting in a collective call for a rank
/// that stopped at bad input.
void on_every_rank(const mpi::Communicator& group, const std::function<void()>& step) {
  if (group.size() == 1) {
    step();
    return;
  }
  std::string outcome = "0";
  try {
    step();
  } catch (const std::exception& e) {
    outcome = std::to_string(exit_code_of(e)) + e.what();
  } catch (...) {
    outcome = "1unknown error";
  }
  for (const std::string& o : group.allgather(outcome)) {
    if (o == "0") continue;
    const int code = o[0] - '0';
    if (!group.is_root()) throw mpi::EndedByRank0(code);
    if (code == 2) throw UsageError(o.substr(1));
    throw std::runtime_error(o.substr(1));
  }
}

/// The calibration runs: one that does not converge is a run-time failure (exit 1), as in lbm
/// run; bad options stay bad input.
lbm::CalibrationResult calibrate(const lbm::CalibrationOptions& co,
                                 const lbm::ProgressCallback& progress) {
  try {
    return lbm::calibrate_hydrodynamic_diameter(co, progress);
  } catch (const Error& e) {
    if (e.code() == ErrorCode::kOutOfValidity) throw std::runtime_error(e.what());
    throw;
  }
}

/// Before any work: the operator must hold the cell Reynolds number (resolution.h), and an
/// averaging window the user set must fit in max_steps.
void check_finite_re_plan(double phi, double d, const lbm::RunOptions& options,
                          const SolverOptions& s) {
  if (options.re == 0.0) return;
  const lbm::VelocityPlan plan = lbm::plan_velocity(phi, options.re, d, options.collision,
                                                    options.mach_target, 0.0, false, options.tau);
  const std::string refusal = lbm::cell_reynolds_refusal(plan, options.re, d, options.collision);
  if (!refusal.empty()) throw UsageError("--d / --re: " + refusal);
  if (!s.average_time_given) return;
  // Steps of the window at the plan's velocity (kappa estimated; the measured one is larger,
  // so the run's window is longer still).
  const double window = options.average_time * d / plan.velocity;
  if (window > static_cast<double>(options.max_steps)) {
    throw UsageError(fmt::format(
        "--average-time = {} d/U is {:.0f} steps at this run's velocity (U = {:.4g}), more than "
        "--max-steps = {}; raise --max-steps to at least {:.0f} or shorten --average-time",
        options.average_time, window, plan.velocity, options.max_steps, 2.0 * window));
  }
}

void run_lbm(const CliContext& ctx, const RunCommand& c) {
  // Launched with several ranks, the ranks share the box (slabs of z-planes): each reads the
  // input, rank 0 alone checks the outputs, prints and writes.
  const mpi::Communicator group = mpi::Communicator::world();
  const bool root = group.is_root();
  // Everything the user typed is checked before the (possibly long) run.
  lbm::RunOptions options;
  Case the_case;
  on_every_rank(group, [&] {
    options = run_options(c.solver);
    options.ranks = group;  // the calibration runs, and the run, share the box
    if (std::isnan(c.d)) throw UsageError("--d is required (lattice units per sphere diameter)");
    the_case = load_case(c.case_options);
    lbm::check_run_size(the_case.packing, c.d, options, "--d");
    if (!c.fields.empty() && root) core::check_output_file(c.fields, "--fields");
    options.checkpoint = c.checkpoint;
    options.checkpoint_interval = c.checkpoint_interval;
    if (!std::isfinite(c.checkpoint_interval) || c.checkpoint_interval < 0.0 ||
        c.checkpoint_interval > 1e6) {
      throw UsageError(
          fmt::format("--checkpoint-interval = {} s is outside [0, 1e6]", c.checkpoint_interval));
    }
    if (!c.checkpoint.empty()) {
      const std::string mine = group.size() == 1
                                   ? c.checkpoint
                                   : c.checkpoint + ".rank" + std::to_string(group.rank()) + "of" +
                                         std::to_string(group.size());
      if (core::file_exists(mine)) {
        lbm::check_checkpoint_file(mine);
      } else {
        core::check_output_file(c.checkpoint, "--checkpoint");
      }
    }
    if (c.d_hydro_given && c.calibrate) {
      throw UsageError("give --d-hydro or --calibrate, not both");
    }
    if (c.d_hydro_given) {
      if (!std::isfinite(c.d_hydro) || c.d_hydro < 0.5 * c.d || c.d_hydro > 1.5 * c.d) {
        throw UsageError(fmt::format("--d-hydro = {} is outside [0.5 d, 1.5 d] = [{}, {}]",
                                     c.d_hydro, 0.5 * c.d, 1.5 * c.d));
      }
    }
    if (c.calibrate && options.re > 0.0 && options.tau == 0.0) {
      throw UsageError(
          "--calibrate at --re > 0 needs --tau: d_h depends on tau and the "
          "calibration runs in Stokes flow");
    }
    if (c.calibrate && c.d > 128.0) throw UsageError("--calibrate works for --d up to 128");
    check_finite_re_plan(the_case.packing.phi(), c.d, options, c.solver);
  });

  lbm::CaseOptions co;
  co.run = options;
  co.run.throw_on_failure = false;  // report a failed run with its diagnosis, then exit 1
  co.resolution = c.d;
  co.calibrate = c.calibrate;
  co.hydrodynamic_diameter = c.d_hydro_given ? c.d_hydro : 0.0;
  co.fields = c.fields;
  co.description = the_case.description;
  ProgressLine progress(!ctx.quiet && root);
  // With a checkpoint, SIGTERM and SIGINT stop the run at its next check with the checkpoint
  // saved (the same command goes on from it); without one they end it at once, as before.
  std::optional<StopOnSignal> stop_on_signal;
  if (!co.run.checkpoint.empty()) stop_on_signal.emplace();
  lbm::CaseResult result;
  try {
    result = lbm::run_case(the_case.packing, co, [&progress](double f, const std::string& stage) {
      progress.update(f, stage);
    });
  } catch (const std::exception& e) {
    // The engine agrees on bad input (too many ranks for the box, memory) across the ranks
    // before any of them goes on: rank 0 reports it. Anything else may be this rank's alone
    // (an MPI failure): end the whole job rather than leave the others waiting.
    if (group.size() == 1) throw;
    const int code = exit_code_of(e);
    if (code == 2) {
      if (root) throw;
      throw mpi::EndedByRank0(code);
    }
    std::cerr << "error: rank " << group.rank() << ": " << e.what() << '\n';
    mpi::abort(code);
  }
  progress.finish();
  const lbm::RunResult& r = result.run;
  if (!root) {
    if (!r.converged) throw mpi::EndedByRank0(1);  // rank 0 prints the diagnosis
    return;
  }
  if (result.calibration) {
    ctx.info(fmt::format("calibration: d_h/d = {:.5f} ({} at d = {:.4g}, {:.1f} s)",
                         result.calibration->ratio,
                         lbm::Scheme{r.collision, options.boundary}.name(),
                         result.calibration->diameter, result.calibration->wall_s));
  }
  const nlohmann::json j = nlohmann::json::parse(result.ToJson(co));
  const double reference = result.reference_F;
  const std::string& fields_error = result.fields_error;
  if (ctx.json) {
    ctx.print_json(j);
  } else {
    std::cout << fmt::format("case             {}\n", the_case.description);
    std::cout << fmt::format("lattice          {} x {} x {} nodes, d = {:.4g} lattice units{}\n",
                             result.dims[0], result.dims[1], result.dims[2], result.resolution,
                             result.hydrodynamic_diameter > 0.0
                                 ? fmt::format(" (d_h = {:.4g})", result.hydrodynamic_diameter)
                                 : "");
    std::cout << fmt::format("scheme           {} + {}, {}, tau = {:.4g}{}\n",
                             lbm::to_string(r.collision), r.wall, lbm::to_string(options.precision),
                             r.tau, options.re == 0.0 ? " (Stokes mode)" : "");
    if (!r.collision_reason.empty()) {
      std::cout << fmt::format("collision        auto -> {}: {}\n", lbm::to_string(r.collision),
                               r.collision_reason);
    }
    if (!r.wall_reason.empty()) {
      std::cout << fmt::format("wall             {}: {}\n", r.wall, r.wall_reason);
    }
    if (r.pore_speed_ratio > 0.0) {
      std::cout << fmt::format(
          "velocity plan    kappa = u_max/U {:.3g} ({}), Mach target {:g}, U = {:.4g}; Re_cell "
          "= kappa Re/d {:.3g} (limit {:g}){}\n",
          r.pore_speed_ratio, r.pore_speed_ratio_measured ? "Stokes run" : "estimated",
          r.mach_target, r.superficial_velocity, r.cell_reynolds, r.cell_reynolds_limit,
          r.converged ? fmt::format("; at the end kappa {:.3g}, max|u|/nu {:.3g}",
                                    r.final_pore_speed_ratio, r.final_cell_reynolds)
                      : std::string());
    }
    std::cout << fmt::format(
        "phi              {:.6f} exact, {:.6f} on the lattice{}\n", r.phi, r.phi_lattice,
        j.contains("phi_hydrodynamic")
            ? fmt::format(", {:.6f} with d_h", j["phi_hydrodynamic"].get<double>())
            : "");
    if (r.converged) {
      std::cout << fmt::format("F                {} (estimated error {:.2g} %{})\n",
                               format_number(r.F), 100.0 * r.error_estimate,
                               j.contains("error") ? fmt::format("; vs the series {:+.3f} %",
                                                                 100.0 * (r.F / reference - 1.0))
                                                   : "");
      for (const lbm::SpeciesDrag& sd : result.species) {
        std::cout << fmt::format(
            "F_i              {} +- {} (d_i/<d> = {:.4g}, {:.3g} of the solids, {} spheres; "
            "own diameter)\n",
            format_number(sd.F), format_number(sd.F_standard_error, 2), sd.diameter,
            sd.volume_fraction, sd.spheres);
      }
      std::cout << fmt::format("K                {}\n", format_number(r.K));
      std::cout << fmt::format("beta d^2/mu      {}\n", format_number(r.beta_d2_over_mu));
      std::cout << fmt::format("Re               {} (target {})\n", format_number(r.re, 4),
                               format_number(c.solver.re, 4));
      std::cout << fmt::format("momentum balance {:.2g} relative\n", r.momentum_balance_rel);
    }
    std::cout << fmt::format("Mach max         {:.3g}\n", r.mach_max);
    if (r.narrow_gap_pairs > 0 || r.narrow_gap_fluid_fraction > 0.0) {
      std::cout << fmt::format(
          "sub-node gaps    {} sphere pairs closer than one node (smallest {:.3g}), {:.2f} % of "
          "fluid nodes in one-node gaps\n",
          r.narrow_gap_pairs, r.smallest_gap_nodes, 100.0 * r.narrow_gap_fluid_fraction);
    }
    std::cout << fmt::format("run              {}, {} steps, {:.2f} s, {:.1f} MFLUPS\n",
                             r.converged ? "converged" : "NOT CONVERGED", r.steps, r.wall_s,
                             r.mflups);
    if (!c.fields.empty() && fields_error.empty()) {
      std::cout << fmt::format("fields           {} + {} (ParaView: XDMF Reader)\n", c.fields,
                               lbm::xdmf_path_for(c.fields));
    }
  }
  for (const std::string& w : r.warnings) ctx.info("warning: " + w);
  if (!r.converged) {
    throw std::runtime_error("the run did not converge: " + r.diagnosis +
                             " (no drag value reported)");
  }
  if (!fields_error.empty()) {
    throw std::runtime_error(
        "--fields: the result above is complete, but the field file was not "
        "written: " +
        fields_error);
  }
}

void run_bench(const CliContext& ctx, const BenchCommand& b) {
  if (b.threads < 0 || b.threads > kMaxThreads) {
    throw UsageError(
        fmt::format("--threads = {} is outside [0, {}] (0 = all)", b.threads, kMaxThreads));
  }
  if (b.repeat < 1 || b.repeat > 100) throw UsageError("--repeat must lie in [1, 100]");
  if (!(b.phi >= 0.1 && b.phi <= 0.6)) {
    throw UsageError(
        fmt::format("--phi = {} is outside [0.1, 0.6] (the packing's solid fraction)", b.phi));
  }
  ctx.info(fmt::format(
      "lbm bench: all-fluid box, phi = {} packing, the blocks-8 geometry and in-place bandwidth "
      "kernel, the first two at least 4x the last-level cache (about a minute)",
      b.phi));
  lbm::BenchOptions options;
  options.threads = b.threads;
  options.repeat = b.repeat;
  options.packing_phi = b.phi;
  const lbm::BenchResult r = lbm::benchmark(options);
  if (ctx.json) {
    ctx.print_json(
        {{"mflups", r.mflups},
         {"mflups_fluid_packing", r.mflups_fluid_packing},
         {"mflups_fluid_packing_bb", r.mflups_fluid_packing_bb},
         {"packing_bb_to_fluid_ratio", r.mflups > 0 ? r.mflups_fluid_packing_bb / r.mflups : 0.0},
         {"mflups_blocks", r.mflups_blocks},
         {"mflups_blocks_bb", r.mflups_blocks_bb},
         {"blocks_fluid_nodes", r.blocks_fluid_nodes},
         {"bandwidth_gbs", r.bandwidth_gbs},
         {"roofline_fraction", r.roofline_fraction},
         {"mflups_rr", r.mflups_rr},
         {"mflups_fluid_packing_rr", r.mflups_fluid_packing_rr},
         {"roofline_fraction_rr", r.roofline_fraction_rr},
         {"packing_to_fluid_ratio", r.mflups > 0 ? r.mflups_fluid_packing / r.mflups : 0.0},
         {"threads", r.threads},
         {"last_level_cache_bytes", r.last_level_cache_bytes},
         {"box_edge", r.box_edge},
         {"packing_spheres", r.packing_spheres},
         {"packing_phi", r.packing_phi}});
    return;
  }
  std::cout << fmt::format(
      "all-fluid {}^3   {:.1f} MLUPS (double, TRT, {} threads; >= 4x the "
      "{:.0f} MiB last-level cache)\n",
      r.box_edge, r.mflups, r.threads, r.last_level_cache_bytes / 1048576.0);
  std::cout << fmt::format(
      "phi = {} packing {:.1f} MFLUPS (fluid nodes), {:.2f} x all-fluid "
      "(goal >= 0.8)\n",
      r.packing_phi, r.mflups_fluid_packing,
      r.mflups > 0 ? r.mflups_fluid_packing / r.mflups : 0.0);
  std::cout << fmt::format("  same, halfway bounce-back {:.1f} MFLUPS, {:.2f} x all-fluid\n",
                           r.mflups_fluid_packing_bb,
                           r.mflups > 0 ? r.mflups_fluid_packing_bb / r.mflups : 0.0);
  std::cout << fmt::format(
      "blocks-8 100^3    {:.1f} MFLUPS interpolated path, {:.1f} halfway bounce-back (RRZE "
      "lbm-benchmark-kernels' porous geometry, {} fluid nodes)\n",
      r.mflups_blocks, r.mflups_blocks_bb, r.blocks_fluid_nodes);
  std::cout << fmt::format(
      "rr                {:.1f} MLUPS all-fluid ({:.2f} of the roofline), {:.1f} MFLUPS on the "
      "packing (interpolated walls with TRT's wall correction)\n",
      r.mflups_rr, r.roofline_fraction_rr, r.mflups_fluid_packing_rr);
  std::cout << fmt::format("bandwidth         {:.1f} GB/s (in-place update kernel)\n",
                           r.bandwidth_gbs);
  std::cout << fmt::format(
      "roofline          {:.2f} of bandwidth/304 B = {:.0f} MLUPS (goal >= "
      "0.8)\n",
      r.roofline_fraction, r.bandwidth_gbs * 1e3 / 304.0);
}

void run_convergence_command(const CliContext& ctx, const ConvergenceCommand& c) {
  const lbm::RunOptions options = run_options(c.solver);
  const Case the_case = load_case(c.case_options);
  lbm::ConvergenceOptions co;
  co.packing = the_case.packing;
  co.run = options;
  co.resolutions = core::parse_number_list(c.d_list, "--d");
  co.schemes.clear();
  {
    std::size_t start = 0;
    while (start <= c.schemes.size()) {
      const std::size_t comma = c.schemes.find(',', start);
      const std::string item =
          c.schemes.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      co.schemes.push_back(lbm::scheme_from_string(item));  // Error(kInvalidArgument): exit 2
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  if (!std::isnan(c.reference)) {
    if (!std::isfinite(c.reference) || c.reference <= 0.0 || c.reference > kMaxReferenceF) {
      throw UsageError(fmt::format("--reference = {} is outside (0, {:g}] (a drag F)",
                                   format_number(c.reference), kMaxReferenceF));
    }
    co.reference_F = c.reference;
  }
  for (double d : co.resolutions) lbm::check_run_size(the_case.packing, d, options, "--d");
  std::string error;
  if (!co.IsValid(&error)) throw UsageError(error);
  std::string tool;
  if (!c.plot.empty()) {
    core::check_output_file(c.plot, "--plot");
    tool = workflows::convergence_plot_tool();
    if (tool.empty()) {
      throw std::runtime_error(
          "--plot needs gnuplot (Debian package gnuplot-nox) or matplotlib for /usr/bin/python3 "
          "(python3-matplotlib); neither was found");
    }
  }

  ProgressLine progress(!ctx.quiet);
  const lbm::ConvergenceResult r = lbm::run_convergence(
      co, [&progress](double f, const std::string&) { progress.update(f, "lbm convergence"); });
  progress.finish();

  const std::string title = fmt::format("{}, Re = {}: error vs wall time (reference: {})",
                                        the_case.description, c.solver.re, r.reference_source);
  // As with lbm run's fields: a plot that fails is reported after the table, never instead.
  std::string plot_error;
  if (!c.plot.empty()) {
    try {
      workflows::write_convergence_plot(c.plot, tool, r, title);
    } catch (const std::exception& e) {
      plot_error = e.what();
    }
  }

  if (ctx.json) {
    nlohmann::json schemes = nlohmann::json::array();
    for (const auto& sc : r.schemes) {
      nlohmann::json points = nlohmann::json::array();
      for (const auto& p : sc.points) {
        points.push_back({{"d_requested", p.d_requested},
                          {"d", p.d},
                          {"dims", p.dims},
                          {"converged", p.converged},
                          {"diagnosis", p.diagnosis},
                          {"F", number_or_null(p.F)},
                          {"error", number_or_null(p.error)},
                          {"error_estimate", number_or_null(p.error_estimate)},
                          {"wall_s", p.wall_s},
                          {"steps", p.steps},
                          {"mflups", p.mflups}});
      }
      schemes.push_back({{"scheme", sc.scheme.name()},
                         {"order", number_or_null(sc.order)},
                         {"richardson",
                          {{"ok", sc.richardson.ok},
                           {"F_inf", number_or_null(sc.richardson.F_inf)},
                           {"order", number_or_null(sc.richardson.order)},
                           {"note", sc.richardson.note}}},
                         {"points", points}});
    }
    nlohmann::json j = {{"case", the_case.description},
                        {"phi", r.phi},
                        {"re", r.re},
                        {"reference_F", number_or_null(r.reference_F)},
                        {"reference_source", r.reference_source},
                        {"reference_spread", number_or_null(r.reference_spread)},
                        {"wall_s", r.wall_s},
                        {"schemes", schemes}};
    if (!c.plot.empty()) j["plot"] = plot_error.empty() ? nlohmann::json(c.plot) : nullptr;
    if (!plot_error.empty()) j["plot_error"] = plot_error;
    ctx.print_json(j);
  } else {
    std::cout << the_case.description << "\n" << r.Table();
    if (!c.plot.empty() && plot_error.empty())
      std::cout << fmt::format("plot: {} ({})\n", c.plot, tool);
  }
  if (!plot_error.empty()) {
    throw std::runtime_error("the table above is complete, but the plot was not written: " +
                             plot_error);
  }
}

void run_calibrate(const CliContext& ctx, const CalibrateCommand& c) {
  SolverOptions s = c.solver;
  s.re = 0.0;  // calibration is a Stokes measurement
  lbm::CalibrationOptions co;
  co.run = run_options(s);
  if (std::isnan(c.d)) throw UsageError("--d is required (input sphere diameter, lattice units)");
  co.diameter = c.d;
  co.phi = c.phi;
  co.check_phi = c.check_phi;
  co.positions = c.positions;
  std::string error;
  if (!co.IsValid(&error)) throw UsageError(error);
  ProgressLine progress(!ctx.quiet);
  const lbm::CalibrationResult r = calibrate(
      co, [&progress](double f, const std::string&) { progress.update(f, "lbm calibrate"); });
  progress.finish();
  const lbm::Scheme scheme{co.run.collision, co.run.boundary};
  if (ctx.json) {
    auto check_json = [](const lbm::CalibrationCheck& k) {
      return nlohmann::json{{"phi", k.phi},
                            {"phi_hydrodynamic", k.phi_hydrodynamic},
                            {"F_input", k.F_input},
                            {"F_hydrodynamic", k.F_hydrodynamic},
                            {"F_series", k.F_reference},
                            {"F_series_hydrodynamic", number_or_null(k.F_reference_hydrodynamic)},
                            {"error_input", k.error_input},
                            {"error_hydrodynamic", number_or_null(k.error_hydrodynamic)},
                            {"positions", k.positions},
                            {"F_position_spread", k.F_position_spread},
                            {"steps", k.steps},
                            {"wall_s", k.wall_s}};
    };
    nlohmann::json j = {{"d", r.diameter},
                        {"d_h", r.hydrodynamic_diameter},
                        {"d_h_over_d", r.ratio},
                        {"box_nodes", r.box_nodes},
                        {"scheme", scheme.name()},
                        {"tau", r.calibration.run.tau},
                        {"precision", lbm::to_string(co.run.precision)},
                        {"newton_iterations", r.newton_iterations},
                        {"calibration", check_json(r.calibration)},
                        {"wall_s", r.wall_s}};
    j["check"] = r.has_check ? check_json(r.check) : nlohmann::json(nullptr);
    ctx.print_json(j);
    return;
  }
  std::cout << fmt::format("scheme                {} ({}), tau = {:.4g}\n", scheme.name(),
                           lbm::to_string(co.run.precision), r.calibration.run.tau);
  std::cout << r.Report();
  std::cout << fmt::format("use it                draglab lbm run ... --d {} --d-hydro {:.4f}\n",
                           format_number(c.d), r.ratio * c.d);
}

void add_case_options(CLI::App* cmd, CaseOptions* o) {
  cmd->add_option("--packing", o->packing_file, "Packing HDF5 file (draglab pack)");
  cmd->add_option("--array", o->array, "Ordered array instead: sc, bcc or fcc")
      ->check(CLI::IsMember({"sc", "bcc", "fcc"}));
  cmd->add_option("--phi", o->phi, "Solids fraction of the array, (0, close packing]");
  cmd->add_option("--cells", o->cells, "Unit cells per box edge of the array, [1, 16]")
      ->capture_default_str();
}

void add_solver_options(CLI::App* cmd, SolverOptions* s, bool with_re) {
  if (with_re) {
    cmd->add_option("--re", s->re,
                    "Target Reynolds number U d/nu (superficial), [0, 1000]; 0 = "
                    "Stokes flow (linear equilibrium)");
  }
  if (s->collision == "auto") {
    cmd->add_option("--collision", s->collision,
                    "Collision: auto (trt where kappa Re/d is within what it holds, rr with "
                    "TRT's wall beyond; the result says which and why), bgk (seed baseline), "
                    "trt, rr (regularized, robust at high Re)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "bgk", "trt", "rr"}));
  } else {
    cmd->add_option("--collision", s->collision,
                    "Collision: bgk (seed baseline), trt, rr (regularized, robust at high Re)")
        ->capture_default_str()
        ->check(CLI::IsMember({"bgk", "trt", "rr"}));
  }
  cmd->add_option("--boundary", s->boundary,
                  "Wall: bb (halfway bounce-back) or ibb (interpolated bounce-back with q)")
      ->capture_default_str()
      ->check(CLI::IsMember({"bb", "ibb"}));
  cmd->add_option("--wall-interpolation", s->wall_interpolation,
                  "Interpolated wall: auto (CLI where stable, BFL near tau = 1/2), cli (central "
                  "linear) or bfl (Bouzidi linear)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "cli", "bfl"}));
  cmd->add_option("--rr-wall-correction", s->rr_wall_correction,
                  "rr with interpolated walls: correct the reflected values to TRT's wall at "
                  "--magic (on), or not (off: only to compare; rr's own wall sits about half a "
                  "node off near tau = 1/2)")
      ->capture_default_str()
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--precision", s->precision, "double, or float (shifted populations)")
      ->capture_default_str()
      ->check(CLI::IsMember({"double", "float"}));
  cmd->add_option("--tau", s->tau,
                  "Relaxation time (> 1/2); 0 = choose from Re and the Mach "
                  "budget")
      ->capture_default_str();
  cmd->add_option("--magic", s->magic, "TRT magic parameter Lambda")->capture_default_str();
  cmd->add_option("--mach", s->mach,
                  "Finite Re: Mach target max|u| sqrt(3), (0, 0.3]; U = Mach c_s / kappa with "
                  "kappa = u_max/U measured by a short Stokes run")
      ->capture_default_str();
  cmd->add_option("--average-time", s->average_time,
                  "Unsteady flow: average F over at least this many d/U after the start-up, "
                  "[1, 10000]")
      ->capture_default_str()
      ->each([s](const std::string&) { s->average_time_given = true; });
  cmd->add_option("--average-tolerance", s->average_tolerance,
                  "Unsteady flow: converged when the standard error of the time-averaged F is "
                  "below this (relative), [1e-4, 0.1]")
      ->capture_default_str();
  cmd->add_option("--max-steps", s->max_steps, "Step limit (reaching it = not converged)")
      ->capture_default_str();
  cmd->add_option("--tolerance", s->tolerance,
                  "Relative drag change per characteristic time at convergence")
      ->capture_default_str();
  cmd->add_option("--threads", s->threads, "OpenMP threads (0 = all)")->capture_default_str();
  cmd->add_option("--min-gap-nodes", s->min_gap_nodes,
                  "Refuse packings whose smallest sphere gap spans fewer lattice units (0 = off: "
                  "sub-node gaps are run and reported)")
      ->capture_default_str();
}

}  // namespace

void add_lbm_commands(CLI::App& app, CliContext& ctx) {
  CLI::App* lbm = app.add_subcommand(
      "lbm", "Lattice-Boltzmann drag on fixed sphere arrays: run, bench, convergence, calibrate");
  lbm->require_subcommand(1);
  lbm->footer(
      "Examples:\n"
      "  draglab lbm run --array sc --phi 0.125 --d 16 --re 0\n"
      "  draglab lbm run --packing p.h5 --d 24 --re 10 --fields flow.h5 --json\n"
      "  draglab lbm bench --json\n"
      "  draglab lbm convergence --array sc --phi 0.125 --re 0 --d 8,12,16,24 --plot wp.png\n"
      "  draglab lbm calibrate --d 12 --collision trt --boundary bb");

  auto rc = std::make_shared<RunCommand>();
  auto* run = lbm->add_subcommand(
      "run", "Steady flow through a packing or array; drag F, K, beta with an error estimate");
  add_case_options(run, &rc->case_options);
  run->add_option("--d", rc->d,
                  "Resolution: lattice units per (reference) sphere diameter, "
                  "[4, 512]");
  add_solver_options(run, &rc->solver, true);
  run->add_option("--fields", rc->fields,
                  "Write velocity, density and solid mask to this HDF5 file, plus a .xmf file "
                  "for ParaView");
  run->add_option("--d-hydro", rc->d_hydro,
                  "Normalise with this hydrodynamic diameter (lattice units; draglab lbm "
                  "calibrate), [0.5 d, 1.5 d]")
      ->each([rc](const std::string&) { rc->d_hydro_given = true; });
  run->add_option("--checkpoint", rc->checkpoint,
                  "Checkpoint file: the run resumes from it if it exists (the same run), "
                  "rewrites it every --checkpoint-interval seconds and when --max-steps stops "
                  "it (run again with a larger --max-steps to go on), and removes it at the end");
  run->add_option("--checkpoint-interval", rc->checkpoint_interval,
                  "Seconds between checkpoints, [0, 1e6] (0: at every convergence check)")
      ->capture_default_str();
  run->add_flag("--calibrate", rc->calibrate,
                "Calibrate d_h first (dilute SC array, same d, scheme and tau) and normalise "
                "with it");
  run->footer(
      "Output: F = F_d/(3 pi mu d U) drag only, K = F/(1 - phi), beta d^2/mu, Re = U d/nu\n"
      "(U superficial), the achieved Re, momentum balance, max Mach number, an error\n"
      "estimate, wall time and MFLUPS. A run that does not converge exits 1 without a drag.\n"
      "Examples:\n"
      "  draglab lbm run --array sc --phi 0.125 --d 16 --re 0 --json\n"
      "  draglab lbm run --packing p.h5 --d 20 --re 50 --collision trt --boundary ibb\n"
      "  draglab lbm run --array fcc --phi 0.5 --d 24 --re 100 --collision rr\n"
      "  draglab lbm run --array sc --phi 0.5235987755982988 --d 24 --re 0   # touching\n"
      "  draglab lbm run --array sc --phi 0.2 --d 12 --re 0 --boundary bb --calibrate\n"
      "  draglab lbm run --array sc --phi 0.1 --d 16 --re 0 --fields flow.h5\n"
      "  draglab lbm run --packing p.h5 --d 48 --re 300 --checkpoint p_d48.ckpt   # resumable\n"
      "  mpirun -np 4 draglab lbm run --packing p.h5 --d 64 --re 100   # one box on 4 ranks");
  run->callback([&ctx, rc] {
    ctx.runs_on_ranks = true;  // the ranks share the box
    ctx.action = [&ctx, rc] { run_lbm(ctx, *rc); };
  });

  auto bc = std::make_shared<BenchCommand>();
  auto* bench = lbm->add_subcommand(
      "bench",
      "MLUPS (100^3 fluid box), MFLUPS (random packing, phi 0.4 unless --phi), bandwidth, "
      "roofline fraction");
  bench->add_option("--threads", bc->threads, "OpenMP threads (0 = all)")->capture_default_str();
  bench->add_option("--phi", bc->phi, "Solid fraction of the random packing (d 16), [0.1, 0.6]")
      ->capture_default_str();
  bench->add_option("--repeat", bc->repeat, "Repetitions (median)")->capture_default_str();
  bench->footer(
      "roofline_fraction = MLUPS / (bandwidth / 304 bytes): 1 is the in-place D3Q19 double\n"
      "limit of this machine's memory.\n"
      "Example:\n  draglab lbm bench --json");
  bench->callback([&ctx, bc] { ctx.action = [&ctx, bc] { run_bench(ctx, *bc); }; });

  auto cc = std::make_shared<ConvergenceCommand>();
  auto* conv = lbm->add_subcommand("convergence",
                                   "Resolution sweep: error against wall time for several schemes");
  add_case_options(conv, &cc->case_options);
  add_solver_options(conv, &cc->solver, true);
  conv->add_option("--d", cc->d_list, "Resolutions, comma-separated, each in [4, 256]")
      ->capture_default_str();
  conv->add_option("--schemes", cc->schemes,
                   "Schemes COLLISION-BOUNDARY, comma-separated (bgk|trt|rr)-(bb|ibb)")
      ->capture_default_str();
  conv->add_option("--reference", cc->reference,
                   "Reference F (default: Sangani-Acrivos for SC Stokes, else Richardson)");
  conv->add_option("--plot", cc->plot, "PNG of error vs wall time (gnuplot or matplotlib)");
  conv->footer(
      "Reference: the Sangani-Acrivos series for an SC array in Stokes flow (phi <= 0.22),\n"
      "otherwise Richardson extrapolation d -> infinity with its measured order.\n"
      "Examples:\n"
      "  draglab lbm convergence --array sc --phi 0.125 --re 0 --d 8,12,16,24 --plot wp.png\n"
      "  draglab lbm convergence --packing p.h5 --re 10 --d 12,16,24 --schemes trt-bb,trt-ibb "
      "--json");
  conv->callback([&ctx, cc] { ctx.action = [&ctx, cc] { run_convergence_command(ctx, *cc); }; });

  auto kc = std::make_shared<CalibrateCommand>();
  auto* cal = lbm->add_subcommand(
      "calibrate",
      "Hydrodynamic diameter d_h of a scheme at a resolution (dilute SC array vs "
      "Sangani-Acrivos)");
  cal->add_option("--d", kc->d, "Input sphere diameter, lattice units, [4, 128]");
  kc->solver.boundary = "bb";  // the calibration is meant for halfway bounce-back
  add_solver_options(cal, &kc->solver, false);
  cal->add_option("--phi", kc->phi, "Solids fraction of the dilute SC array, [0.001, 0.05]")
      ->capture_default_str();
  cal->add_option("--positions", kc->positions,
                  "Sub-grid sphere positions averaged over, [1, 64] (bounce-back drag depends on "
                  "them)")
      ->capture_default_str();
  cal->add_option("--check-phi", kc->check_phi,
                  "Also run an SC array at this phi (<= 0.22) and compare with d and d_h")
      ->capture_default_str();
  cal->footer(
      "d_h is the diameter for which the Sangani-Acrivos series reproduces the measured Stokes\n"
      "drag of a dilute SC array; it depends on d, tau and the scheme. Use it with\n"
      "draglab lbm run --d-hydro, or let run --calibrate do both.\n"
      "Examples:\n"
      "  draglab lbm calibrate --d 12\n"
      "  draglab lbm calibrate --d 16 --collision bgk --tau 1 --check-phi 0.125 --json");
  cal->callback([&ctx, kc] { ctx.action = [&ctx, kc] { run_calibrate(ctx, *kc); }; });
}

}  // namespace cli
}  // namespace draglab
