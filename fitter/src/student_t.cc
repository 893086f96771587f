#include "student_t.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "draglab/error.h"

namespace draglab {
namespace fitter {
namespace {

/// Continued fraction of I_x(a, b) by the modified Lentz method (NR3 betacf); converges fast for
/// x < (a + 1)/(a + b + 2), which the caller ensures by symmetry.
double incomplete_beta_continued_fraction(double a, double b, double x) {
  const double tiny = 1e-300;
  const double eps = 1e-16;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0;
  double d = 1.0 - qab * x / qap;
  if (std::fabs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 10000; ++m) {
    const int m2 = 2 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < eps) break;
  }
  return h;
}

}  // namespace

double regularized_incomplete_beta(double a, double b, double x) {
  if (!(a > 0.0) || !(b > 0.0) || !(x >= 0.0 && x <= 1.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                "regularized_incomplete_beta: need a > 0, b > 0 and x in [0, 1]");
  }
  if (x == 0.0 || x == 1.0) return x;
  // Prefactor x^a (1-x)^b / (a B(a, b)), in logarithms to avoid overflow for large a, b.
  const double log_front =
      std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  const double front = std::exp(log_front);
  if (x < (a + 1.0) / (a + b + 2.0)) return front * incomplete_beta_continued_fraction(a, b, x) / a;
  return 1.0 - front * incomplete_beta_continued_fraction(b, a, 1.0 - x) / b;
}

double student_t_cdf(double t, double dof) {
  if (!(dof > 0.0) || std::isnan(t)) {
    throw Error(ErrorCode::kInvalidArgument, "student_t_cdf: need dof > 0 and t not NaN");
  }
  if (std::isinf(t)) return t > 0.0 ? 1.0 : 0.0;
  // P(|T| > |t|) = I_{dof/(dof+t^2)}(dof/2, 1/2).
  const double tail = 0.5 * regularized_incomplete_beta(0.5 * dof, 0.5, dof / (dof + t * t));
  return t >= 0.0 ? 1.0 - tail : tail;
}

double student_t_quantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0) || !std::isfinite(dof)) {
    throw Error(ErrorCode::kInvalidArgument,
                "student_t_quantile: p = " + std::to_string(p) +
                    " must be in (0, 1) and dof = " + std::to_string(dof) + " finite and > 0");
  }
  if (p == 0.5) return 0.0;
  if (p < 0.5) return -student_t_quantile(1.0 - p, dof);
  // Bracket: the CDF is increasing; double `high` until it passes p (dof = 1, p = 1 - 1e-12 needs
  // t ~ 3e11, reached in ~40 doublings).
  double low = 0.0, high = 1.0;
  while (student_t_cdf(high, dof) < p) {
    low = high;
    high *= 2.0;
    if (high > 1e300) return std::numeric_limits<double>::infinity();
  }
  for (int i = 0; i < 200 && high - low > 1e-13 * std::max(1.0, high); ++i) {
    const double mid = 0.5 * (low + high);
    (student_t_cdf(mid, dof) < p ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

}  // namespace fitter
}  // namespace draglab
