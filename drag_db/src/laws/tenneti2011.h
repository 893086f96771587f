// tenneti2011: Tenneti, Garg & Subramaniam (2011), particle-resolved DNS (PUReIBM) of fixed random
// arrays.
//
// clang-format off
//   F_TGS   = F_isol(Re)/eps^3 + F_phi(phi) + F_phiRe(phi, Re)   (total force incl. mean pressure)
//   F_isol  = 1 + 0.15 Re^0.687
//   F_phi   = a1 phi/eps^3 + a2 phi^(1/3)/eps^4,                  a1 = 5.81, a2 = 0.48
//   F_phiRe = phi^3 Re (b1 + b2 phi^3/eps^2),                     b1 = 0.95, b2 = 0.61
// clang-format on
//   normalised by 3 pi mu d eps |W| (W mean slip, so superficial), Re_m = eps rho d |W|/mu.
//
// Native convention: TOTAL force (ForceKind::kTotal), canonical F = (1 - phi) F_TGS -- the waLBerla
// dragForceTenneti reading (CdRe = eps (F_isol/eps^3 + F_phi + F_phiRe)), following the OpenFOAM
// comment that the TGS correlation includes the mean pressure drag. phi^3 in the last bracket, as
// OpenFOAM and waLBerla. Deviations, NOT implemented: MFiX-21.3.2 DRAG_TGS (phi^(1/3) in the last
// bracket and F_TGS used as a drag-only F; its DRAG_GS even dispatches TGS to the Tang routine);
// OpenFOAM Tenneti (isolated term F_isol/eps instead of F_isol/eps^2, i.e. smaller by eps). F_isol
// has no Newton switch (as waLBerla; Re stays below 1000 in the validity box anyway). Validity (not
// verified against the paper): phi 0.1-0.5, Re_m <= 300.
#pragma once

#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Tenneti2011 {
  static constexpr int kNumParameters = 4;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{ForceKind::kTotal, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// F_TGS (total-force normalisation); p = {a1, a2, b1, b2}.
  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    const T eps = T(1.0) - phi;
    const T eps3 = eps * eps * eps;
    const T phi3 = phi * phi * phi;
    const T isolated = (T(1.0) + pow_nonneg(re, 0.687) * 0.15) / eps3;
    const T volume_fraction = p[0] * phi / eps3 + p[1] * pow_nonneg(phi, 1.0 / 3.0) / (eps3 * eps);
    const T inertial = phi3 * re * (p[2] + p[3] * phi3 / (eps * eps));
    return isolated + volume_fraction + inertial;
  }
};

}  // namespace laws
}  // namespace draglab
