// bvk2007: Beetstra, van der Hoef & Kuipers (2007), monodisperse random arrays, finite Re.
//
//   F(phi, Re) = a phi/eps^2 + eps^2 (1 + b sqrt(phi))
//              + c Re / (24 eps^2) * [1/eps + 3 phi eps + d Re^-e] / [1 + 10^(3 phi) Re^-(1+4 phi)/2]
//
// Native convention = canonical: drag-only F = F_d/(3 pi mu d eps u), Re = rho eps d u / mu.
// Defaults a = 10, b = 1.5 (van der Hoef et al. 2005 Stokes part), c = 0.413, d = 8.4, e = 0.343.
// Validity: random monodisperse arrays, 0.1 <= phi <= 0.6, Re <= 1000; "on average within 10 %"
// of the LBM data (abstract). Cross-checked forms: MFiX DRAG_BVK, OpenFOAM Beetstra, Kratos
// (drag_laws.md 1.10). At Re = 0 the inertial term is exactly 0 (written without Re^-0.343).
#pragma once

#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Bvk2007 {
  static constexpr int kNumParameters = 5;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// Stokes part shared with vdh2005 and tang2015: a phi/eps^2 + eps^2 (1 + b sqrt(phi)).
  template <typename T>
  static T stokes_part(const T& phi, const T& a, const T& b) {
    const T eps = T(1.0) - phi;
    return phi * a / (eps * eps) + eps * eps * (T(1.0) + sqrt_nonneg(phi) * b);
  }

  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    const T& a = p[0];
    const T& b = p[1];
    const T& c = p[2];
    const T& d = p[3];
    const T& e = p[4];
    const T eps = T(1.0) - phi;
    const T stokes = stokes_part(phi, a, b);
    const T numerator = re * (T(1.0) / eps + phi * eps * 3.0) + d * pow(re, T(1.0) - e);
    const T denominator = T(1.0) + pow(T(10.0), phi * 3.0) * pow(re, -(T(1.0) + phi * 4.0) * 0.5);
    const T inertial = c / (eps * eps * 24.0) * numerator / denominator;
    return stokes + select(re > 0.0, inertial, T(0.0));
  }
};

}  // namespace laws
}  // namespace draglab
