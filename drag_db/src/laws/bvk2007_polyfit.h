// bvk2007_polyfit: bvk2007's finite-Re drag with a size factor whose coefficients are fitted (the
// form draglab refits to its own bidisperse LBM data; docs/fitting.md, "Per-species data").
//
// clang-format off
//   F_i(phi, Re, y_i) = F_bvk2007(phi, Re) [a(phi) y_i + b(phi) y_i^2 + c(phi) y_i^3]
//   a = a0 + a1 phi,   b = b0 + b1 phi,   c = c0 + c1 phi
// clang-format on
//
// y_i = d_i/<d> (Sauter mean), Re based on <d>, drag-only F_i normalised with the particle's own
// diameter. The defaults (a0, a1, b0, b1, c0, c1) = (1, -1, 0, 1, 0.064, -0.064) give Beetstra et
// al. (2007)'s factor (1 - phi) y + phi y^2 + 0.064 (1 - phi) y^3 (bvk2007_poly); with c0 = c1 = 0
// it is van der Hoef et al. (2005)'s. Each coefficient is linear in phi, the simplest form that
// lets a fit follow how the factor's curvature changes between dilute and dense arrays. The
// mixture's F is F_bvk2007 [a + b + c sum_i x_i y_i] (sum_i x_i/y_i = 1 for the Sauter mean), so
// a + b also carries how far the mixture's drag lies from the monodisperse one.
// Validity: as bvk2007, y in about [0.25, 4]; a stored fit narrows phi, Re and y to its data.
#pragma once

#include "laws/bvk2007.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Bvk2007Polyfit {
  static constexpr int kNumParameters = 11;
  static constexpr int kNumExtraInputs = 1;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// extra = {y}; p = {the five bvk2007 coefficients, a0, a1, b0, b1, c0, c1}.
  template <typename T>
  static T native(const T& phi, const T& re, const T* extra, const T* p) {
    const T& y = extra[0];
    const T a = p[5] + p[6] * phi, b = p[7] + p[8] * phi, c = p[9] + p[10] * phi;
    return Bvk2007::native<T>(phi, re, nullptr, p) * (a * y + b * y * y + c * y * y * y);
  }
};

}  // namespace laws
}  // namespace draglab
