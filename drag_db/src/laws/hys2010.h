// hys2010: Yin & Sundaresan (2009) polydisperse drag with Beetstra et al.'s inertia, as in MFiX
// DRAG_HYS (Holloway, Yin & Sundaresan 2010).
//
// clang-format off
//   F_i(phi, Re, y_i) = 1/eps + (F_bvk2007(phi, Re) - 1/eps) [a(phi) y_i + (1 - a(phi)) y_i^2]
//   a(phi) = 1 - k1 phi + k2 phi^2 - k3 phi^3,   k1 = 2.66, k2 = 9.096, k3 = 11.338
// clang-format on
//
// Native convention = canonical: drag-only F_i = F_d,i/(3 pi mu d_i eps u), normalised with the
// particle's own diameter; y_i = d_i/<d> with <d> the Sauter mean; Re = rho eps <d> u/mu of the
// mixture (MFiX: DPA and the volume-weighted mean slip), not the particle's own. 1/eps is the
// isolated sphere's Stokes drag in this normalisation, the y -> 0 limit; at y = 1 F_i = F_bvk2007.
// Not included: the lubrication cross term alpha = 1.313 log10(d_min/lambda) - 1.249, a friction
// between solid species that MFiX cancels in the gas phase (it adds no gas-particle drag), and
// MFiX's F_bvk2007 = 0 at zero slip (here its Stokes part). a(phi) and the y^2 form were fitted to
// Stokes-flow data; the inertia enters only through F_bvk2007 (MFiX applies it at any Re).
// Validity: phi 0.1-0.6 and Re <= 1000 (bvk2007's box), y in about [0.25, 4].
#pragma once

#include "laws/bvk2007.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Hys2010 {
  static constexpr int kNumParameters = 8;
  static constexpr int kNumExtraInputs = 1;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// extra = {y}; p = {the five bvk2007 coefficients, k1, k2, k3}.
  template <typename T>
  static T native(const T& phi, const T& re, const T* extra, const T* p) {
    const T& y = extra[0];
    const T isolated = T(1.0) / (T(1.0) - phi);
    const T a = T(1.0) - p[5] * phi + p[6] * phi * phi - p[7] * phi * phi * phi;
    return isolated +
           (Bvk2007::native<T>(phi, re, nullptr, p) - isolated) * (a * y + (T(1.0) - a) * y * y);
  }
};

}  // namespace laws
}  // namespace draglab
