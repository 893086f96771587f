// gidaspow: Ding & Gidaspow (1990) / Gidaspow (1994): Ergun for eps <= 0.8, Wen-Yu above.
//
//   beta d^2/(mu phi) = a phi/eps + b Re/eps                 eps <= 0.8  (Ergun, Re_p = Re/eps)
//                     = 0.75 (C_d Re) eps^-n                 eps >  0.8  (Wen & Yu)
//
// Native convention: beta d^2/(mu phi), superficial Re, TFM model A (MFiX DRAG_GIDASPOW: EP_g <=
// 0.8 -> Ergun, with ROPg = eps rho in Re). Both arms call the ergun and wen_yu forms, so this law
// equals them exactly on either side of the switch. The hard switch is discontinuous, a known and
// documented property of the published law (F jumps by 15 % at Re = 0, by 5.6 % at Re = 10 and by
// 73 % at Re = 100); gidaspow_blend is the continuous variant. Parameters: p = {a, b, n} as in
// ergun and wen_yu. Validity: the union of the two, phi <= 0.65, Re up to 1e4 (indicative).
#pragma once

#include "laws/ergun.h"
#include "laws/law_math.h"
#include "laws/wen_yu.h"

namespace draglab {
namespace laws {

struct Gidaspow {
  static constexpr int kNumParameters = 3;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{
      ForceKind::kDragOnly, Normalisation::kBetaD2OverMuPhi,
      ReynoldsDefinition::kSuperficialDiameter, TfmModel::kModelA};
  static LawFormDescription describe();

  /// Gas fraction at and below which the Ergun arm is used.
  static constexpr double kSwitchEps = 0.8;

  /// Ergun's beta d^2/(mu phi) from the superficial Re (the same operations as the ergun form's
  /// convention conversion, so the two agree bit for bit).
  template <typename T>
  static T ergun_arm(const T& phi, const T& re, const T* p) {
    const T re_p = re / (T(1.0) - phi);
    return Ergun::native<T>(phi, re_p, nullptr, p);
  }

  /// p = {a, b, n}; `re` superficial.
  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    const T eps = T(1.0) - phi;
    return select(eps <= kSwitchEps, ergun_arm(phi, re, p),
                  WenYu::native<T>(phi, re, nullptr, p + 2));
  }
};

}  // namespace laws
}  // namespace draglab
