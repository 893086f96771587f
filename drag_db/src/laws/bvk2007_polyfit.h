// bvk2007_polyfit: bvk2007's finite-Re drag with a size factor whose three coefficients are fitted
// (the form draglab refits to its own bidisperse LBM data; docs/validation.md, issue 36).
//
// clang-format off
//   F_i(phi, Re, y_i) = F_bvk2007(phi, Re) [p_a (1 - phi) y_i + p_b phi y_i^2 + g (1 - phi) y_i^3]
// clang-format on
//
// y_i = d_i/<d> (Sauter mean), Re based on <d>, drag-only F_i normalised with the particle's own
// diameter. At p_a = p_b = 1 it is van der Hoef et al. (2005)'s factor, with g = 0.064 also
// Beetstra et al. (2007)'s (bvk2007_poly). The mixture's F is F_bvk2007 times
// p_a (1 - phi) + p_b phi + g (1 - phi) sum_i x_i y_i, so p_a and p_b also carry how far the
// mixture's drag lies from the monodisperse one at the same phi and Sauter mean.
// Validity: as bvk2007, y in about [0.25, 4]; a stored fit narrows phi and Re to its data.
#pragma once

#include "laws/bvk2007.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Bvk2007Polyfit {
  static constexpr int kNumParameters = 8;
  static constexpr int kNumExtraInputs = 1;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// extra = {y}; p = {the five bvk2007 coefficients, p_a, p_b, g}.
  template <typename T>
  static T native(const T& phi, const T& re, const T* extra, const T* p) {
    const T& y = extra[0];
    const T eps = T(1.0) - phi;
    const T factor = p[5] * eps * y + p[6] * phi * y * y + p[7] * eps * y * y * y;
    return Bvk2007::native<T>(phi, re, nullptr, p) * factor;
  }
};

}  // namespace laws
}  // namespace draglab
