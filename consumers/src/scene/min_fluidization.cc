// Minimum fluidization velocity of a loaded law: 18 Re F(1 - eps_mf, Re) = eps_mf Ar (scene.h),
// bracketed on a log grid inside the law's Re validity range and refined with Brent's method.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/consumers/scene.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

using core::format_number;

/// Brent's root finder (inverse quadratic interpolation with bisection safeguard) on [a, b]
/// with f(a) f(b) <= 0. Returns the root; *iterations counts function evaluations after the
/// bracket. Converges for any continuous f; falls back to bisection where interpolation stalls.
template <typename Fn>
double brent(Fn f, double a, double b, double fa, double fb, double rel_tol, int max_iterations,
             int* iterations, bool* converged) {
  double c = a, fc = fa, d = b - a, e = d;
  *converged = false;
  for (int it = 1; it <= max_iterations; ++it) {
    *iterations = it;
    if ((fb > 0.0 && fc > 0.0) || (fb < 0.0 && fc < 0.0)) {
      c = a;
      fc = fa;
      d = e = b - a;
    }
    if (std::fabs(fc) < std::fabs(fb)) {
      a = b;
      b = c;
      c = a;
      fa = fb;
      fb = fc;
      fc = fa;
    }
    const double tol = 2.0 * 1e-16 * std::fabs(b) + 0.5 * rel_tol * std::fabs(b);
    const double m = 0.5 * (c - b);
    if (std::fabs(m) <= tol || fb == 0.0) {
      *converged = true;
      return b;
    }
    if (std::fabs(e) >= tol && std::fabs(fa) > std::fabs(fb)) {
      double p, q, r;
      const double s = fb / fa;
      if (a == c) {
        p = 2.0 * m * s;
        q = 1.0 - s;
      } else {
        q = fa / fc;
        r = fb / fc;
        p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0));
        q = (q - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0.0) q = -q;
      p = std::fabs(p);
      if (2.0 * p < std::min(3.0 * m * q - std::fabs(tol * q), std::fabs(e * q))) {
        e = d;
        d = p / q;
      } else {
        d = m;
        e = m;
      }
    } else {
      d = m;
      e = m;
    }
    a = b;
    fa = fb;
    b += std::fabs(d) > tol ? d : (m > 0.0 ? tol : -tol);
    fb = f(b);
  }
  return b;
}

}  // namespace

bool MinFluidizationOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!(eps_mf > 0.2 && eps_mf < 0.9)) {
    return fail("eps_mf = " + format_number(eps_mf) + " is outside (0.2, 0.9)");
  }
  if (!(relative_tolerance > 0.0 && relative_tolerance <= 1e-3)) {
    return fail("relative_tolerance = " + format_number(relative_tolerance) +
                " is outside (0, 1e-3]");
  }
  if (max_iterations < 10 || max_iterations > 10000) {
    return fail("max_iterations = " + std::to_string(max_iterations) + " is outside [10, 10000]");
  }
  return true;
}

std::string MinFluidizationResult::BriefReport() const {
  std::ostringstream s;
  s << law << ": U_mf = " << format_number(umf_m_s, 4)
    << " m/s (Re_mf = " << format_number(re_mf, 4) << ", eps_mf = " << eps_mf
    << ", Ar = " << format_number(archimedes, 4) << ", F = " << format_number(F_mf, 4)
    << ", beta = " << format_number(beta_mf, 4) << " kg/m^3/s, " << iterations
    << " Brent iterations)";
  if (!extrapolation.empty()) s << "; EXTRAPOLATED: " << extrapolation;
  return s.str();
}

MinFluidizationResult minimum_fluidization(const Law& law, const SceneParticles& particles,
                                           const SceneGas& gas,
                                           const MinFluidizationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  const double d = particles.diameter_m, rho_p = particles.density_kg_m3;
  const double rho = gas.density_kg_m3, mu = gas.viscosity_pa_s, g = gas.gravity_m_s2;
  auto positive = [](double x, const std::string& field, const std::string& unit) {
    if (!(std::isfinite(x) && x > 0.0)) {
      throw Error(ErrorCode::kInvalidArgument,
                  field + " = " + format_number(x) + " is outside (0, inf) " + unit);
    }
  };
  positive(d, "particles.diameter_m", "m");
  positive(rho_p, "particles.density_kg_m3", "kg/m^3");
  positive(rho, "gas.density_kg_m3", "kg/m^3");
  positive(mu, "gas.viscosity_pa_s", "Pa s");
  positive(g, "gas.gravity_m_s2", "m/s^2");
  if (!(rho_p > rho)) {
    throw Error(ErrorCode::kInvalidArgument,
                "particles.density_kg_m3 = " + format_number(rho_p) +
                    " must exceed gas.density_kg_m3 = " + format_number(rho));
  }

  const double eps = options.eps_mf, phi = 1.0 - eps;
  const ValidityBox& box = law.record().validity;
  const std::string ref = law.reference();
  // Asked to extrapolate, the formula is solved as is beyond the box (the result says so).
  const bool extrapolate = law.range_policy() == RangePolicy::kExtrapolate;
  if (!extrapolate && !box.phi.contains(phi)) {
    throw Error(ErrorCode::kOutOfValidity,
                ref + ": the bed at eps_mf = " + format_number(eps) + " (phi = " +
                    format_number(phi) + ") is outside the law's validity range phi in [" +
                    format_number(box.phi.min) + ", " + format_number(box.phi.max) +
                    "]; use an eps_mf inside it, another law, or range_policy = \"extrapolate\"");
  }
  // Monodisperse particles: every polydispersity input y_i = d_i/<d> is 1.
  std::vector<double> extra(static_cast<std::size_t>(law.num_extra_inputs()), 1.0);
  const double* extra_ptr = extra.empty() ? nullptr : extra.data();
  // Size classes (d = their Sauter mean <d>): a per-size law's drag of the whole bed is
  // F = sum_i x_i F_i(phi, Re, y_i)/y_i^2 (beta = sum_i beta_i, beta_i = 18 mu eps phi_i
  // F_i/d_i^2); a monodisperse law is taken at <d>.
  const bool classes = !particles.diameters_m.empty() && law.num_extra_inputs() == 1;
  auto bed_F = [&](double re) {
    if (!classes) return law.F(phi, re, extra_ptr);
    double F = 0.0;
    for (std::size_t i = 0; i < particles.diameters_m.size(); ++i) {
      const double y = particles.diameters_m[i] / d;
      F += particles.volume_fractions[i] * law.F(phi, re, &y) / (y * y);
    }
    return F;
  };

  const double ar = rho * (rho_p - rho) * g * d * d * d / (mu * mu);
  const double target = eps * ar;
  // Scaled residual (18 Re F - eps Ar)/(eps Ar): O(1), negative at Re = 0.
  auto residual = [&](double re) { return (18.0 * re * bed_F(re) - target) / target; };

  // Bracket: the first sign change on a log grid over the law's Re range (the residual of a
  // physical law grows monotonically with Re; the scan also copes with one that does not).
  const double re_lo = extrapolate ? 0.0 : box.re.min;
  const double re_hi = extrapolate ? std::max(box.re.max, kExtrapolatedReMax) : box.re.max;
  double a = re_lo, fa = residual(re_lo);
  if (fa > 0.0) {
    throw Error(ErrorCode::kOutOfValidity,
                ref + ": U_mf lies below the law's validity range Re >= " + format_number(re_lo) +
                    " (Ar = " + format_number(ar, 4) + "); use a law valid at lower Re");
  }
  const double start = std::max(re_lo, 1e-6 * std::max(re_hi, 1.0));
  const int kScan = 80;
  double b = a, fb = fa;
  bool bracketed = false;
  for (int k = 0; k <= kScan; ++k) {
    const double re = start * std::pow(re_hi / start, static_cast<double>(k) / kScan);
    const double fr = residual(k == kScan ? re_hi : re);
    if (fr >= 0.0) {
      b = k == kScan ? re_hi : re;
      fb = fr;
      bracketed = true;
      break;
    }
    a = re;
    fa = fr;
  }
  if (!bracketed) {
    const double u_hi = re_hi * mu / (rho * d);
    throw Error(ErrorCode::kOutOfValidity,
                ref + ": the law's drag at its highest valid Re = " + format_number(re_hi) +
                    " (U = " + format_number(u_hi, 4) +
                    " m/s) does not yet carry the bed's weight (Ar = " + format_number(ar, 4) +
                    ", eps_mf = " + format_number(eps) +
                    "): U_mf lies outside its validity box; use a law valid at higher Re, "
                    "smaller/lighter particles, or range_policy = \"extrapolate\"");
  }
  MinFluidizationResult r;
  bool converged = false;
  r.re_mf = brent(residual, a, b, fa, fb, options.relative_tolerance, options.max_iterations,
                  &r.iterations, &converged);
  if (!converged) {
    throw Error(ErrorCode::kInternal,
                ref + ": Brent's method did not reach relative_tolerance = " +
                    format_number(options.relative_tolerance) + " in " +
                    std::to_string(options.max_iterations) +
                    " iterations (raise max_iterations or relative_tolerance)");
  }
  r.law = ref;
  r.eps_mf = eps;
  r.archimedes = ar;
  r.umf_m_s = r.re_mf * mu / (rho * d);
  r.F_mf = bed_F(r.re_mf);
  r.beta_mf = 18.0 * phi * eps * r.F_mf * mu / (d * d);
  r.residual = residual(r.re_mf);
  if (!box.phi.contains(phi) || !box.re.contains(r.re_mf)) {
    r.extrapolation = "outside the law's validity box (phi in [" + format_number(box.phi.min) +
                      ", " + format_number(box.phi.max) + "], Re in [" + format_number(box.re.min) +
                      ", " + format_number(box.re.max) +
                      "]): the formula evaluated as is (range_policy = \"extrapolate\")";
  }
  return r;
}

}  // namespace consumers
}  // namespace draglab
