// ergun: Ergun (1952) packed-bed pressure drop, written as a gas-solid friction coefficient.
//
//   dP/L = 150 mu (1-eps)^2 U/(eps^3 d^2) + 1.75 rho (1-eps) U^2/(eps^3 d)      (U superficial)
//   beta d^2/(mu phi) = a phi/eps + b Re_p,    Re_p = rho d u/mu (interstitial),  a = 150, b = 1.75
//   F = (a phi + b Re)/(18 eps^2)               (canonical, Re = eps Re_p)
//
// Native convention: beta d^2/(mu phi) (MFiX's DgA d^2/mu), interstitial Re, TFM model A: the form
// of MFiX DRAG_GIDASPOW's dense branch and of OpenFOAM's Ergun (CdRe = 4/3 (150 alpha_d/alpha_c
// + 1.75 Re)); it reproduces Ergun's dP/L through the model-A momentum balance. Other papers write
// other eps powers (e.g. Grains3D's "Gidaspow": 150 phi^2/eps^2, 1.75 phi/eps); not implemented.
// Validity: packed and dense beds, eps 0.35-0.8 (Gidaspow's switch at eps = 0.8); Ergun's
// correlation spans Re_p of order 1 to 1000s. The law has no isolated-sphere limit: F(phi -> 0,
// Re -> 0) = 0.
#pragma once

#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Ergun {
  static constexpr int kNumParameters = 2;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{
      ForceKind::kDragOnly, Normalisation::kBetaD2OverMuPhi,
      ReynoldsDefinition::kInterstitialDiameter, TfmModel::kModelA};
  static LawFormDescription describe();

  /// beta d^2/(mu phi) = a phi/eps + b Re_p; `re_p` interstitial (rho d u/mu), p = {a, b}.
  template <typename T>
  static T native(const T& phi, const T& re_p, const T* /*extra*/, const T* p) {
    return p[0] * phi / (T(1.0) - phi) + p[1] * re_p;
  }
};

}  // namespace laws
}  // namespace draglab
