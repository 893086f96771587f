// Helpers shared by the law formulas in this folder. Private to drag_db.
//
// Formulas are templates on the scalar type T (double, ceres::Jet, codegen::Expr). Write them with
// unqualified sqrt/exp/log/log10/atan/pow so argument-dependent lookup picks the right overload,
// and write every branch as select(condition, a, b): that is what lets the code exporter turn a
// branch into C/Fortran. Both arms are evaluated, so an arm that is invalid where it is not
// selected (e.g. Re^-0.343 at Re = 0) may produce inf/NaN there without harm.
#pragma once

#include <cmath>

#include "codegen/expr.h"
#include "draglab/drag_db/law_form.h"

namespace draglab {
namespace laws {

using codegen::select;
using std::atan;
using std::exp;
using std::log;
using std::log10;
using std::pow;
using std::sqrt;

/// The extra input of the polydisperse forms: a particle's size ratio y = d_i/<d> to the Sauter
/// mean of the mixture, for diameter ratios up to 1:4.
inline ExtraInputSpec size_ratio_input() {
  return {
      "y", "d_i/<d>: particle diameter over the Sauter mean diameter of the mixture", {0.25, 4.0}};
}

/// Branch written so that it can be traced symbolically (see file comment).
template <typename T>
inline T select(bool condition, const T& if_true, const T& if_false) {
  return condition ? if_true : if_false;
}

/// x^p for x >= 0 and p > 0 that is exactly 0 at x = 0 with a zero derivative (avoids the
/// 0 * inf of p x^(p-1) in automatic derivatives when p < 1).
template <typename T>
inline T pow_nonneg(const T& x, double p) {
  return select(x > 0.0, pow(x, p), T(0.0));
}

/// sqrt(x) for x >= 0 that is exactly 0 at x = 0 with a zero derivative. Plain sqrt has the
/// derivative 1/(2 sqrt x) = inf there, which turns even an unseeded input into 0 * inf = NaN in
/// automatic derivatives (e.g. the parameter gradient of a law fitted to Re = 0 data).
template <typename T>
inline T sqrt_nonneg(const T& x) {
  return select(x > 0.0, sqrt(x), T(0.0));
}

/// x ln x, continuously extended by 0 at x = 0 (Hill-Koch-Ladd's (135/64) phi ln phi).
template <typename T>
inline T x_log_x(const T& x) {
  return select(x > 0.0, x * log(x), T(0.0));
}

/// Schiller-Naumann (1933) single-sphere C_d * Re_p: 24 (1 + 0.15 Re^0.687) for Re <= 1000,
/// 0.44 Re above (drag_laws.md 1.1; MFiX uses <=, OpenFOAM <: the switch point itself differs).
template <typename T>
inline T schiller_naumann_cd_re(const T& re) {
  return select(re <= 1000.0, (T(1.0) + pow_nonneg(re, 0.687) * 0.15) * 24.0, re * 0.44);
}

/// Dalla Valle (1948) single-sphere C_d * Re_p = (0.63 sqrt(Re) + 4.8)^2 (drag_laws.md 1.1).
template <typename T>
inline T dalla_valle_cd_re(const T& re) {
  const T s = sqrt(re) * 0.63 + 4.8;
  return s * s;
}

/// Dalla Valle C_d * Re_p as dalla_valle_cd_re, written with sqrt_nonneg so that automatic
/// derivatives stay finite at Re = 0 (same values for double; the Re-derivative there is reported
/// as 0 instead of the true +inf of the sqrt(Re) term).
template <typename T>
inline T dalla_valle_cd_re_nonneg(const T& re) {
  const T s = sqrt_nonneg(re) * 0.63 + 4.8;
  return s * s;
}

}  // namespace laws
}  // namespace draglab
