// tang2015: Tang, Peters, Kuipers, Kriebitzsch & van der Hoef (2015), immersed-boundary DNS of
// static random monodisperse arrays, Eq. (21).
//
//   F = a phi/eps^2 + eps^2 (1 + b sqrt(phi))
//     + [c1 phi (1 + phi) - c2/eps^4 + (c3 eps + c4/eps^4) Re^-e] Re
//   a = 10, b = 1.5, c1 = 0.11, c2 = 0.00456, c3 = 0.169, c4 = 0.0644, e = 0.343
//
// Native convention = canonical (drag-only, superficial Re). CROSS-CHECKED forms: MFiX DRAG_TPKKV,
// waLBerla dragForceTang, MFiX-Exa ComputeDragBVK2 (labelled BVK2, but it is this law). The Stokes
// part is bvk2007's (Bvk2007::stokes_part): tang2015 == bvk2007 == vdh2005 exactly at Re = 0. The
// Re^(1-e) term is written with a select so that Re = 0 is exact with finite derivatives.
// Validity (not verified against the paper): phi 0.1-0.6, Re <= 1000.
#pragma once

#include "laws/bvk2007.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Tang2015 {
  static constexpr int kNumParameters = 7;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// p = {a, b, c1, c2, c3, c4, e}; `re` superficial.
  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    const T eps = T(1.0) - phi;
    const T eps2 = eps * eps;
    const T inv_eps4 = T(1.0) / (eps2 * eps2);
    const T linear = p[2] * phi * (T(1.0) + phi) - p[3] * inv_eps4;
    const T power = p[4] * eps + p[5] * inv_eps4;
    const T re_to_1_minus_e = select(re > 0.0, pow(re, T(1.0) - p[6]), T(0.0));
    return Bvk2007::stokes_part(phi, p[0], p[1]) + (linear * re + power * re_to_1_minus_e);
  }
};

}  // namespace laws
}  // namespace draglab
