// wen_yu: Wen & Yu (1966) dilute-suspension drag, Schiller-Naumann C_d with the eps^-2.65 voidage
// function.
//
//   beta = (3/4) C_d rho eps phi u eps^-n / d,  C_d = Schiller-Naumann(Re),  n = 2.65
//   beta d^2/(mu phi) = (3/4) (C_d Re) eps^-n    (Re = rho eps d u/mu superficial)
//   F = (C_d Re / 24) eps^-(n+1)
//
// Native convention: beta d^2/(mu phi), superficial Re, TFM model A, as MFiX DRAG_WEN_YU (RE =
// DPM VREL ROPg/Mu with ROPg = eps rho), MFiX-Exa, OpenFOAM WenYu (CdRe(Res) alpha_c^-2.65) and
// the seed paper's Eq. 2. The C_d switch is taken at Re <= 1000 (MFiX; OpenFOAM uses <). Variant
// not implemented: Grains3D's eps^-2.7. Validity: dilute suspensions, eps > 0.8; Re up to the
// Newton regime (1e4 here, an indicative bound: no published range was located).
#pragma once

#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct WenYu {
  static constexpr int kNumParameters = 1;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{
      ForceKind::kDragOnly, Normalisation::kBetaD2OverMuPhi,
      ReynoldsDefinition::kSuperficialDiameter, TfmModel::kModelA};
  static LawFormDescription describe();

  /// beta d^2/(mu phi) = 0.75 (C_d Re) eps^-n; `re` superficial, p = {n}.
  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    return schiller_naumann_cd_re(re) * pow(T(1.0) - phi, -p[0]) * 0.75;
  }
};

}  // namespace laws
}  // namespace draglab
