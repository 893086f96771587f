// options.cc: enum names, option validation and the text reports of a run.
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {
namespace {

using core::format_fixed;

}  // namespace

const char* to_string(Collision c) {
  switch (c) {
    case Collision::kBgk:
      return "bgk";
    case Collision::kTrt:
      return "trt";
    case Collision::kRegularized:
      return "rr";
    case Collision::kAuto:
      return "auto";
  }
  return "?";
}

Collision collision_from_string(const std::string& s) {
  if (s == "bgk") return Collision::kBgk;
  if (s == "trt") return Collision::kTrt;
  if (s == "rr" || s == "regularized") return Collision::kRegularized;
  if (s == "auto") return Collision::kAuto;
  throw Error(ErrorCode::kInvalidArgument,
              "unknown collision model '" + s + "' (allowed: auto, bgk, trt, rr)");
}

const char* to_string(Boundary b) {
  switch (b) {
    case Boundary::kHalfwayBounceBack:
      return "bb";
    case Boundary::kInterpolated:
      return "ibb";
  }
  return "?";
}

Boundary boundary_from_string(const std::string& s) {
  if (s == "bb") return Boundary::kHalfwayBounceBack;
  if (s == "ibb") return Boundary::kInterpolated;
  throw Error(ErrorCode::kInvalidArgument,
              "unknown boundary scheme '" + s + "' (allowed: bb, ibb)");
}

const char* to_string(WallInterpolation w) {
  switch (w) {
    case WallInterpolation::kAuto:
      return "auto";
    case WallInterpolation::kCentral:
      return "cli";
    case WallInterpolation::kBouzidi:
      return "bfl";
  }
  return "?";
}

WallInterpolation wall_interpolation_from_string(const std::string& s) {
  if (s == "auto") return WallInterpolation::kAuto;
  if (s == "cli") return WallInterpolation::kCentral;
  if (s == "bfl") return WallInterpolation::kBouzidi;
  throw Error(ErrorCode::kInvalidArgument,
              "unknown wall interpolation '" + s + "' (allowed: auto, cli, bfl)");
}

const char* to_string(Precision p) {
  switch (p) {
    case Precision::kDouble:
      return "double";
    case Precision::kFloat:
      return "float";
  }
  return "?";
}

Precision precision_from_string(const std::string& s) {
  if (s == "double") return Precision::kDouble;
  if (s == "float") return Precision::kFloat;
  throw Error(ErrorCode::kInvalidArgument,
              "unknown precision '" + s + "' (allowed: double, float)");
}

bool RunOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (collision != Collision::kBgk && collision != Collision::kTrt &&
      collision != Collision::kRegularized && collision != Collision::kAuto) {
    return fail("collision: unknown model (allowed: auto, bgk, trt, rr)");
  }
  if (boundary != Boundary::kHalfwayBounceBack && boundary != Boundary::kInterpolated) {
    return fail("boundary: unknown scheme (allowed: bb, ibb)");
  }
  if (interpolation != WallInterpolation::kAuto && interpolation != WallInterpolation::kCentral &&
      interpolation != WallInterpolation::kBouzidi) {
    return fail("interpolation: unknown wall interpolation (allowed: auto, cli, bfl)");
  }
  if (precision != Precision::kDouble && precision != Precision::kFloat) {
    return fail("precision: unknown (allowed: double, float)");
  }
  if (!(std::isfinite(magic) && magic > 0.0 && magic <= 10.0)) {
    return fail("magic: TRT Lambda must be in (0, 10], got " + format_fixed("%g", magic));
  }
  if (!(std::isfinite(re) && re >= 0.0 && re <= kMaxReynolds)) {
    return fail("re: must be in [0, " + format_fixed("%g", kMaxReynolds) + "], got " +
                format_fixed("%g", re));
  }
  if (!(std::isfinite(tau) && (tau == 0.0 || (tau > 0.5 && tau <= 100.0)))) {
    return fail("tau: must be 0 (automatic) or in (0.5, 100], got " + format_fixed("%g", tau));
  }
  if (stokes_mode != StokesMode::kAuto && stokes_mode != StokesMode::kOn &&
      stokes_mode != StokesMode::kOff) {
    return fail("stokes_mode: unknown value");
  }
  if (!(std::isfinite(re_tolerance) && re_tolerance > 0.0 && re_tolerance <= 0.5)) {
    return fail("re_tolerance: must be in (0, 0.5], got " + format_fixed("%g", re_tolerance));
  }
  if (!(std::isfinite(tolerance) && tolerance >= 1e-12 && tolerance <= 0.1)) {
    return fail("tolerance: must be in [1e-12, 0.1], got " + format_fixed("%g", tolerance));
  }
  if (max_steps < 2) return fail("max_steps: must be >= 2");
  if (!(std::isfinite(mach_limit) && mach_limit > 0.0 && mach_limit <= 1.0)) {
    return fail("mach_limit: must be in (0, 1], got " + format_fixed("%g", mach_limit));
  }
  if (!(std::isfinite(mach_target) && mach_target > 0.0 && mach_target <= 0.3)) {
    return fail("mach_target: must be in (0, 0.3], got " + format_fixed("%g", mach_target));
  }
  if (!(std::isfinite(average_tolerance) && average_tolerance >= 1e-4 &&
        average_tolerance <= 0.1)) {
    return fail("average_tolerance: must be in [1e-4, 0.1], got " +
                format_fixed("%g", average_tolerance));
  }
  if (!(std::isfinite(average_time) && average_time >= 1.0 && average_time <= 1e4)) {
    return fail("average_time: must be in [1, 10000] d/U, got " + format_fixed("%g", average_time));
  }
  if (!(std::isfinite(min_gap_nodes) && min_gap_nodes >= 0.0 && min_gap_nodes <= 100.0)) {
    return fail("min_gap_nodes: must be in [0, 100], got " + format_fixed("%g", min_gap_nodes));
  }
  if (use_hydrodynamic_diameter &&
      !(std::isfinite(hydrodynamic_diameter) && hydrodynamic_diameter > 0.0)) {
    return fail("hydrodynamic_diameter: must be > 0 (lattice units) when it is used, got " +
                format_fixed("%g", hydrodynamic_diameter));
  }
  if (threads < 0 || threads > 4096) return fail("threads: must be in [0, 4096] (0 = all)");
  if (!(std::isfinite(checkpoint_interval) && checkpoint_interval >= 0.0 &&
        checkpoint_interval <= 1e6)) {
    return fail("checkpoint_interval: must be in [0, 1e6] seconds, got " +
                format_fixed("%g", checkpoint_interval));
  }
  return true;
}

std::string RunResult::BriefReport() const {
  std::ostringstream out;
  if (converged) {
    out << "F = " << format_fixed("%.6g", F) << " (K = " << format_fixed("%.6g", K)
        << ", beta d^2/mu = " << format_fixed("%.6g", beta_d2_over_mu) << ") +- "
        << format_fixed("%.2g", error_estimate * 100.0) << " % at Re = " << format_fixed("%.4g", re)
        << ", phi = " << format_fixed("%.4g", phi) << ", d = " << format_fixed("%.4g", d) << "; "
        << steps << " steps, " << format_fixed("%.3g", wall_s) << " s, "
        << format_fixed("%.4g", mflups) << " MFLUPS";
  } else {
    out << "not converged after " << steps << " steps (" << format_fixed("%.3g", wall_s)
        << " s): " << diagnosis;
  }
  return out.str();
}

std::string RunResult::FullReport() const {
  std::ostringstream out;
  out << "converged            " << (converged ? "yes" : "no") << "\n";
  if (!diagnosis.empty()) out << "diagnosis            " << diagnosis << "\n";
  out << "F (drag only)        " << format_fixed("%.8g", F) << " +- "
      << format_fixed("%.3g", F_standard_error) << " (spread over " << body_F.size()
      << " bodies)\n";
  if (unsteady) {
    out << "unsteady             F +- " << format_fixed("%.3g", F_time_error) << ", Re "
        << format_fixed("%.6g", re) << " +- " << format_fixed("%.3g", re_standard_error)
        << " (time means over " << averaging_steps
        << " steps = " << format_fixed("%.3g", averaging_time) << " d/U after " << startup_steps
        << " steps; " << averaging_restarts << " restarts)\n";
  }
  out << "K = F/(1-phi)        " << format_fixed("%.8g", K) << "\n"
      << "beta d^2/mu          " << format_fixed("%.8g", beta_d2_over_mu) << "\n"
      << "error estimate       " << format_fixed("%.3g", error_estimate) << " (convergence "
      << format_fixed("%.3g", convergence_residual) << ", discretisation "
      << format_fixed("%.3g", discretisation_error) << ")\n"
      << "Re (achieved)        " << format_fixed("%.6g", re)
      << (stokes_mode ? "  [Stokes mode]" : "") << " (" << force_adjustments
      << " corrections of the force)\n"
      << "phi / phi_lattice    " << format_fixed("%.6g", phi) << " / "
      << format_fixed("%.6g", phi_lattice) << "\n"
      << "d (lattice units)    " << format_fixed("%.6g", d) << "\n"
      << "tau+ / tau-          " << format_fixed("%.6g", tau) << " / "
      << format_fixed("%.6g", tau_minus) << "  (nu = " << format_fixed("%.6g", nu) << ")\n"
      << (pore_speed_ratio > 0.0
              ? "velocity plan        kappa = u_max/U = " + format_fixed("%.4g", pore_speed_ratio) +
                    (pore_speed_ratio_measured ? " (measured)" : " (estimated)") +
                    ", Mach target " + format_fixed("%g", mach_target) +
                    ", Re_cell = kappa Re/d = " + format_fixed("%.3g", cell_reynolds) + " (limit " +
                    format_fixed("%g", cell_reynolds_limit) +
                    "; at the end max|u|/nu = " + format_fixed("%.3g", final_cell_reynolds) +
                    ", kappa " + format_fixed("%.3g", final_pore_speed_ratio) + ")\n"
              : std::string())
      << "collision            " << to_string(collision)
      << (collision_reason.empty() ? std::string() : " (auto: " + collision_reason + ")") << "\n"
      << "wall                 " << wall
      << (wall_reason.empty() ? std::string() : " (" + wall_reason + ")") << "\n"
      << "body force           " << format_fixed("%.6g", body_force) << "\n"
      << "superficial U        " << format_fixed("%.6g", superficial_velocity) << "\n"
      << "Mach (max)           " << format_fixed("%.4g", mach_max) << "\n"
      << "momentum balance     " << format_fixed("%.3g", momentum_balance_rel) << " (relative)\n"
      << "mass change          " << format_fixed("%.3g", mass_change_rel) << " (relative)\n"
      << "sub-node gaps        " << narrow_gap_pairs << " sphere pairs below one node (smallest "
      << format_fixed("%.3g", smallest_gap_nodes) << "), "
      << format_fixed("%.3g", 100.0 * narrow_gap_fluid_fraction)
      << " % of fluid nodes in one-node gaps\n"
      << "fluid nodes / links  " << fluid_nodes << " / " << boundary_links << " (" << fallback_links
      << " interpolation fallbacks)\n"
      << "steps                " << steps << " (characteristic time " << characteristic_steps
      << " steps)\n"
      << "wall time            " << format_fixed("%.4g", wall_s) << " s, "
      << format_fixed("%.4g", mflups) << " MFLUPS, "
      << format_fixed("%.4g", static_cast<double>(memory_bytes) / 1048576.0) << " MiB"
      << (ranks > 1 ? " on " + std::to_string(ranks) + " ranks" : std::string()) << "\n";
  if (resumed_from_step > 0 || checkpoints_written > 0) {
    out << "checkpoint           "
        << (resumed_from_step > 0
                ? "resumed at step " + std::to_string(resumed_from_step) +
                      " (the earlier parts: " + format_fixed("%.4g", earlier_parts_wall_s) + " s)"
                : std::string("started afresh"))
        << ", " << checkpoints_written << " written\n";
  }
  for (const std::string& w : warnings) out << "warning              " << w << "\n";
  if (!history.empty()) {
    out << "history (last points): step, F, Re, relative change per characteristic time\n";
    const std::size_t first = history.size() > 10 ? history.size() - 10 : 0;
    for (std::size_t i = first; i < history.size(); ++i) {
      out << "  " << history[i].step << "  " << format_fixed("%.10g", history[i].F) << "  "
          << format_fixed("%.6g", history[i].re) << "  "
          << format_fixed("%.3g", history[i].relative_change) << "\n";
    }
  }
  return out.str();
}

std::string RunResult::ToJson(const RunOptions& o) const {
  nlohmann::json j = {{"F", F},
                      {"K", K},
                      {"beta_d2_over_mu", beta_d2_over_mu},
                      {"F_standard_error", F_standard_error},
                      {"re", re},
                      {"phi", phi},
                      {"phi_lattice", phi_lattice},
                      {"converged", converged},
                      {"diagnosis", diagnosis},
                      {"steps", steps},
                      {"wall_s", wall_s},
                      {"mflups", mflups},
                      {"momentum_balance_rel", momentum_balance_rel},
                      {"mass_change_rel", mass_change_rel},
                      {"mach_max", mach_max},
                      {"error_estimate", error_estimate},
                      {"convergence_residual", convergence_residual},
                      {"discretisation_error", discretisation_error},
                      {"d", d},
                      {"tau", tau},
                      {"tau_minus", tau_minus},
                      {"nu", nu},
                      {"body_force", body_force},
                      {"superficial_velocity", superficial_velocity},
                      {"stokes_mode", stokes_mode},
                      {"fluid_nodes", fluid_nodes},
                      {"collision", to_string(collision)},
                      {"boundary", to_string(o.boundary)},
                      {"wall", wall},
                      {"wall_corrected", wall_corrected},
                      {"pore_speed_ratio", pore_speed_ratio},
                      {"pore_speed_ratio_measured", pore_speed_ratio_measured},
                      {"mach_target", mach_target},
                      {"cell_reynolds", cell_reynolds},
                      {"cell_reynolds_limit", cell_reynolds_limit},
                      {"final_pore_speed_ratio", final_pore_speed_ratio},
                      {"final_cell_reynolds", final_cell_reynolds},
                      {"resolution_needed", resolution_needed},
                      {"unsteady", unsteady},
                      {"F_time_error", F_time_error},
                      {"re_standard_error", re_standard_error},
                      {"averaging_steps", averaging_steps},
                      {"averaging_time", averaging_time},
                      {"startup_steps", startup_steps},
                      {"averaging_restarts", averaging_restarts},
                      {"force_adjustments", force_adjustments},
                      {"precision", to_string(o.precision)},
                      {"narrow_gap_pairs", narrow_gap_pairs},
                      {"smallest_gap_nodes", smallest_gap_nodes},
                      {"narrow_gap_fluid_fraction", narrow_gap_fluid_fraction},
                      {"fallback_links", fallback_links},
                      {"boundary_links", boundary_links},
                      {"warnings", warnings}};
  if (collision == Collision::kTrt) j["magic"] = o.magic;
  if (o.collision == Collision::kAuto) {  // a run that named its operator keeps its record
    j["collision_requested"] = to_string(o.collision);
    j["collision_reason"] = collision_reason;
  }
  if (ranks > 1) j["ranks"] = ranks;  // a one-rank run's record stays as it always was
  if (!o.checkpoint.empty()) {
    j["resumed_from_step"] = resumed_from_step;
    j["earlier_parts_wall_s"] = earlier_parts_wall_s;
    j["checkpoints_written"] = checkpoints_written;
  }
  j["d_hydrodynamic"] =
      o.use_hydrodynamic_diameter ? nlohmann::json(o.hydrodynamic_diameter) : nlohmann::json();
  // JSON has no NaN: what a failed run did not measure is null.
  for (auto& [key, value] : j.items()) {
    if (value.is_number_float() && !std::isfinite(value.get<double>())) value = nullptr;
  }
  return j.dump();
}

}  // namespace lbm
}  // namespace draglab
