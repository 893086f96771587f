// Resolution sweeps: error against wall time per scheme, analytical or Richardson reference.
#include "draglab/lbm/convergence.h"
#include "draglab/core/text.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "draglab/arrays/voxelization.h"
#include "draglab/error.h"
#include "draglab/lbm/calibration.h"

namespace draglab {
namespace lbm {
namespace {

using core::format_fixed;

constexpr double kMinOrder = 0.05, kMaxOrder = 8.0;  // orders Richardson may report

/// The realised resolution: the voxelizer rounds d * box_x to whole nodes.
double realised_resolution(const arrays::Packing& p, double d) {
  const double nodes = std::max(1.0, std::round(d * p.box_length[0]));
  return nodes / p.box_length[0];
}

}  // namespace

std::string Scheme::name() const {
  return std::string(to_string(collision)) + "-" + to_string(boundary);
}

Scheme scheme_from_string(const std::string& s) {
  const std::size_t dash = s.find('-');
  const std::string accepted =
      "accepted: COLLISION-BOUNDARY with COLLISION bgk, trt or rr and BOUNDARY bb or ibb, e.g. "
      "trt-ibb";
  if (dash == std::string::npos) {
    throw Error(ErrorCode::kInvalidArgument, "unknown scheme '" + s + "' (" + accepted + ")");
  }
  Scheme scheme;
  try {
    scheme.collision = collision_from_string(s.substr(0, dash));
    scheme.boundary = boundary_from_string(s.substr(dash + 1));
  } catch (const Error&) {
    throw Error(ErrorCode::kInvalidArgument, "unknown scheme '" + s + "' (" + accepted + ")");
  }
  return scheme;
}

std::vector<Scheme> default_schemes() {
  return {{Collision::kBgk, Boundary::kHalfwayBounceBack},
          {Collision::kTrt, Boundary::kHalfwayBounceBack},
          {Collision::kTrt, Boundary::kInterpolated}};
}

double analytical_reference_F(const arrays::Packing& packing, double re) {
  const double nan = std::nan("");
  if (re != 0.0 || packing.size() != 1) return nan;
  const auto& b = packing.box_length;
  if (std::fabs(b[1] - b[0]) > 1e-12 * b[0] || std::fabs(b[2] - b[0]) > 1e-12 * b[0]) return nan;
  const double phi = packing.phi();
  if (!(phi > 0.0) || phi > kSanganiAcrivosMaxPhi) return nan;
  return sangani_acrivos_sc_F(phi);
}

namespace {

/// Three-point Richardson through (d1, F1), (d2, F2), (d3, F3), d1 < d2 < d3.
RichardsonEstimate three_point(double d1, double F1, double d2, double F2, double d3, double F3) {
  RichardsonEstimate e;
  const double h1 = 1.0 / d1, h2 = 1.0 / d2, h3 = 1.0 / d3;
  if (F2 == F3) {
    if (F1 == F2) {  // already exact at every resolution
      e.ok = true;
      e.F_inf = F3;
      e.order = std::numeric_limits<double>::infinity();
      return e;
    }
    e.note = "the two finest resolutions give the same F";
    return e;
  }
  const double ratio = (F1 - F2) / (F2 - F3);
  // g(p) = (h1^p - h2^p)/(h2^p - h3^p) increases with p for h1 > h2 > h3 > 0.
  auto g = [&](double p) {
    return (std::pow(h1, p) - std::pow(h2, p)) / (std::pow(h2, p) - std::pow(h3, p));
  };
  double lo = kMinOrder, hi = kMaxOrder;
  if (!(ratio > 0.0)) {
    e.note = "non-monotone convergence (the F differences change sign)";
    return e;
  }
  if (ratio < g(lo) || ratio > g(hi)) {
    e.note = format_fixed("measured order outside [%g, %g]", lo, hi);
    return e;
  }
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) < ratio ? lo : hi) = mid;
  }
  const double p = 0.5 * (lo + hi);
  const double C = (F2 - F3) / (std::pow(h2, p) - std::pow(h3, p));
  e.ok = true;
  e.order = p;
  e.F_inf = F3 - C * std::pow(h3, p);
  return e;
}

/// Least squares of F = F_inf + C d^-p over all points: for each p the fit is linear in (F_inf,
/// C); p minimises the residual (scan, then golden-section refinement). Fails when the best p
/// lies on the boundary of [kMinOrder, kMaxOrder] (no convergence visible).
RichardsonEstimate least_squares(const std::vector<std::pair<double, double>>& pts) {
  auto fit = [&](double p, double* F_inf) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = static_cast<double>(pts.size());
    for (const auto& [d, F] : pts) {
      const double x = std::pow(d, -p);
      sx += x;
      sy += F;
      sxx += x * x;
      sxy += x * F;
    }
    const double C = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    const double a = (sy - C * sx) / n;
    double ssr = 0;
    for (const auto& [d, F] : pts) ssr += std::pow(F - a - C * std::pow(d, -p), 2);
    if (F_inf) *F_inf = a;
    return ssr;
  };
  double best_p = kMinOrder, best = std::numeric_limits<double>::infinity();
  for (double p = kMinOrder; p <= kMaxOrder + 1e-12; p += 0.05) {
    const double r = fit(p, nullptr);
    if (r < best) {
      best = r;
      best_p = p;
    }
  }
  RichardsonEstimate e;
  if (best_p <= kMinOrder + 1e-9 || best_p >= kMaxOrder - 1e-9) {
    e.note = format_fixed("least-squares order at the bound of [%g, %g]", kMinOrder, kMaxOrder);
    return e;
  }
  double a = std::max(kMinOrder, best_p - 0.05), b = std::min(kMaxOrder, best_p + 0.05);
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int i = 0; i < 100 && b - a > 1e-10; ++i) {
    const double c = b - golden * (b - a), d = a + golden * (b - a);
    if (fit(c, nullptr) < fit(d, nullptr)) {
      b = d;
    } else {
      a = c;
    }
  }
  e.ok = true;
  e.order = 0.5 * (a + b);
  fit(e.order, &e.F_inf);
  e.note = format_fixed("least-squares fit over %g points", static_cast<double>(pts.size()));
  return e;
}

}  // namespace

RichardsonEstimate richardson_extrapolate(const std::vector<double>& d,
                                          const std::vector<double>& F) {
  std::vector<std::pair<double, double>> pts;
  for (std::size_t i = 0; i < d.size() && i < F.size(); ++i) {
    if (d[i] > 0.0 && std::isfinite(d[i]) && std::isfinite(F[i])) pts.emplace_back(d[i], F[i]);
  }
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end(),
                        [](const auto& a, const auto& b) { return a.first == b.first; }),
            pts.end());
  if (pts.size() < 3) {
    RichardsonEstimate e;
    e.note = "needs three converged resolutions";
    return e;
  }
  const std::size_t n = pts.size();
  RichardsonEstimate e = three_point(pts[n - 3].first, pts[n - 3].second, pts[n - 2].first,
                                     pts[n - 2].second, pts[n - 1].first, pts[n - 1].second);
  if (e.ok || n < 4) return e;
  // Staircase geometry makes F(d) irregular; with four or more points a least-squares fit of
  // the same model is more robust than three exact points.
  RichardsonEstimate fallback = least_squares(pts);
  fallback.note = "three finest points: " + e.note + "; " + fallback.note;
  return fallback;
}

double fitted_order(const std::vector<double>& d, const std::vector<double>& error) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < d.size() && i < error.size(); ++i) {
    if (d[i] > 0.0 && std::isfinite(error[i]) && error[i] != 0.0) {
      x.push_back(std::log(d[i]));
      y.push_back(std::log(std::fabs(error[i])));
    }
  }
  if (x.size() < 2) return std::nan("");
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  if (sxx == 0.0) return std::nan("");
  return -sxy / sxx;
}

bool ConvergenceOptions::IsValid(std::string* error) const {
  std::string e;
  if (packing.size() == 0) {
    e = "convergence: the packing has no spheres";
  } else if (resolutions.empty()) {
    e = "convergence: no resolutions given";
  } else if (schemes.empty()) {
    e = "convergence: no schemes given";
  } else if (!std::isnan(reference_F) && !(reference_F > 0.0 && std::isfinite(reference_F))) {
    e = format_fixed("convergence: reference F = %g must be finite and > 0", reference_F);
  }
  for (double d : resolutions) {
    if (!e.empty()) break;
    if (!std::isfinite(d) || d < 4.0 || d > 256.0) {
      e = format_fixed("convergence: resolution d = %g is outside [4, 256] lattice units per d_ref",
                       d);
    }
  }
  if (e.empty()) {
    for (const Scheme& s : schemes) {
      RunOptions r = run;
      r.collision = s.collision;
      r.boundary = s.boundary;
      std::string run_error;
      if (!r.IsValid(&run_error)) {
        e = "convergence (" + s.name() + "): " + run_error;
        break;
      }
    }
  }
  if (!e.empty() && error) *error = e;
  return e.empty();
}

ConvergenceResult run_convergence(const ConvergenceOptions& options,
                                  const ProgressCallback& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  std::vector<double> resolutions = options.resolutions;
  std::sort(resolutions.begin(), resolutions.end());
  resolutions.erase(std::unique(resolutions.begin(), resolutions.end()), resolutions.end());
  // Refuse what cannot run (gaps not resolved, too little memory) before spending any time.
  for (double d : resolutions) check_run_size(options.packing, d, options.run, "convergence: d");

  const auto start = std::chrono::steady_clock::now();
  ConvergenceResult result;
  result.phi = options.packing.phi();
  result.re = options.run.re;
  for (const Scheme& s : options.schemes) {
    SchemeConvergence sc;
    sc.scheme = s;
    result.schemes.push_back(sc);
  }
  // Cost model for the progress fraction: nodes (d^3) x steps to steady state (diffusive, d^2).
  double total = 0.0;
  for (double d : resolutions) total += std::pow(d, 5.0) * options.schemes.size();
  double done = 0.0;
  const std::size_t count = resolutions.size() * options.schemes.size();
  std::size_t index = 0;
  for (double d : resolutions) {
    const double weight = std::pow(d, 5.0);
    for (SchemeConvergence& sc : result.schemes) {
      ++index;
      RunOptions r = options.run;
      r.collision = sc.scheme.collision;
      r.boundary = sc.scheme.boundary;
      r.throw_on_failure = false;
      r.checkpoint.clear();                 // several runs: none resumes another's state
      r.use_hydrodynamic_diameter = false;  // a calibrated d_h belongs to one resolution only
      const std::string label = sc.scheme.name() +
                                format_fixed(" d=%g", realised_resolution(options.packing, d)) +
                                " (" + std::to_string(index) + "/" + std::to_string(count) + ")";
      ProgressCallback point_progress;
      if (progress) {
        point_progress = [&, label](double f, const std::string&) {
          progress((done + weight * std::clamp(f, 0.0, 1.0)) / total, label);
        };
      }
      ConvergencePoint p;
      p.d_requested = d;
      try {
        const RunResult run_result = run(options.packing, d, r, point_progress);
        p.d = run_result.d;
        p.converged = run_result.converged;
        p.diagnosis = run_result.diagnosis;
        p.F = run_result.converged ? run_result.F : std::nan("");
        p.error_estimate = run_result.error_estimate;
        p.wall_s = run_result.wall_s;
        p.steps = run_result.steps;
        p.mflups = run_result.mflups;
      } catch (const Error& e) {
        if (e.is_bad_input()) throw;
        p.d = realised_resolution(options.packing, d);
        p.converged = false;
        p.diagnosis = e.what();
      }
      const double nodes_x = std::round(d * options.packing.box_length[0]);
      p.dims = {static_cast<std::int64_t>(nodes_x),
                static_cast<std::int64_t>(std::round(nodes_x / options.packing.box_length[0] *
                                                     options.packing.box_length[1])),
                static_cast<std::int64_t>(std::round(nodes_x / options.packing.box_length[0] *
                                                     options.packing.box_length[2]))};
      sc.points.push_back(p);
      done += weight;
      if (progress) progress(done / total, label + " done");
    }
  }

  // Reference.
  for (SchemeConvergence& sc : result.schemes) {
    std::vector<double> ds, Fs;
    for (const ConvergencePoint& p : sc.points) {
      ds.push_back(p.d);
      Fs.push_back(p.F);
    }
    sc.richardson = richardson_extrapolate(ds, Fs);
  }
  const double analytical = analytical_reference_F(options.packing, options.run.re);
  if (!std::isnan(options.reference_F)) {
    result.reference_F = options.reference_F;
    result.reference_source = "user";
  } else if (!std::isnan(analytical)) {
    result.reference_F = analytical;
    result.reference_source = "Sangani-Acrivos series (SC, Stokes)";
  } else {
    // The best-converged extrapolation: the smallest move from its finest converged value.
    const SchemeConvergence* best = nullptr;
    double best_move = std::numeric_limits<double>::infinity();
    for (const SchemeConvergence& sc : result.schemes) {
      if (!sc.richardson.ok) continue;
      double finest = std::nan("");
      for (const ConvergencePoint& p : sc.points) {
        if (p.converged) finest = p.F;
      }
      const double move = std::fabs(sc.richardson.F_inf - finest) / std::fabs(sc.richardson.F_inf);
      if (move < best_move) {
        best_move = move;
        best = &sc;
      }
    }
    if (best) {
      result.reference_F = best->richardson.F_inf;
      result.reference_source = "Richardson extrapolation of " + best->scheme.name() +
                                format_fixed(" (order %.2f)", best->richardson.order);
      // Spread over the schemes' limits: meaningful with two or more extrapolations only.
      int extrapolated = 0;
      double spread = 0.0;
      for (const SchemeConvergence& sc : result.schemes) {
        if (!sc.richardson.ok) continue;
        ++extrapolated;
        spread = std::max(spread,
                          std::fabs(sc.richardson.F_inf - result.reference_F) / result.reference_F);
      }
      if (extrapolated >= 2) result.reference_spread = spread;
    } else {
      result.reference_source = "none";
    }
  }
  for (SchemeConvergence& sc : result.schemes) {
    std::vector<double> ds, errors;
    for (ConvergencePoint& p : sc.points) {
      p.error = p.F / result.reference_F - 1.0;  // NaN when either is NaN
      ds.push_back(p.d);
      errors.push_back(p.error);
    }
    sc.order = fitted_order(ds, errors);
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string ConvergenceResult::Table() const {
  std::string s;
  char buf[512];
  std::snprintf(buf, sizeof buf, "phi = %.6g, Re = %g; reference F = %.6g (%s)", phi, re,
                reference_F, reference_source.c_str());
  s += buf;
  if (std::isfinite(reference_spread)) {
    std::snprintf(buf, sizeof buf, ", schemes' extrapolations within %.2g %%",
                  100.0 * reference_spread);
    s += buf;
  }
  s += "\n";
  std::snprintf(buf, sizeof buf, "%-10s %8s %16s %12s %10s %10s %9s %8s\n", "scheme", "d", "nodes",
                "F", "error %", "wall s", "steps", "MFLUPS");
  s += buf;
  for (const SchemeConvergence& sc : schemes) {
    for (const ConvergencePoint& p : sc.points) {
      const std::string dims = std::to_string(p.dims[0]) + "x" + std::to_string(p.dims[1]) + "x" +
                               std::to_string(p.dims[2]);
      if (p.converged) {
        char error[32] = "-";
        if (std::isfinite(p.error)) std::snprintf(error, sizeof error, "%+.3f", 100.0 * p.error);
        std::snprintf(buf, sizeof buf, "%-10s %8.3f %16s %12.6g %10s %10.2f %9lld %8.1f\n",
                      sc.scheme.name().c_str(), p.d, dims.c_str(), p.F, error, p.wall_s,
                      static_cast<long long>(p.steps), p.mflups);
      } else {
        std::snprintf(buf, sizeof buf, "%-10s %8.3f %16s %12s %10s %10.2f %9lld  FAILED: %s\n",
                      sc.scheme.name().c_str(), p.d, dims.c_str(), "-", "-", p.wall_s,
                      static_cast<long long>(p.steps), p.diagnosis.c_str());
      }
      s += buf;
    }
  }
  s += "orders:";
  for (const SchemeConvergence& sc : schemes) {
    s += "\n  " + sc.scheme.name() + ":";
    if (std::isfinite(sc.order)) {
      std::snprintf(buf, sizeof buf, " fitted to the errors %.2f;", sc.order);
      s += buf;
    }
    if (sc.richardson.ok) {
      std::snprintf(buf, sizeof buf, " Richardson %.2f, F_inf = %.6g", sc.richardson.order,
                    sc.richardson.F_inf);
      s += buf;
      if (!sc.richardson.note.empty()) s += " (" + sc.richardson.note + ")";
    } else {
      s += " Richardson: " + sc.richardson.note;
    }
  }
  s += "\n";
  return s;
}

}  // namespace lbm
}  // namespace draglab
