// Sangani-Acrivos series for simple-cubic arrays and the hydrodynamic-diameter calibration.
#include "draglab/lbm/calibration.h"
#include "draglab/core/text.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/error.h"

namespace draglab {
namespace lbm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Sangani & Acrivos (1982) Int. J. Multiphase Flow 8:343, Eq. 60 / Table 1, q_0 .. q_30, as
// transcribed in waLBerla tests/pe_coupling/momentum_exchange_method/DragForceSphereMEM.cpp.
// Embedded (the library never reads data/ at run time); data/sangani_acrivos_sc_series.csv holds
// the same numbers for the tests, which compare the two.
constexpr std::array<double, kSanganiAcrivosTerms> kSanganiAcrivosQ{
    1.000000,  1.418649,  2.012564,   2.331523,  2.564809, 2.584787, 2.873609, 3.340163,
    3.536763,  3.504092,  3.253622,   2.689757,  2.037769, 1.809341, 1.877347, 1.534685,
    0.9034708, 0.2857896, -0.5512626, -1.278724, 1.013350, 5.492491, 4.615388, -0.5736023,
    -2.865924, -4.709215, -6.870076,  0.1455304, 12.51891, 9.742811, -5.566269};

double chi_of_phi(double phi) { return std::cbrt(6.0 * phi / kPi); }

/// K(chi) and dK/dchi by Horner's rule.
void series(double chi, double* K, double* dK) {
  double k = 0.0, dk = 0.0;
  for (int s = kSanganiAcrivosTerms - 1; s >= 0; --s) {
    dk = dk * chi + k;
    k = k * chi + kSanganiAcrivosQ[static_cast<std::size_t>(s)];
  }
  *K = k;
  *dK = dk;
}

void check_phi_range(double phi) {
  if (!std::isfinite(phi) || phi <= 0.0 || phi > kSanganiAcrivosMaxPhi) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "Sangani-Acrivos series: phi = %g is outside (0, %g] (the 31-term series "
                  "drifts from the exact result above)",
                  phi, kSanganiAcrivosMaxPhi);
    throw Error(ErrorCode::kInvalidArgument, buf);
  }
}

using core::format_fixed;

/// An SC array (one sphere per periodic cube) whose edge is a whole number of lattice nodes
/// near `diameter` (pi/(6 phi))^(1/3); its exact phi follows from that edge.
struct ScArray {
  std::int64_t box_nodes = 0;
  double phi = 0.0;
};

ScArray sc_array(double diameter, double phi_target) {
  ScArray a;
  const double edge = diameter * std::cbrt(kPi / (6.0 * phi_target));
  a.box_nodes = std::max<std::int64_t>(2, std::llround(edge));
  const double ratio = diameter / static_cast<double>(a.box_nodes);  // d/L
  a.phi = kPi / 6.0 * ratio * ratio * ratio;
  return a;
}

/// Sub-grid offset (lattice units, each component in [0, 1)) of the sphere centre for position
/// k: the R3 low-discrepancy sequence (additive recurrence with the powers of 1/g, g the plastic
/// number), so that any number of positions samples the cell evenly. Position 0 is the centre
/// of the box.
std::array<double, 3> position_offset(int k) {
  constexpr double g = 1.32471795724474602596;  // x^3 = x + 1
  const double a[3] = {1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g)};
  std::array<double, 3> o{};
  for (int axis = 0; axis < 3; ++axis) o[axis] = std::fmod(k * a[axis], 1.0);
  return o;
}

arrays::Packing sc_packing(const ScArray& array, double diameter, int position) {
  arrays::Packing p;
  const double edge = static_cast<double>(array.box_nodes) / diameter;  // in d
  const std::array<double, 3> o = position_offset(position);
  p.box_length = {edge, edge, edge};
  p.centers = {
      {0.5 * edge + o[0] / diameter, 0.5 * edge + o[1] / diameter, 0.5 * edge + o[2] / diameter}};
  p.radii = {0.5};
  p.generator = "hydrodynamic-diameter calibration: simple-cubic array";
  return p;
}

/// Stokes drag of the array averaged over `positions` sub-grid positions of the sphere (the
/// staircase of a bounce-back sphere, hence its drag, depends on where its centre sits between
/// nodes; random packings sample all positions, so the calibration does too, as Ladd's did).
CalibrationCheck measure(const ScArray& array, double diameter, int positions,
                         const RunOptions& run_options,
                         const std::function<ProgressCallback(int)>& progress_of) {
  CalibrationCheck c;
  c.positions = positions;
  double sum = 0.0, sum2 = 0.0;
  for (int k = 0; k < positions; ++k) {
    const RunResult r = run(sc_packing(array, diameter, k), diameter, run_options, progress_of(k));
    if (!r.converged) {  // run() throws unless throw_on_failure was cleared; be explicit anyway
      throw Error(ErrorCode::kInternal, "calibration run did not converge: " + r.diagnosis);
    }
    if (k == 0) c.run = r;
    sum += r.F;
    sum2 += r.F * r.F;
    c.steps += r.steps;
    c.wall_s += r.wall_s;
  }
  // phi of the realised lattice diameter (equal to array.phi up to round-off).
  if (!(c.run.d > 0.0)) c.run.d = diameter;
  c.phi = kPi / 6.0 * std::pow(c.run.d / static_cast<double>(array.box_nodes), 3.0);
  const double n = positions;
  c.F_input = sum / n;
  c.F_position_spread =
      n > 1 ? std::sqrt(std::max(0.0, (sum2 - n * c.F_input * c.F_input) / (n - 1))) / c.F_input
            : 0.0;
  c.F_reference = sangani_acrivos_sc_F(std::min(c.phi, kSanganiAcrivosMaxPhi));
  c.error_input = c.F_input / c.F_reference - 1.0;
  return c;
}

void apply_hydrodynamic(double ratio, CalibrationCheck* c) {
  c->phi_hydrodynamic = c->phi * ratio * ratio * ratio;
  c->F_hydrodynamic = c->F_input / ratio;
  c->F_reference_hydrodynamic = c->phi_hydrodynamic <= kSanganiAcrivosMaxPhi
                                    ? sangani_acrivos_sc_F(c->phi_hydrodynamic)
                                    : std::nan("");
  c->error_hydrodynamic = c->F_hydrodynamic / c->F_reference_hydrodynamic - 1.0;
}

}  // namespace

const std::array<double, kSanganiAcrivosTerms>& sangani_acrivos_coefficients() {
  return kSanganiAcrivosQ;
}

double sangani_acrivos_sc_K(double phi) {
  check_phi_range(phi);
  double K, dK;
  series(chi_of_phi(phi), &K, &dK);
  return K;
}

double sangani_acrivos_sc_F(double phi) { return (1.0 - phi) * sangani_acrivos_sc_K(phi); }

double solve_hydrodynamic_diameter(double box_edge, double diameter, double F_measured,
                                   int* iterations) {
  if (!(box_edge > 0.0) || !(diameter > 0.0) || !(F_measured > 0.0) ||
      !std::isfinite(box_edge * diameter * F_measured)) {
    throw Error(
        ErrorCode::kInvalidArgument,
        format_fixed("hydrodynamic diameter: box edge (%g), diameter (%g) and measured F (%g) "
                     "must be finite and > 0",
                     box_edge, diameter, F_measured));
  }
  // r(x) = x (1 - phi(x)) K(chi(x)) - d F_measured with chi = x/L, phi = pi/6 chi^3: the
  // drag force divided by 3 pi mu U, as the series predicts for diameter x minus as measured.
  // r grows monotonically in x up to chi_max (the series is accepted only up to there).
  const double target = diameter * F_measured;
  const double chi_max = chi_of_phi(kSanganiAcrivosMaxPhi);
  auto residual = [&](double x, double* slope) {
    const double chi = x / box_edge;
    const double phi = kPi / 6.0 * chi * chi * chi;
    double K, dK;
    series(chi, &K, &dK);
    // d/dx [x (1 - phi) K] = (1 - phi) K + x [-(pi/2) chi^2 K + (1 - phi) dK] / L.
    *slope = (1.0 - phi) * K + chi * (-(kPi / 2.0) * chi * chi * K + (1.0 - phi) * dK);
    return x * (1.0 - phi) * K - target;
  };
  double slope = 0.0;
  const double x_max = chi_max * box_edge;
  if (residual(x_max, &slope) < 0.0) {
    throw Error(
        ErrorCode::kInvalidArgument,
        format_fixed("hydrodynamic diameter: the measured drag (F = %g at d = %g in a box of %g) "
                     "exceeds the series for any diameter up to phi = %g",
                     F_measured, diameter, box_edge, kSanganiAcrivosMaxPhi));
  }
  // Newton from x = target (the dilute limit, K -> 1), kept inside (0, x_max] by bisection
  // fallback: r(0) = -target < 0 < r(x_max).
  double lo = 0.0, hi = x_max;
  double x = std::min(target, x_max);
  int n = 0;
  for (; n < 100; ++n) {
    const double r = residual(x, &slope);
    if (r < 0.0) {
      lo = x;
    } else {
      hi = x;
    }
    const double step = r / slope;
    if (std::fabs(step) <= 1e-13 * x) {  // converged (checked first: the step may be below ulp)
      x -= step;
      break;
    }
    double next = x - step;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    x = next;
  }
  if (iterations) *iterations = n + 1;
  return x;
}

bool CalibrationOptions::IsValid(std::string* error) const {
  std::string e;
  if (!std::isfinite(diameter) || diameter < 4.0 || diameter > 128.0) {
    e = format_fixed("calibration: diameter = %g lattice units is outside [4, 128]", diameter);
  } else if (!std::isfinite(phi) || phi < 0.001 || phi > 0.05) {
    e = format_fixed("calibration: phi = %g is outside [0.001, 0.05] (a dilute simple-cubic array)",
                     phi);
  } else if (positions < 1 || positions > 64) {
    e = format_fixed("calibration: positions = %g is outside [1, 64]",
                     static_cast<double>(positions));
  } else if (!std::isfinite(check_phi) || check_phi < 0.0 || check_phi > kSanganiAcrivosMaxPhi) {
    e = format_fixed("calibration: check phi = %g is outside (0, %g] (0 = no check)", check_phi,
                     kSanganiAcrivosMaxPhi);
  } else {
    RunOptions r = run;
    r.re = 0.0;
    r.use_hydrodynamic_diameter = false;
    std::string run_error;
    if (!r.IsValid(&run_error)) e = "calibration: " + run_error;
  }
  if (!e.empty() && error) *error = e;
  return e.empty();
}

CalibrationResult calibrate_hydrodynamic_diameter(const CalibrationOptions& options,
                                                  const ProgressCallback& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  const auto start = std::chrono::steady_clock::now();
  RunOptions r = options.run;
  r.re = 0.0;
  r.use_hydrodynamic_diameter = false;
  r.hydrodynamic_diameter = 0.0;
  r.throw_on_failure = true;
  r.checkpoint.clear();  // several runs: none resumes another's state

  // Progress weights: nodes x diffusive steps ~ L^5 per run.
  const ScArray calibration_array = sc_array(options.diameter, options.phi);
  ScArray check_array;
  const bool check = options.check_phi > 0.0;
  const int n = options.positions;
  const double w1 = std::pow(static_cast<double>(calibration_array.box_nodes), 5.0);
  double w2 = 0.0;
  if (check) {
    check_array = sc_array(options.diameter, options.check_phi);
    w2 = std::pow(static_cast<double>(check_array.box_nodes), 5.0);
  }
  const double total = n * (w1 + w2);
  auto stage = [&](double offset, double weight,
                   const std::string& name) -> std::function<ProgressCallback(int)> {
    return [=, &progress](int k) -> ProgressCallback {
      if (!progress) return nullptr;
      const std::string label =
          name + " position " + std::to_string(k + 1) + "/" + std::to_string(n);
      return [=, &progress](double f, const std::string& status) {
        progress((offset + weight * (k + std::clamp(f, 0.0, 1.0))) / total, label + ": " + status);
      };
    };
  };

  CalibrationResult result;
  result.box_nodes = calibration_array.box_nodes;
  result.calibration =
      measure(calibration_array, options.diameter, n, r, stage(0.0, w1, "calibration array"));
  result.diameter = result.calibration.run.d;
  result.hydrodynamic_diameter =
      solve_hydrodynamic_diameter(static_cast<double>(calibration_array.box_nodes), result.diameter,
                                  result.calibration.F_input, &result.newton_iterations);
  result.ratio = result.hydrodynamic_diameter / result.diameter;
  apply_hydrodynamic(result.ratio, &result.calibration);
  if (check) {
    result.has_check = true;
    result.check = measure(check_array, options.diameter, n, r, stage(n * w1, w2, "check array"));
    apply_hydrodynamic(result.ratio, &result.check);
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (progress) progress(1.0, "calibration done");
  return result;
}

std::string CalibrationResult::Report() const {
  std::string s;
  s += format_fixed("input diameter d      %.4f lattice units (SC box of %.0f nodes, phi = %.5f)\n",
                    diameter, static_cast<double>(box_nodes), calibration.phi);
  s += format_fixed("hydrodynamic d_h      %.4f lattice units, d_h/d = %.5f (%+.2f %%)\n",
                    hydrodynamic_diameter, ratio, 100.0 * (ratio - 1.0));
  s += format_fixed("calibration array     F = %.5f with d, series %.5f (%+.2f %%)\n",
                    calibration.F_input, calibration.F_reference, 100.0 * calibration.error_input);
  s += format_fixed("                      mean over %g sphere positions (spread %.2f %%)\n",
                    static_cast<double>(calibration.positions),
                    100.0 * calibration.F_position_spread);
  s += format_fixed("effect of d_h         F x %.5f, phi x %.5f\n", 1.0 / ratio,
                    ratio * ratio * ratio);
  if (has_check) {
    s += format_fixed("check phi = %.4f      with d: F = %.5f, series %.5f (%+.2f %%)\n", check.phi,
                      check.F_input, check.F_reference, 100.0 * check.error_input);
    s += format_fixed("                      with d_h: F = %.5f, series at phi_h = %.4f: %.5f",
                      check.F_hydrodynamic, check.phi_hydrodynamic, check.F_reference_hydrodynamic);
    s += format_fixed(" (%+.2f %%)\n", 100.0 * check.error_hydrodynamic);
  }
  s += format_fixed("time                  %.2f s\n", wall_s);
  return s;
}

}  // namespace lbm
}  // namespace draglab
