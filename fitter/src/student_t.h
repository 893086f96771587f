// Student t distribution for the fitter's confidence intervals (private to fitter/).
//
// The 95 % interval of a least-squares parameter with dof = points - free parameters is
// value +- t_{0.975, dof} * stddev. The quantile is computed here (no statistics library among
// the Debian packages we use): the t CDF via the regularized incomplete beta function (continued
// fraction, Numerical Recipes 3rd ed. section 6.4) and the quantile by bisection on the CDF.
#pragma once

namespace draglab {
namespace fitter {

/// Regularized incomplete beta I_x(a, b) for a, b > 0 and x in [0, 1]; relative accuracy ~1e-14.
double regularized_incomplete_beta(double a, double b, double x);

/// CDF of Student's t with `dof` > 0 degrees of freedom (real-valued dof allowed).
double student_t_cdf(double t, double dof);

/// Quantile t_p of Student's t: CDF(t_p) = p, for p in (0, 1) and dof > 0; accurate to ~1e-12
/// absolute (bisection). Throws Error(kInvalidArgument) outside those ranges.
double student_t_quantile(double p, double dof);

}  // namespace fitter
}  // namespace draglab
