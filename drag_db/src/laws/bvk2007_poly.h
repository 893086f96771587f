// bvk2007_poly: Beetstra, van der Hoef & Kuipers (2007), polydisperse (bidisperse-fitted) form.
//
// clang-format off
//   F_i(phi, Re, y_i) = F_bvk2007(phi, Re) [(1 - phi) y_i + phi y_i^2 + g (1 - phi) y_i^3],  g = 0.064
//   y_i = d_i/<d>, <d> = Sauter mean diameter of the mixture (1/<d> = sum_j (phi_j/phi)/d_j),
//   phi = total solids fraction, Re = rho eps <d> u/mu based on the MEAN diameter <d>.
// clang-format on
//
// Native convention: drag-only F_i normalised with the particle's own diameter, F_i = F_d,i/(3 pi
// mu d_i eps u) (Beetstra et al.'s definition as recalled, not verified against the paper). The
// extra input is y; the Reynolds number input is Re_<d>, not the particle's own Re_i = y Re_<d>.
// Parameters: the five bvk2007 coefficients and g.
//
// At y = 1 the factor is 1 + g (1 - phi): this form does NOT reduce to bvk2007 for a monodisperse
// system but is 6.4 % (phi -> 0) to 2.6 % (phi = 0.6) higher -- a property of the published fit
// (the y^3 term was fitted to finite-Re bidisperse data). So F(phi -> 0, Re -> 0) = 1.064 at y = 1.
// Known deviations, NOT implemented: MFiX DRAG_GS (BVK) drops the y^3 term for solids phase 1 and
// uses F_cor = y_i for TFM model A, citing an erratum; Yin & Sundaresan's HYS form is different.
// Validity: phi 0.1-0.6, Re <= 1000, diameter ratios up to 1:4 (abstract: "on average within 10 %
// ... diameter ratios up to 1:4"), i.e. y in about [0.25, 4].
#pragma once

#include "laws/bvk2007.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Bvk2007Poly {
  static constexpr int kNumParameters = 6;
  static constexpr int kNumExtraInputs = 1;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// Polydisperse factor (1 - phi) y + phi y^2 + g (1 - phi) y^3.
  template <typename T>
  static T size_factor(const T& phi, const T& y, const T& g) {
    const T eps = T(1.0) - phi;
    return eps * y + phi * y * y + g * eps * y * y * y;
  }

  /// extra = {y}; p = {a, b, c, d, e, g}; `re` superficial, based on the Sauter mean diameter.
  template <typename T>
  static T native(const T& phi, const T& re, const T* extra, const T* p) {
    return Bvk2007::native<T>(phi, re, nullptr, p) * size_factor(phi, extra[0], p[5]);
  }
};

}  // namespace laws
}  // namespace draglab
