// draglab/lbm/convergence.h: work-precision of the LBM drag, a resolution sweep of one case for
// several schemes (collision + boundary), each point's error against its wall time.
//
// Reference value of F, in this order:
//  1. ConvergenceOptions::reference_F when given (a value the user trusts);
//  2. the analytical value where one exists: a simple-cubic array (one sphere in a periodic cube)
//     in Stokes flow at phi <= 0.22, the 31-term Sangani-Acrivos series (calibration.h);
//  3. otherwise Richardson extrapolation d -> infinity: for each scheme, F(d) = F_inf + C d^-p
//     through its three finest converged points (or, when those do not converge monotonically,
//     fitted by least squares to four or more) gives F_inf and the measured order p; the
//     reference is the F_inf of the scheme whose extrapolation moved its finest value the least
//     (the best-converged one), and the spread of the schemes' F_inf is reported beside it.
// Measured order with an analytical reference: least-squares slope of log|error| on log d over
// the converged points (halfway bounce-back converges irregularly, so this is a trend, not a
// proof).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {

/// A collision model with a boundary scheme, e.g. TRT + interpolated bounce-back.
struct Scheme {
  Collision collision = Collision::kTrt;
  Boundary boundary = Boundary::kInterpolated;
  /// "bgk-bb", "trt-ibb", "rr-bb", ...: collision_from_string + "-" + boundary_from_string.
  std::string name() const;
};
/// Parses "bgk-bb" etc.; throws Error(kInvalidArgument) naming the accepted forms.
Scheme scheme_from_string(const std::string& s);
/// The three: BGK + halfway bounce-back (the seed's method), TRT + halfway bounce-back,
/// TRT + interpolated bounce-back.
std::vector<Scheme> default_schemes();

/// Analytical reference F of a packing at Reynolds number re where one is known: the
/// Sangani-Acrivos series for one monodisperse sphere in a cubic box (an SC array) at re == 0
/// and phi <= 0.22. NaN otherwise.
double analytical_reference_F(const arrays::Packing& packing, double re);

/// F(d) = F_inf + C d^-p through three points.
struct RichardsonEstimate {
  bool ok = false;
  double F_inf = std::numeric_limits<double>::quiet_NaN();
  double order = std::numeric_limits<double>::quiet_NaN();  ///< Measured p.
  std::string note;  ///< Why it failed (fewer than 3 points, non-monotone convergence, ...).
};
/// Uses the three largest d (distinct, > 0) with finite F. The order is solved from
/// (F1 - F2)/(F2 - F3) = (d1^-p - d2^-p)/(d2^-p - d3^-p) by bisection on p in [0.05, 8]
/// (arbitrary ratios of d). If that fails (non-monotone convergence, order outside the range) and
/// there are four or more points, the same model is fitted by least squares over all of them
/// (note says so); ok = false if that also puts p on a bound of [0.05, 8].
RichardsonEstimate richardson_extrapolate(const std::vector<double>& d,
                                          const std::vector<double>& F);

/// Least-squares order -slope of log|error| against log d over the points with finite non-zero
/// error; NaN for fewer than two.
double fitted_order(const std::vector<double>& d, const std::vector<double>& error);

struct ConvergenceOptions {
  arrays::Packing packing;  ///< The case (lengths in d_ref).
  /// Requested resolutions d (lattice units per d_ref), each in [4, 256]; each is realised as the
  /// nearest whole number of nodes along the box (ConvergencePoint::d).
  std::vector<double> resolutions{8.0, 12.0, 16.0, 24.0};
  std::vector<Scheme> schemes = default_schemes();
  /// Re, tau, Lambda, tolerance, step limit, threads, precision: shared by all points.
  /// collision and boundary are taken from each scheme; throw_on_failure is ignored (a failed
  /// point is recorded with its diagnosis and the sweep goes on).
  RunOptions run;
  double reference_F = std::numeric_limits<double>::quiet_NaN();  ///< NaN: see the file comment.
  bool IsValid(std::string* error) const;
};

struct ConvergencePoint {
  double d_requested = 0.0;
  double d = 0.0;  ///< Realised resolution (lattice units per d_ref).
  std::array<std::int64_t, 3> dims{0, 0, 0};
  bool converged = false;
  std::string diagnosis;
  double F = std::numeric_limits<double>::quiet_NaN();
  double error = std::numeric_limits<double>::quiet_NaN();  ///< F/reference - 1 (signed).
  double error_estimate = 0.0;  ///< The engine's own estimate for this run.
  double wall_s = 0.0;
  std::int64_t steps = 0;
  double mflups = 0.0;
};

struct SchemeConvergence {
  Scheme scheme;
  std::vector<ConvergencePoint> points;                     ///< In order of increasing d.
  double order = std::numeric_limits<double>::quiet_NaN();  ///< fitted_order of the errors.
  RichardsonEstimate richardson;
};

struct ConvergenceResult {
  double reference_F = std::numeric_limits<double>::quiet_NaN();
  /// "user", "Sangani-Acrivos series (SC, Stokes)", "Richardson extrapolation of trt-ibb
  /// (order 2.03)", or "none" when no reference could be formed (errors are then NaN).
  std::string reference_source;
  /// Richardson: max |F_inf(scheme) - reference| / reference over the schemes whose
  /// extrapolation succeeded, when at least two did; NaN otherwise and for the other sources.
  double reference_spread = std::numeric_limits<double>::quiet_NaN();
  double phi = 0.0, re = 0.0;
  std::vector<SchemeConvergence> schemes;
  double wall_s = 0.0;
  /// Table: scheme, d, nodes, F, error, wall time, steps, then per scheme the orders.
  std::string Table() const;
};

/// Runs the sweep: every resolution (ascending) for every scheme. Throws Error(kInvalidArgument)
/// for invalid options (also when a resolution leaves the smallest gap below
/// run.min_gap_nodes, naming the gap in lattice units); failed runs are recorded, not thrown.
/// `progress` receives the fraction of the estimated total cost (nodes x steps ~ d^5) and a
/// status line naming the current point.
ConvergenceResult run_convergence(const ConvergenceOptions& options,
                                  const ProgressCallback& progress = nullptr);

}  // namespace lbm
}  // namespace draglab
